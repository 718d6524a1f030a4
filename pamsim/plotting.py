"""Plots of results.  Kept apart from the model and the Result class.

The functions take a :class:`pamsim.Result` without importing it: ``Result.plot``
imports this module, and one direction of dependency is enough.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .atomic import atomic_path
from .constants import PA_PER_BAR


_FORCES = (("F_static_N", "static"), ("F_gravity_N", "gravity"), ("F_friction_N", "friction"),
           ("F_damping_N", "damping"), ("F_stop_N", "stop contact"), ("F_external_N", "external"))


def plot_result(result: "Result", path=None, title: str | None = None, compare: "list[Result] | None" = None) -> Figure:
    """Contraction, pressure and force components against time.

    ``compare`` overlays the contraction of other results (for example the
    constant-friction model).  With ``path`` the figure is written there (PNG,
    atomically) as well as returned.
    """
    fig = Figure(figsize=(9, 9), constrained_layout=True)
    ax_x, ax_p, ax_f = fig.subplots(3, 1, sharex=True)
    t = result.t_s
    ax_x.plot(t, result.x_m * 1e3, color="C0", label=result.name)
    for other in compare or []:
        ax_x.plot(other.t_s, other.x_m * 1e3, "--", label=other.name)
    held = result.mode == 0
    if held.any():
        ax_x.fill_between(t, 0, 1, where=held, transform=ax_x.get_xaxis_transform(), color="0.85", lw=0,
                          label="stuck (friction)")
    ax_x.set_ylabel("contraction x [mm]")
    ax_x.legend(loc="lower right", fontsize=8)
    ax_x.grid(alpha=0.3)

    ax_p.plot(t, result.p_gauge_Pa / PA_PER_BAR, color="C3", label="muscle")
    if "supply_gauge_Pa" in result.signals:
        ax_p.plot(t, result.signals["supply_gauge_Pa"] / PA_PER_BAR, ":", color="k", label="supply")
    ax_p.set_ylabel("gauge pressure [bar]")
    ax_p.legend(loc="lower right", fontsize=8)
    ax_p.grid(alpha=0.3)

    for key, label in _FORCES:
        values = result.signals[key]
        if np.any(values != 0.0):
            ax_f.plot(t, values, label=label, lw=1)
    ax_f.set_ylabel("force on the load [N]")
    ax_f.set_xlabel("time [s]")
    ax_f.legend(loc="upper right", fontsize=8, ncol=3)
    ax_f.grid(alpha=0.3)
    fig.suptitle(title or f"{result.name}: {result.mass_kg * result.g_m_s2:.2f} N hanging weight "
                          f"({result.mass_kg:.3f} kg), {result.p_gauge_Pa[-1] / PA_PER_BAR:.2f} bar at the end")
    if path is not None:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=110)
    return fig
