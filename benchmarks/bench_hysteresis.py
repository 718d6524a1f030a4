"""Maxwell-slip elements in the force balance against the paper's Coulomb friction, same scenario, same run.

``scenarios/acra2012_fig4.toml`` (8 s) as it is, and with its load-dependent friction replaced by N = 10
Maxwell-slip elements (a ``[hysteresis]`` table: slip displacements from 0.1 to 5 mm, geometrically
spaced, shares 0.1 each), without and with presliding damping (100 N s/m).  Per backend: the median wall
time of N calls of ``pamsim.simulate`` after warm-up, the right-hand-side evaluations and events, and the
ratio to Coulomb friction.  The scenarios alternate call by call, so a change in the machine's load falls
on all.  Targets: native <= 3x, python <= 5x.

Run:  python benchmarks/bench_hysteresis.py [--repeats N]
"""

from __future__ import annotations

import argparse
import copy
import statistics
import time
from pathlib import Path

import numpy as np

import pamsim
from pamsim.scenario import Scenario

ROOT = Path(__file__).resolve().parents[1]
TARGETS = {"native": 3.0, "python": 5.0}


def scenarios() -> dict:
    """Figure 4 with Coulomb friction, and with ten elements without and with presliding damping."""
    fig4 = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    out = {"Coulomb (paper)": fig4}
    for c in (0.0, 100.0):
        spec = copy.deepcopy(dict(fig4.spec))
        spec["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": list(np.geomspace(1e-4, 5e-3, 10)),
                              "share": [0.1] * 10, "damping_N_s_per_m": c}
        out[f"10 elements, c = {c:g} N s/m"] = Scenario.from_dict(spec, name="maxwell_slip_10", base_dir=fig4.base_dir)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    args = parser.parse_args()
    cases = scenarios()
    print(f"{'backend':8} {'scenario':28} {'[ms]':>9} {'RHS':>7} {'events':>7} {'/ Coulomb':>10} {'target':>7}")
    for backend in ("native", "python"):
        repeats = args.repeats if backend == "native" else max(2, args.repeats // 5)
        for sc in cases.values():
            pamsim.simulate(sc, backend=backend)
        walls = {label: [] for label in cases}
        last = {}
        for _ in range(repeats):
            for label, sc in cases.items():
                t0 = time.perf_counter()
                last[label] = pamsim.simulate(sc, backend=backend)
                walls[label].append(time.perf_counter() - t0)
        base = statistics.median(walls["Coulomb (paper)"])
        for label, res in last.items():
            ms = statistics.median(walls[label])
            print(f"{backend:8} {label:28} {ms * 1e3:9.2f} {res.stats['rhs_evaluations']:7d} {len(res.transitions):7d} "
                  f"{ms / base:10.2f} {TARGETS[backend]:7.1f}")


if __name__ == "__main__":
    main()
