"""The thermal chamber against the polytropic one on the native backend, same scenarios, same run.

Two scenarios, each run with the chamber's thermal law and with the polytropic law (the muscle's own
index, 1): ``scenarios/thermal_drift.toml`` (a 0.6 s fill at 3.6 bar, then 4.2 s with the valve closed,
where the thermal gas cools and the load creeps) and ``scenarios/acra2012_fig4.toml`` (the valve open
from 1 s to the end, 8 s).  Per run: the median wall time of N calls of ``pamsim.simulate`` after
warm-up, the engine's own time (``Result.wall_time_s``), the right-hand-side evaluations and events,
and the ratio thermal / polytropic of each.  The two laws alternate call by call, so a change in the
machine's load falls on both.  Target: thermal <= 1.5x polytropic.

Run:  python benchmarks/bench_chamber.py [--repeats N]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import pamsim

ROOT = Path(__file__).resolve().parents[1]
TARGET_RATIO = 1.5


def timed(scenarios: dict, repeats: int) -> dict:
    """``{label: (median wall [ms], median engine [ms], result)}`` over ``repeats`` alternating calls."""
    for sc in scenarios.values():
        for _ in range(3):
            pamsim.simulate(sc, backend="native")
    walls = {label: [] for label in scenarios}
    own = {label: [] for label in scenarios}
    last = {}
    for _ in range(repeats):
        for label, sc in scenarios.items():
            t0 = time.perf_counter()
            res = pamsim.simulate(sc, backend="native")
            walls[label].append(time.perf_counter() - t0)
            own[label].append(res.wall_time_s)
            last[label] = res
    return {label: (statistics.median(walls[label]) * 1e3, statistics.median(own[label]) * 1e3, last[label])
            for label in scenarios}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30)
    args = parser.parse_args()
    print(f"{'scenario':15} {'law':11} {'wall [ms]':>10} {'engine [ms]':>12} {'RHS':>6} {'events':>7} "
          f"{'us/RHS':>7}")
    for name in ("thermal_drift", "acra2012_fig4"):
        base = pamsim.load_scenario(ROOT / "scenarios" / f"{name}.toml")
        scenarios = {"polytropic": base.with_changes({"chamber": {"law": "polytropic"}}),
                     "thermal": base.with_changes({"chamber": {"law": "thermal"}})}
        out = timed(scenarios, args.repeats)
        for law, (wall, engine, res) in out.items():
            rhs = res.stats["rhs_evaluations"]
            print(f"{name:15} {law:11} {wall:10.3f} {engine:12.3f} {rhs:6d} {res.stats['events']:7d} "
                  f"{engine * 1e3 / rhs:7.3f}")
        (pw, pe, pr), (tw, te, tr) = out["polytropic"], out["thermal"]
        per_rhs = (te / tr.stats["rhs_evaluations"]) / (pe / pr.stats["rhs_evaluations"])
        print(f"{name:15} thermal / polytropic: wall {tw / pw:.2f}x, engine {te / pe:.2f}x, "
              f"per RHS evaluation {per_rhs:.2f}x (target <= {TARGET_RATIO:g}x)")


if __name__ == "__main__":
    main()
