"""
Hysteresis loops with minor loops
=================================

``scenarios/hysteresis_loops.toml`` cycles the Shadow muscle's pressure slowly at a 10 N weight, its
friction three Maxwell-slip elements: a major cycle from 1.2 to 4 bar, turns of falling amplitude inside
it, and a last rise to 4 bar.  This runs it on the native engine and plots the contraction against the
pressure (the major loop and its minor loops) and the elements' force against the contraction.  It prints
where the last rise passes 3 bar against where the first minor loop left that branch at 3 bar
(return-point memory), and the loops' widths.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pamsim  # noqa: E402

scenario = pamsim.load_scenario("../scenarios/hysteresis_loops.toml")
res = pamsim.simulate(scenario, backend="native")
p_bar, x_mm = res.p_gauge_Pa / 1e5, res.x_m * 1e3
force = res.signals["hysteresis.F_N"]


def at(t_s):
    """The sample at ``t_s``."""
    return int(np.searchsorted(res.t_s, t_s))


# The first minor loop leaves the rising branch at 3 bar (30.6 s); after the turns inside it the last rise
# (41.8-48.2 s) passes 3 bar again.
last = np.arange(at(41.8), at(48.2))
again = last[np.argmin(np.abs(p_bar[last] - 3.0))]
print(f"at 3 bar: {x_mm[at(30.6)]:.3f} mm where the first minor loop turned, {x_mm[again]:.3f} mm on the last rise")
for lo, hi in ((12.2, 23.4), (30.6, 35.4)):
    falling = np.arange(at(lo), at(hi))
    mid = 0.5 * (p_bar[at(lo)] + p_bar[at(hi)])
    rising = np.arange(at(1.0), at(12.2)) if lo == 12.2 else np.arange(at(23.4), at(30.6))
    width = x_mm[falling][np.argmin(np.abs(p_bar[falling] - mid))] - x_mm[rising][np.argmin(np.abs(p_bar[rising] - mid))]
    print(f"loop from {p_bar[at(lo)]:.1f} bar down to {p_bar[at(hi)]:.1f} bar: width {width:.2f} mm at {mid:.1f} bar")
print(f"{len(res.transitions)} events, of which {sum(e.kind.startswith('hysteresis.') for e in res.transitions)} "
      "element slips")

fig, (ax_p, ax_f) = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
ax_p.plot(p_bar, x_mm, lw=1)
ax_p.set_xlabel("gauge pressure [bar]")
ax_p.set_ylabel("contraction [mm]")
ax_p.set_title("contraction against pressure")
ax_f.plot(x_mm, force, lw=1, color="C1")
ax_f.set_xlabel("contraction [mm]")
ax_f.set_ylabel("elements' force on the load [N]")
ax_f.set_title("Maxwell-slip force against contraction")
fig.savefig("plot_hysteresis_loops.png", dpi=120)
