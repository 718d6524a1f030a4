"""
Coulomb friction as the limit of one stiff Maxwell-slip element
===============================================================

``scenarios/acra2012_fig4.toml`` with its load-dependent Coulomb friction replaced by Maxwell-slip elements
(a ``[hysteresis]`` table): one element of share 1 and slip displacement 100, 10, 1 and 0.1 um, against the
Coulomb model on the native engine.  It prints the largest gap of the contraction, the final gap and the
events; then three elements (50, 200 and 1000 um; shares 0.2, 0.3 and 0.5) on the same step, whose spread
of slip displacements rounds the corners where the load turns.  The figure shows the contractions.
"""

import copy

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pamsim  # noqa: E402
from pamsim.scenario import Scenario  # noqa: E402

fig4 = pamsim.load_scenario("../scenarios/acra2012_fig4.toml")


def with_elements(deltas, shares):
    """Figure 4 with the elements of slip displacements ``deltas`` [m] and ``shares`` in place of its friction."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": deltas, "share": shares}
    return Scenario.from_dict(spec, name="maxwell_slip", base_dir=fig4.base_dir)


coulomb = pamsim.simulate(fig4, backend="native")
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
ax.plot(coulomb.t_s, coulomb.x_m * 1e3, "k-", lw=2, label="Coulomb friction (paper)")
for delta in (1e-4, 1e-5, 1e-6, 1e-7):
    res = pamsim.simulate(with_elements([delta], [1.0]), backend="native")
    gap = np.abs(res.x_m - coulomb.x_m)
    print(f"one element, delta {delta * 1e6:5.1f} um: largest gap {gap.max() * 1e3:.4f} mm, final gap "
          f"{(res.x_m[-1] - coulomb.x_m[-1]) * 1e3:+.4f} mm, {len(res.transitions)} events")
    if delta >= 1e-5:
        ax.plot(res.t_s, res.x_m * 1e3, lw=1, label=f"one element, {delta * 1e6:g} um")
three = pamsim.simulate(with_elements([5e-5, 2e-4, 1e-3], [0.2, 0.3, 0.5]), backend="native")
slips = sum(e.kind.startswith("hysteresis.") for e in three.transitions)
print(f"three elements: final {three.x_m[-1] * 1e3:.3f} mm (Coulomb {coulomb.x_m[-1] * 1e3:.3f} mm), "
      f"{slips} slip events of {len(three.transitions)}")
ax.plot(three.t_s, three.x_m * 1e3, "--", label="three elements, 50-1000 um")
ax.set_xlim(0.9, 3.0)
ax.set_xlabel("time [s]")
ax.set_ylabel("contraction [mm]")
ax.legend()
fig.savefig("plot_maxwell_slip_limit.png", dpi=120)
