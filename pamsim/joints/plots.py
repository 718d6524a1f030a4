"""Figures of a joint run: the angle, each muscle's pressure, and the torques on the link, over time."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..atomic import atomic_path
from ..constants import PA_PER_BAR
from ..figure_style import format_of, save, series
from ..plotting import shade_held


def joint_figure(result) -> Figure:
    """Three panels over time: the joint angle (shaded where the link is held), each muscle's gauge
    pressure, and each muscle's torque with gravity's and the net torque at rest."""
    fig = Figure(figsize=(7.5, 8.0), layout="constrained")
    ax_theta, ax_p, ax_tau = fig.subplots(3, 1, sharex=True)
    t = result.t_s
    shade_held(ax_theta, t, result.mode)
    ax_theta.plot(t, np.degrees(result.theta_rad), color="k", label="angle")
    ax_theta.set_ylabel("joint angle [deg]")
    ax_theta.legend(loc="best", fontsize="small")
    for k, m in enumerate(result.muscles):
        ax_p.plot(t, result.muscle(m, "p_gauge_Pa") / PA_PER_BAR, label=m, **series(k))
        ax_tau.plot(t, result.muscle(m, "tau_Nm"), label=f"{m} (tendon {np.max(result.muscle(m, 'F_tendon_N')):.3g} N max)",
                    **series(k))
    ax_tau.plot(t, result.signals["joint.tau_gravity_Nm"], label="gravity", **series(len(result.muscles), "C7"))
    ax_p.set_ylabel("gauge pressure [bar]")
    ax_p.legend(loc="best", fontsize="small")
    ax_tau.set_ylabel("torque on the link [N m]\n(positive turns it to larger angles)")
    ax_tau.set_xlabel("time [s]")
    ax_tau.legend(loc="best", fontsize="small")
    final = np.degrees(result.theta_rad[-1])
    fig.suptitle(f"{result.name}: {len(result.muscles)} muscles on a joint, final angle {final:.2f} deg "
                 f"({result.final_mode.label})", fontsize="medium")
    return fig


def plot_joint(result, path=None, dpi: int | None = None) -> Figure:
    """:func:`joint_figure`, written to ``path`` (atomically) if given: PNG, PDF or SVG by its suffix."""
    fmt = None if path is None else format_of(path)
    fig = joint_figure(result)
    if path is not None:
        with atomic_path(path) as tmp:
            save(fig, tmp, fmt, dpi)
    return fig
