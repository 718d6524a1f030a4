"""The paper's rig as a linear slider: Figure 4 and the 66 ACRA 2012 tests run as a hanging load and as a
vertical slider (pamsim.joints.scenario.slider_of_rig), and how far apart their traces are.

    python examples/slider_vs_rig.py
"""

from pathlib import Path

import numpy as np

from pamsim.api import simulate
from pamsim.joints import simulate_joint
from pamsim.joints.scenario import slider_of_rig
from pamsim.scenario import load_scenario
from pamsim.sweep.spec import load_sweep

ROOT = Path(__file__).resolve().parents[1] / "scenarios"


def gap_m(scenario, backend: str) -> tuple[float, float, int, int]:
    """Largest difference of the two traces [m], final contraction [m], RHS evaluations of each."""
    rig, slider = simulate(scenario, backend=backend), simulate_joint(slider_of_rig(scenario), backend)
    return (float(np.max(np.abs(rig.x_m - slider.position))), float(slider.position[-1]),
            rig.stats["rhs_evaluations"], slider.stats["rhs_evaluations"])


fig4 = load_scenario(ROOT / "acra2012_fig4.toml")
for backend in ("python", "native"):
    gap, final, n_rig, n_slider = gap_m(fig4, backend)
    print(f"fig4 {backend:6s}: largest gap {gap:.2e} m, final {final * 1e3:.3f} mm, "
          f"RHS evaluations {n_rig} (hanging load) / {n_slider} (slider)")
sweep = load_sweep(ROOT / "acra2012_grid.toml")
gaps = [gap_m(sweep.case_scenario(c, "load_dependent"), "native")[0] for c in sweep.cases]
print(f"{len(gaps)} paper tests, native: largest gap {max(gaps):.2e} m, median {np.median(gaps):.2e} m")
