"""Benchmark of the Python (solve_ivp) simulator, issue 2.

Prints, side by side with the targets:
  * the median wall time of each 8 s paper scenario,
  * the total for the 66 steady-state tests of the paper (default valve and a fast valve),
  * the largest contraction error at the default tolerances against a tight reference
    (Radau, rtol 1e-10).

Run on one core:  taskset -c 0 python benchmarks/bench_core.py [--repeats N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402

import pamsim  # noqa: E402
from pamsim.paperdata import acra2012_steady_state  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PAPER = ["acra2012_fig3", "acra2012_fig4", "acra2012_fig5", "acra2012_fig6a", "acra2012_fig6b"]


def grid_scenarios(base: pamsim.Scenario, valve_C: float | None = None) -> list[pamsim.Scenario]:
    """The 66 measured tests: each stepped to its stable pressure (Table 1), 8 s."""
    changes = {"parameters": {"valve_C_m3_per_s_Pa": valve_C}} if valve_C else {}
    return [base.with_changes({**changes, "load": {"weight_N": float(r["weight_N"])},
                               "pressure": {"supply_gauge_bar": float(r["pressure_stable_bar"])}},
                              name=f"{r['pressure_step_bar']}bar_{r['weight_N']}N")
            for r in acra2012_steady_state()]


def timed(scenarios) -> tuple[float, list]:
    t0 = time.perf_counter()
    results = [pamsim.simulate(s) for s in scenarios]
    return time.perf_counter() - t0, results


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    scenarios = {n: pamsim.load_scenario(ROOT / "scenarios" / f"{n}.toml") for n in PAPER}
    pamsim.simulate(scenarios["acra2012_fig4"])  # warm caches and imports

    print("== one 8 s paper scenario, Python backend (LSODA, rtol 1e-6), one process ==")
    print(f"{'scenario':18s} {'median ms':>10s} {'min ms':>8s} {'events':>7s} {'RHS evals':>10s}")
    medians = []
    for name, sc in scenarios.items():
        times = []
        for _ in range(args.repeats):
            dt, (res,) = timed([sc])
            times.append(dt)
        medians.append(statistics.median(times))
        print(f"{name:18s} {medians[-1] * 1e3:10.1f} {min(times) * 1e3:8.1f} {res.stats['events']:7d} "
              f"{res.stats['rhs_evaluations']:10d}")
    print(f"median over the five: {statistics.median(medians) * 1e3:.1f} ms   (target <= 40 ms, "
          f"ratio {statistics.median(medians) / 0.040:.2f} of target)")

    base = scenarios["acra2012_fig4"]
    for label, C, target in (("default valve (C = 1e-9)", None, 3.0), ("fast valve (C = 2e-8)", 2e-8, 10.0)):
        cases = grid_scenarios(base, C)
        dt, results = timed(cases)
        events = sum(r.stats["events"] for r in results)
        rest = sum(r.at_rest_at_end for r in results)
        print(f"== 66 steady-state tests, {label}: {dt:.2f} s  (target <= {target:.0f} s, ratio {dt / target:.2f}); "
              f"{events} events in all, max {max(r.stats['events'] for r in results)}; {rest}/66 at rest at 8 s ==")

    print("== accuracy at the default tolerances against Radau rtol 1e-10 ==")
    print(f"{'scenario':18s} {'max |dx| mm':>12s} {'final |dx| mm':>14s}")
    worst = 0.0
    for name, sc in scenarios.items():
        ref = pamsim.simulate(sc.with_changes({"solver": {"method": "Radau", "rtol": 1e-10}}))
        res = pamsim.simulate(sc)
        err = np.max(np.abs(res.x_m - ref.x_m)) * 1e3
        worst = max(worst, err)
        print(f"{name:18s} {err:12.5f} {abs(res.x_m[-1] - ref.x_m[-1]) * 1e3:14.5f}")
    print(f"largest contraction error: {worst:.5f} mm   (target <= 0.05 mm)")


if __name__ == "__main__":
    main()
