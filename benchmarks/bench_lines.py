"""What a supply line costs: ``scenarios/supply_chain.toml`` against Figure 4 without a line.

Per backend (python, native) and scenario: the median wall time of N calls of ``pamsim.simulate`` after
warm-up, the engine's own time (``Result.wall_time_s``), and the right-hand-side evaluations.  The line
adds stiff modes (a tube's bore exchanging air with the muscle through its resistance: a pole near
-19000 1/s, ``pamsim linearize scenarios/supply_chain.toml``) that the python backend's LSODA steps over
and the native engine's explicit Dormand-Prince integrator must follow.

Run:  python benchmarks/bench_lines.py [--repeats N]
"""

from __future__ import annotations

import argparse
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    args = parser.parse_args()
    print("| scenario | backend | wall [ms] | engine [ms] | RHS evaluations |")
    print("| --- | --- | --- | --- | --- |")
    for name in ("acra2012_fig4", "supply_chain"):
        sc = pamsim.load_scenario(ROOT / "scenarios" / f"{name}.toml")
        for backend in ("python", "native"):
            wall, own, nfev = measure(sc, backend, args.repeats)
            print(f"| {name} | {backend} | {wall:.2f} | {own:.2f} | {nfev} |")


if __name__ == "__main__":
    main()
