"""What a supply line costs: ``scenarios/supply_chain.toml`` against Figure 4 without a line.

Per backend (python, native) and scenario: the median wall time of N calls of ``pamsim.simulate`` after
warm-up, the engine's own time (``Result.wall_time_s``), and the right-hand-side evaluations.  The line
adds stiff modes (a tube's bore exchanging air with the muscle through its resistance: a pole near
-19000 1/s, ``pamsim linearize scenarios/supply_chain.toml``) that the python backend's LSODA steps over
and the native engine's Rodas4 steps over while the load is held (its Dormand-Prince follows them while
the load moves).  The line again with its tubes'
turbulent law, and with the muscle's tube in 10 cells with inertia (acoustic modes near 2 pi 72 Hz and up
to the cells' own, ``c / (2 h)``).

Run:  python benchmarks/bench_lines.py [--repeats N]
"""

from __future__ import annotations

import argparse
import copy
import statistics
import time
from pathlib import Path

import pamsim

ROOT = Path(__file__).resolve().parents[1]


def measure(sc, backend: str, repeats: int) -> tuple[float, float, int]:
    """(median wall [ms], median engine [ms], RHS evaluations) of ``repeats`` runs after two to warm up."""
    for _ in range(2):
        pamsim.simulate(sc, backend=backend)
    walls, own = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = pamsim.simulate(sc, backend=backend)
        walls.append(time.perf_counter() - t0)
        own.append(res.wall_time_s)
    return 1e3 * statistics.median(walls), 1e3 * statistics.median(own), res.stats["rhs_evaluations"]


def _tubes(spec: dict, **keys) -> dict:
    """``spec`` with ``keys`` set on its tubes (``segments`` and ``inertia`` on the muscle's tube only)."""
    out = copy.deepcopy(spec)
    for c in out["component"]:
        if c["type"] == "tube" and (c["name"] == "tube" or "segments" not in keys):
            c.update(keys)
    return out


def scenarios() -> dict:
    """``{label: Scenario}``: Figure 4, the shipped line, and the line with the turbulent law and the
    inertial tube."""
    fig4, line = (pamsim.load_scenario(ROOT / "scenarios" / f"{n}.toml") for n in ("acra2012_fig4", "supply_chain"))
    turbulent = _tubes(line.spec, resistance="turbulent")
    inertial = _tubes(turbulent, segments=10, inertia=True)
    base = ROOT / "scenarios"
    return {"acra2012_fig4": fig4, "supply_chain": line,
            "supply_chain, turbulent": pamsim.Scenario.from_dict(turbulent, base_dir=base),
            "supply_chain, turbulent, 10 inertial cells": pamsim.Scenario.from_dict(inertial, base_dir=base)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    args = parser.parse_args()
    print("| scenario | backend | wall [ms] | engine [ms] | RHS evaluations |")
    print("| --- | --- | --- | --- | --- |")
    for name, sc in scenarios().items():
        for backend in ("python", "native"):
            wall, own, nfev = measure(sc, backend, args.repeats)
            print(f"| {name} | {backend} | {wall:.2f} | {own:.2f} | {nfev} |")


if __name__ == "__main__":
    main()
