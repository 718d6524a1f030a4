"""
The paper's rig as a linear slider
==================================

The ACRA 2012 rig is a vertical guide whose carriage is the hanging weight, pulled up by one muscle's
tendon (``pamsim.joints.scenario.slider_of_rig``).  This runs Figure 4 and the 66 paper tests both ways,
as the hanging load and as the slider, and prints how far apart the traces are: while the muscle pulls,
both are the same equations.  Run it from this folder: ``python slider_vs_rig.py``.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pamsim.api import simulate  # noqa: E402
from pamsim.joints import simulate_joint  # noqa: E402
from pamsim.joints.scenario import slider_of_rig  # noqa: E402
from pamsim.scenario import load_scenario  # noqa: E402
from pamsim.sweep.spec import load_sweep  # noqa: E402


def both(scenario, backend):
    """The scenario as a hanging load and as a slider."""
    return simulate(scenario, backend=backend), simulate_joint(slider_of_rig(scenario), backend)


fig4 = load_scenario("../scenarios/acra2012_fig4.toml")
runs = {}
for backend in ("python", "native"):
    rig, slider = runs[backend] = both(fig4, backend)
    gap = float(np.max(np.abs(rig.x_m - slider.position)))
    print(f"fig4 {backend:6s}: largest gap {gap:.2e} m, final {slider.position[-1] * 1e3:.3f} mm, "
          f"RHS evaluations {rig.stats['rhs_evaluations']} (hanging load) / "
          f"{slider.stats['rhs_evaluations']} (slider)")
sweep = load_sweep("../scenarios/acra2012_grid.toml")
gaps = []
for case in sweep.cases:
    rig, slider = both(sweep.case_scenario(case, "load_dependent"), "native")
    gaps.append(float(np.max(np.abs(rig.x_m - slider.position))))
print(f"{len(gaps)} paper tests, native: largest gap {max(gaps):.2e} m, median {np.median(gaps):.2e} m")

fig, (ax_x, ax_gap) = plt.subplots(2, 1, figsize=(7.5, 6.5), layout="constrained")
rig, slider = runs["python"]
ax_x.plot(rig.t_s, rig.x_m * 1e3, color="k", label="hanging load")
ax_x.plot(slider.t_s, slider.position * 1e3, "--", color="C1", label="vertical slider")
ax_x.set_xlabel("time [s]")
ax_x.set_ylabel("contraction / position [mm]")
ax_x.set_title("Figure 4, python backend")
ax_x.legend(loc="lower right")
ax_gap.semilogy(np.arange(1, len(gaps) + 1), np.maximum(gaps, 1e-16), "o", ms=3, color="C0")
ax_gap.set_xlabel("paper test (grid order)")
ax_gap.set_ylabel("largest gap over the run [m]\n(zero drawn at 1e-16)")
ax_gap.set_title("The 66 tests, native backend")
fig.savefig("slider_vs_rig.png", dpi=110)
