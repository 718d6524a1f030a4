"""How accurate each backend and method is at a given tolerance, against a converged run.

    python benchmarks/accuracy.py [--no-paper] [--no-pwm]

The test case is the hardest the rig offers an integrator: no Coulomb friction, no damping and a
prescribed 3.6 bar step at 1 s (no valve to damp it), so the load swings freely and bounces on its
upper stop 37 times in 8 s.  The reference is the python backend with DOP853 at rtol 1e-12.  Two
errors are printed per run:

- the largest contraction error over the smooth swing before the first impact, which measures the
  integrator's error control;
- the largest error over the whole run, which after 37 impacts measures how the bounce sequence
  amplifies any difference (an impact a hair earlier changes every later one), not the error control.

Also the number of events (37 where nothing was missed) and the wall time of the run.  The native
backend runs at each ``rtol`` twice: at that tolerance (``solver.native_rtol_factor = 1``, like for like
with the python methods) and at its default, ``rtol`` times ``pamsim.simulator.NATIVE_RTOL_FACTOR``.

Then the two shipped PWM scenarios (unless ``--no-pwm``), whose load comes to rest for one to four
milliseconds between two pulses, against the python backend's LSODA at rtol 1e-9: per backend and method
at the scenario's own rtol, how many of the reference's events it found (in the reference's order, the
kinds and modes alike, within 1 ms), its sticks, the largest time between an event found and the reference's, and its
largest contraction and pressure errors; then the reference's events a run missed, where it missed four
or fewer.

Then the paper's cases (unless ``--no-paper``): the five figure scenarios and the 66 steady-state cases
of ``acra2012_grid.toml`` (its first friction model), each at its own ``rtol`` (1e-6), against the
python backend's DOP853 at rtol 1e-12: the largest contraction error over the run of the python default
(LSODA) and of the native backend at factors 1, 0.1 and its default, and the native wall time of the
66 cases in one ``simulate_batch`` call (best of 3).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import pamsim
from pamsim.native import simulate_batch
from pamsim.simulator import NATIVE_RTOL_FACTOR

ROOT = Path(__file__).resolve().parents[1]
RUNS = (("native", "DOPRI5(4)", 1.0), ("native", "default", NATIVE_RTOL_FACTOR), ("python", "LSODA", None),
        ("python", "RK45", None), ("python", "DOP853", None))
RTOLS = (1e-6, 1e-8, 1e-10)
FIGURES = ("acra2012_fig3", "acra2012_fig4", "acra2012_fig5", "acra2012_fig6a", "acra2012_fig6b")
CONVERGED = {"rtol": 1e-12, "method": "DOP853"}


def free_swing():
    """Figure 4's rig without friction or damping, under a prescribed pressure step."""
    return pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml").with_changes({
        "model": {"friction": "none", "damping": "none"},
        "pressure": {"source": "prescribed", "prescribed": {"kind": "step", "time_s": 1.0, "final_gauge_bar": 3.6}}})


def free_swing_table() -> None:
    """The free swing at each backend, method and rtol."""
    base = free_swing()
    ref = pamsim.simulate(base.with_changes({"solver": CONVERGED}))
    first = next(e.t_s for e in ref.transitions if e.kind == "stop_high")
    swing = ref.t_s < first
    print(f"reference: python DOP853 at rtol 1e-12, {len(ref.transitions)} events, first impact at {first:.4f} s")
    print(f"{'backend':8} {'method':10} {'rtol':>6} {'its rtol':>8} {'swing error mm':>15} {'whole run mm':>13} "
          f"{'events':>7} {'time s':>7}")
    for backend, method, factor in RUNS:
        for rtol in RTOLS:
            changes = {"rtol": rtol, "method": method} if factor is None else {"rtol": rtol, "native_rtol_factor": factor}
            t0 = time.perf_counter()
            run = pamsim.simulate(base.with_changes({"solver": changes}), backend=backend)
            wall = time.perf_counter() - t0
            swing_mm = np.max(np.abs(run.x_m[swing] - ref.x_m[swing])) * 1e3
            whole_mm = np.max(np.abs(run.x_m - ref.x_m)) * 1e3
            print(f"{backend:8} {method:10} {rtol:6.0e} {rtol * (factor or 1.0):8.0e} {swing_mm:15.2e} {whole_mm:13.2e} "
                  f"{len(run.transitions):7d} {wall:7.3f}")


def error_mm(run, ref) -> float:
    """The largest contraction difference over the run [mm]."""
    return float(np.max(np.abs(run.x_m - ref.x_m))) * 1e3


def paper_errors(scenarios, factors) -> tuple[dict[str, list[float]], list[bool]]:
    """Per run (python LSODA, then the native backend at each factor), the error of each scenario
    [mm] against its converged run; and whether each scenario's load moves at all."""
    runs = {f: simulate_batch([s.with_changes({"solver": {"native_rtol_factor": f}}) for s in scenarios])
            for f in factors}
    errors = {"python LSODA": [], **{f"native x{f:g}" + (" (default)" if f == NATIVE_RTOL_FACTOR else ""): []
                                     for f in factors}}
    moving = []  # the cases whose load leaves its lower stop (the others stay there, exactly, on every run)
    for i, s in enumerate(scenarios):
        ref = pamsim.simulate(s.with_changes({"solver": CONVERGED}))
        moving.append(bool(np.ptp(ref.x_m) > 0.0))
        for name, run in zip(errors, (pamsim.simulate(s), *(runs[f][i] for f in factors))):
            errors[name].append(error_mm(run, ref))
    return errors, moving


def _row(label: str, values, fmt: str = "26.2e") -> str:
    return f"{label:16}" + "".join(f"{v:{fmt}}" for v in values)


