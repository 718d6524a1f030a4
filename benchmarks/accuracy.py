"""How accurate each backend and method is at a given tolerance, against a converged run.

    python benchmarks/accuracy.py

The test case is the hardest the rig offers an integrator: no Coulomb friction, no damping and a
prescribed 3.6 bar step at 1 s (no valve to damp it), so the load swings freely and bounces on its
upper stop 37 times in 8 s.  The reference is the python backend with DOP853 at rtol 1e-12.  Two
errors are printed per run:

- the largest contraction error over the smooth swing before the first impact, which measures the
  integrator's error control;
- the largest error over the whole run, which after 37 impacts measures how the bounce sequence
  amplifies any difference (an impact a hair earlier changes every later one), not the error control.

Also the number of events (37 where nothing was missed) and the wall time of the run.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import pamsim

ROOT = Path(__file__).resolve().parents[1]
RUNS = (("native", "DOPRI5(4)"), ("python", "LSODA"), ("python", "RK45"), ("python", "DOP853"))
RTOLS = (1e-6, 1e-8, 1e-10)


def free_swing():
    """Figure 4's rig without friction or damping, under a prescribed pressure step."""
    return pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml").with_changes({
        "model": {"friction": "none", "damping": "none"},
        "pressure": {"source": "prescribed", "prescribed": {"kind": "step", "time_s": 1.0, "final_gauge_bar": 3.6}}})


def main() -> None:
    base = free_swing()
    ref = pamsim.simulate(base.with_changes({"solver": {"rtol": 1e-12, "method": "DOP853"}}))
    first = next(e.t_s for e in ref.transitions if e.kind == "stop_high")
    swing = ref.t_s < first
    print(f"reference: python DOP853 at rtol 1e-12, {len(ref.transitions)} events, first impact at {first:.4f} s")
    print(f"{'backend':8} {'method':10} {'rtol':>6} {'swing error mm':>15} {'whole run mm':>13} {'events':>7} {'time s':>7}")
    for backend, method in RUNS:
        for rtol in RTOLS:
            changes = {"rtol": rtol} if backend == "native" else {"rtol": rtol, "method": method}
            t0 = time.perf_counter()
            run = pamsim.simulate(base.with_changes({"solver": changes}), backend=backend)
            wall = time.perf_counter() - t0
            swing_mm = np.max(np.abs(run.x_m[swing] - ref.x_m[swing])) * 1e3
            whole_mm = np.max(np.abs(run.x_m - ref.x_m)) * 1e3
            print(f"{backend:8} {method:10} {rtol:6.0e} {swing_mm:15.2e} {whole_mm:13.2e} {len(run.transitions):7d} "
                  f"{wall:7.3f}")


if __name__ == "__main__":
    main()
