"""The closed-loop scenario on every backend, timed in one run and compared with the python backend.

    python benchmarks/bench_closed_loop.py [--rounds N] [--calls N]

Last, one row for ``scenarios/proportional_valve.toml`` (the same loop through a spool valve and a tube):
its run alone on python and native, median over N rounds, and the right-hand-side evaluations it takes.

For each backend: ``pamsim.run(scenarios/closed_loop_position.toml, backend)``, the whole call (the
controller's design, the run, the metrics and the linear prediction) and the run alone (the Result's
``wall_time_s``: the python integration, the native library call, or fmpy driving the FMU), each the
median over N rounds of N calls after one warm-up call per backend (which builds the native library
and the FMU if they are not cached).  The backends alternate within each round, so that a change of
the machine's load falls on all of them; the load average is printed beside the figures.  The
ratios are python's median over each backend's, from the same run.  Each backend's step metrics and
final position are printed too, with their difference from python's.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

import pamsim

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "closed_loop_position.toml"
SPOOL_SCENARIO = SCENARIO.with_name("proportional_valve.toml")
BACKENDS = ("python", "native", "fmu-cs", "fmu-me")
METRICS = ("rise_time_s", "overshoot_percent", "settling_time_s", "steady_state_error_mm")


def timed(backend: str) -> tuple[float, float, object]:
    """Wall seconds of one ``pamsim.run``, of its run alone, and the run."""
    start = time.perf_counter()
    run = pamsim.run(SCENARIO, backend=backend)
    return time.perf_counter() - start, run.result.wall_time_s, run


def main(argv=None) -> None:
    """Time the closed loop on every backend and print the table, the ratios and the agreement."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3, help="rounds of calls (default 3)")
    ap.add_argument("--calls", type=int, default=5, help="calls of each backend per round (default 5)")
    args = ap.parse_args(argv)
    runs = {b: timed(b)[2] for b in BACKENDS}  # warm-up: the native library and the FMU built or found
    whole: dict[str, list[float]] = {b: [] for b in BACKENDS}
    alone: dict[str, list[float]] = {b: [] for b in BACKENDS}
    load = os.getloadavg()[0]
    for _ in range(args.rounds):
        for b in BACKENDS:
            for _ in range(args.calls):
                w, a, _run = timed(b)
                whole[b].append(w)
                alone[b].append(a)
    load = max(load, os.getloadavg()[0])
    med = {b: (statistics.median(whole[b]), statistics.median(alone[b])) for b in BACKENDS}
    print(f"closed_loop_position (20 -> 40 mm, 3 s), median of {args.rounds} x {args.calls} calls per backend; "
          f"load average up to {load:.2f} on {os.cpu_count()} cores")
    print(f"{'backend':8} {'pamsim.run [ms]':>16} {'python/this':>12} {'run alone [ms]':>15} {'python/this':>12}")
    for b in BACKENDS:
        print(f"{b:8} {med[b][0] * 1e3:16.2f} {med['python'][0] / med[b][0]:12.1f} {med[b][1] * 1e3:15.2f} "
              f"{med['python'][1] / med[b][1]:12.1f}")
    ref = runs["python"]
    print("\nagreement with python: " + ", ".join(METRICS) + ", final position")
    for b in BACKENDS:
        m = runs[b].closed_loop.metrics
        diffs = [m[k] - ref.closed_loop.metrics[k] for k in METRICS]
        dx_um = (runs[b].result.x_m[-1] - ref.result.x_m[-1]) * 1e6
        values = ", ".join(f"{m[k]:.4g} ({d:+.2g})" for k, d in zip(METRICS, diffs))
        print(f"{b:8} {values}, {runs[b].result.x_m[-1] * 1e3:.5f} mm ({dx_um:+.3f} um); "
              f"meets spec: {not runs[b].failures}")
    plain_fmpy(ref)
    spool_row(args.rounds)


def spool_row(rounds: int) -> None:
    """Time the closed loop through the spool valve and the tube (its run alone) on python and native."""
    alone = {b: [] for b in ("python", "native")}
    rhs = {}
    for b in alone:
        pamsim.run(SPOOL_SCENARIO, backend=b)  # warm-up: the generated code and the native library
    for _ in range(rounds):
        for b in alone:
            run = pamsim.run(SPOOL_SCENARIO, backend=b)
            alone[b].append(run.result.wall_time_s)
            rhs[b] = run.result.stats["rhs_evaluations"]
    print(f"\nproportional_valve (spool valve and tube, 20 -> 40 mm, 3 s), run alone, median of {rounds}: "
          + ", ".join(f"{b} {statistics.median(v) * 1e3:.1f} ms ({rhs[b]} RHS evaluations)" for b, v in alone.items()))


def plain_fmpy(ref) -> None:
    """The FMU of the closed loop (the one the FMU backends run, as ``pamsim fmu build --scenario`` builds it)
    in plain ``fmpy.simulate_fmu``: no start values, no inputs, the scenario's 1 ms output grid."""
    import fmpy
    import numpy as np

    from pamsim.control.closed_loop import design_closed_loop, step_metrics
    from pamsim.fmu.assembly_runner import cached_assembly_fmu

    loop = design_closed_loop(SCENARIO)
    path, _ = cached_assembly_fmu(loop.scenario, loop.model)
    c = loop.config
    for kind in ("CoSimulation", "ModelExchange"):
        start = time.perf_counter()
        r = fmpy.simulate_fmu(str(path), fmi_type=kind, output_interval=1e-3, output=["load.x_m"])
        wall = time.perf_counter() - start
        after = np.r_[r["time"][1:] != r["time"][:-1], True]  # fmpy records both sides of an event
        t, x = r["time"][after], r["load.x_m"][after]
        m = step_metrics(t, x, c.step_time_s, loop.scenario.initial_contraction_m, c.target_contraction_m,
                         c.spec.get("settling_band_mm", 0.5) * 1e-3)
        diffs = [m[k] - ref.closed_loop.metrics[k] for k in METRICS]
        values = ", ".join(f"{m[k]:.4g} ({d:+.2g})" for k, d in zip(METRICS, diffs))
        print(f"plain fmpy {kind}: {values}, {x[-1] * 1e3:.5f} mm ({(x[-1] - ref.result.x_m[-1]) * 1e6:+.3f} um); "
              f"{wall * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