def paper_table() -> None:
    """The paper's figures and cases: the python default's and the native backend's error, and its time."""
    from pamsim.sweep import load_sweep

    figures = [pamsim.load_scenario(ROOT / "scenarios" / f"{name}.toml") for name in FIGURES]
    grid = load_sweep(ROOT / "scenarios" / "acra2012_grid.toml")
    cases = [grid.case_scenario(c, grid.friction_models[0]) for c in grid.cases]
    factors = tuple(sorted({1.0, 0.1, NATIVE_RTOL_FACTOR}, reverse=True))
    errors, moving = paper_errors(figures + cases, factors)
    print(f"\npaper cases at their rtol ({figures[0].solver.rtol:g}), largest contraction error [mm] against "
          "python DOP853 at rtol 1e-12")
    print(f"{'case':16}" + "".join(f"{name:>26}" for name in errors))
    for i, s in enumerate(figures):
        print(_row(s.name, (e[i] for e in errors.values())))
    grid_errors = [np.array(e[len(figures):]) for e in errors.values()]
    moves = np.array(moving[len(figures):])
    print(_row("66 cases, max", (e.max() for e in grid_errors)))
    print(_row(f"median of {moves.sum()}", (np.median(e[moves]) for e in grid_errors))
          + "  (the cases whose load moves)")
    print(_row("66: above LSODA", (int(np.sum(e > grid_errors[0])) for e in grid_errors), "26d"))
    for f in factors:
        batch = [s.with_changes({"solver": {"native_rtol_factor": f}}) for s in cases]
        best = min(_timed(lambda: simulate_batch(batch)) for _ in range(3))
        print(f"native factor {f:g}: the 66 cases in one simulate_batch call, best of 3: {best * 1e3:.1f} ms")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


PWM_RUNS = (("native", "LSODA"), ("native", "RK45"), ("fmu-cs", None), ("python", "LSODA"), ("python", "DOPRI5"),
            ("python", "RK45"))


MATCH_WINDOW_S = 1e-3
"""An event of a run matches one of the reference's of the same kind and mode after within this time [s]."""


def _matched(run, ref) -> list[tuple[int, int]]:
    """The pairs (run's event, reference's event) of the longest common sequence of events of the same kind
    and mode after, within :data:`MATCH_WINDOW_S` of each other: each event of either matched once, in
    order."""
    a, b = run.transitions, ref.transitions

    def same(x, y) -> bool:
        return (x.kind, x.to_mode) == (y.kind, y.to_mode) and abs(x.t_s - y.t_s) <= MATCH_WINDOW_S
    table = np.zeros((len(a) + 1, len(b) + 1), dtype=np.int64)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            table[i + 1, j + 1] = table[i, j] + 1 if same(x, y) else max(table[i, j + 1], table[i + 1, j])
    pairs, i, j = [], len(a), len(b)
    while i and j:
        if same(a[i - 1], b[j - 1]) and table[i, j] == table[i - 1, j - 1] + 1:
            pairs.append((i - 1, j - 1))
            i, j = i - 1, j - 1
        elif table[i - 1, j] >= table[i, j - 1]:
            i -= 1
        else:
            j -= 1
    return pairs[::-1]


def pwm_table() -> None:
    """The PWM scenarios on each backend and method: events found and errors against a converged run."""
    for name in ("pwm_onoff", "pwm_3_2"):
        base = pamsim.load_scenario(ROOT / "scenarios" / f"{name}.toml")
        ref = pamsim.simulate(base.with_changes({"solver": {"rtol": 1e-9}}))
        sticks = sum(e.to_mode == "stick" for e in ref.transitions)
        print(f"\n{name} at rtol {base.solver.rtol:g} against python LSODA at rtol 1e-9: {len(ref.transitions)} events, "
              f"{sticks} of them sticks")
        print(f"{'backend':8} {'method':7} {'events found':>13} {'sticks':>7} {'event dt ms':>12} {'contraction um':>15} "
              f"{'pressure Pa':>12}")
        missed = []
        for backend, method in PWM_RUNS:
            run = pamsim.simulate(base.with_changes({"solver": {"method": method}}) if method else base,
                                  backend=backend)
            # The FMUs do not report their events: their run is judged by its trajectory alone.
            found = stuck = dt = "-"
            if run.transitions:
                pairs = _matched(run, ref)
                found = f"{len(pairs):6d} of {len(ref.transitions):3d}"
                stuck = f"{sum(e.to_mode == 'stick' for e in run.transitions)}"
                dt = f"{max(abs(run.transitions[i].t_s - ref.transitions[j].t_s) for i, j in pairs) * 1e3:.3f}"
                gone = sorted(set(range(len(ref.transitions))) - {j for _, j in pairs})
                if 0 < len(gone) <= 4:
                    missed.append(f"{backend} {method} missed: " + ", ".join(
                        f"{ref.transitions[j].t_s:.4f} s {ref.transitions[j].kind} to {ref.transitions[j].to_mode}"
                        for j in gone))
            print(f"{backend:8} {method or '':7} {found:>13} {stuck:>7} {dt:>12} {error_mm(run, ref) * 1e3:15.3f} "
                  f"{np.max(np.abs(run.p_gauge_Pa - ref.p_gauge_Pa)):12.2f}")
        for line in missed:
            print(line)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-paper", action="store_true", help="without the paper's cases")
    parser.add_argument("--no-pwm", action="store_true", help="without the PWM scenarios")
    args = parser.parse_args()
    free_swing_table()
    if not args.no_pwm:
        pwm_table()
    if not args.no_paper:
        paper_table()


if __name__ == "__main__":
    main()
