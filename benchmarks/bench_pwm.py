"""A 5 s run under 50 Hz PWM (500 switching instants) against Figure 4, on both backends, in the same run.

Figure 4's muscle and load on a 3/2 on/off valve (supply while the command is on, exhaust while off)
driven at 50 Hz and 40 % duty from 0 to 5 s: every switch is an exact breakpoint.  The median wall time
of N runs after warm-up, and the ratio to Figure 4 (8 s, one valve step) on the same backend and method.
Targets for the PWM run: native <= 5 ms, python <= 300 ms.  The python backend runs with its default
method (LSODA) and with DOPRI5 (each segment starting from the step the last one proposed); the native
engine's Dormand-Prince is the same whichever of them the scenario names.

Run:  python benchmarks/bench_pwm.py [--repeats N]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import pamsim

ROOT = Path(__file__).resolve().parents[1]
TARGETS_MS = {"native": 5.0, "python": 300.0}


def pwm_scenario(method: str = "LSODA") -> pamsim.Scenario:
    return pamsim.Scenario.from_dict({
        "name": "pwm_50Hz", "model": {"parameter_set": "shadow_6x300_acra2012"}, "load": {"weight_N": 22.74},
        "pressure": {"source": "valve", "supply_gauge_bar": 3.6,
                     "command": {"kind": "pwm", "start_s": 0.0, "end_s": 5.0, "frequency_Hz": 50.0, "duty": 0.4,
                                 "low": -1.0, "high": 1.0}},
        "simulation": {"duration_s": 5.0, "sample_rate_Hz": 1000.0}, "solver": {"method": method, "rtol": 1e-6}})


def median_ms(run, repeats: int) -> float:
    """Median wall time of ``run()`` [ms] over ``repeats`` calls after 2 warm-up calls."""
    for _ in range(2):
        run()
    walls = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run().x_m  # noqa: B018 (what a caller reads)
        walls.append(time.perf_counter() - t0)
    return statistics.median(walls) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    args = parser.parse_args()
    pwm, fig4 = pwm_scenario(), pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    switches = len(pwm.build_model().source.command.switch_times_s)
    print(f"{switches} switching instants in 5 s")
    print(f"{'backend':8} {'method':7} {'PWM 5 s [ms]':>13} {'target':>7} {'fig4 8 s [ms]':>14} {'PWM / fig4':>11} "
          f"{'PWM RHS':>8} {'segments':>9}")
    for backend, method in (("native", "LSODA"), ("python", "LSODA"), ("python", "DOPRI5")):
        p_sc, f_sc = pwm_scenario(method), fig4.with_changes({"solver": {"method": method}})
        p_ms = median_ms(lambda: pamsim.simulate(p_sc, backend=backend), args.repeats)
        f_ms = median_ms(lambda: pamsim.simulate(f_sc, backend=backend), args.repeats)
        stats = pamsim.simulate(p_sc, backend=backend).stats
        print(f"{backend:8} {method:7} {p_ms:13.3f} {TARGETS_MS[backend]:7.1f} {f_ms:14.3f} {p_ms / f_ms:11.2f} "
              f"{stats['rhs_evaluations']:8d} {stats.get('segments', 0):9d}")
    res = pamsim.simulate(pwm, backend="native")
    print(f"PWM on native: {len(res.transitions)} stick/slip events, "
          f"contraction {res.x_m.min() * 1e3:.2f}-{res.x_m.max() * 1e3:.2f} mm")
    runs = {m: pamsim.simulate(pwm_scenario(m), backend="python") for m in ("LSODA", "DOPRI5")}
    gap = max(abs(runs["DOPRI5"].x_m - runs["LSODA"].x_m).max(), abs(runs["DOPRI5"].x_m - res.x_m).max())
    print(f"python DOPRI5 within {gap * 1e3:.2e} mm of python LSODA and of native at every sample")

if __name__ == "__main__":
    main()
