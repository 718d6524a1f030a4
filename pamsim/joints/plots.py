"""Figures of a joint (or slider) run: the angle (position), each muscle's pressure, and the torques on the link
(forces on the carriage), over time."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..atomic import atomic_path
from ..constants import PA_PER_BAR
from ..figure_style import format_of, save, series
from ..plotting import shade_held


DISPLAY = {"joint": ("joint angle [deg]", np.degrees, "deg", "torque on the link [N m]\n(positive turns it to larger angles)"),
           "slider": ("position [mm]", lambda x: 1e3 * np.asarray(x), "mm",
                      "force on the carriage [N]\n(positive moves it to larger x)")}
"""How a figure shows each body's coordinate and efforts: label, conversion from SI, unit, effort label."""


def joint_figure(result) -> Figure:
    """Three panels over time: the joint angle (shaded where the link is held), each muscle's gauge
    pressure, and each muscle's torque with gravity's and the external torque (a slider's: its position
    and the forces on the carriage); a fourth, the gas temperature, when a muscle's chamber is thermal."""
    body = result.body
    label, convert, unit, effort_label = DISPLAY[body.name]
    thermal = result.thermal_muscles()
    fig = Figure(figsize=(7.5, 10.0 if thermal else 8.0), layout="constrained")
    ax_theta, ax_p, ax_tau, *ax_gas = fig.subplots(4 if thermal else 3, 1, sharex=True)
    t = result.t_s
    shade_held(ax_theta, t, result.mode)
    ax_theta.plot(t, convert(result.position), color="k", label=body.noun)
    ax_theta.set_ylabel(label)
    ax_theta.legend(loc="best", fontsize="small")
    for k, m in enumerate(result.muscles):
        ax_p.plot(t, result.muscle(m, "p_gauge_Pa") / PA_PER_BAR, label=m, **series(k))
        ax_tau.plot(t, result.muscle(m, body.attach_effort),
                    label=f"{m} (tendon {np.max(result.muscle(m, 'F_tendon_N')):.3g} N max)", **series(k))
    ax_tau.plot(t, result.body_signal(body.effort_name("gravity")), label="gravity", **series(len(result.muscles), "C7"))
    external = result.body_signal(body.effort_name("applied"))
    if np.any(external != 0.0):
        ax_tau.plot(t, external, label="external", **series(len(result.muscles) + 1, "C4"))
    ax_p.set_ylabel("gauge pressure [bar]")
    ax_p.legend(loc="best", fontsize="small")
    ax_tau.set_ylabel(effort_label)
    ax_tau.legend(loc="best", fontsize="small")
    for ax in ax_gas:  # a thermal chamber's gas temperature (its own state)
        for k, m in enumerate(result.muscles):
            if m in thermal:
                ax.plot(t, result.muscle(m, "gas_temperature_K") - 273.15, label=m, **series(k))
        ax.set_ylabel("gas temperature [degC]")
        ax.legend(loc="best", fontsize="small")
    (ax_gas or [ax_tau])[-1].set_xlabel("time [s]")
    final = convert(result.position[-1])
    n = len(result.muscles)
    fig.suptitle(f"{result.name}: {n} muscle{'s' if n > 1 else ''} on a {body.name}, final {body.noun} {final:.2f} {unit} "
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


def equilibrium_map_figure(emap) -> Figure:
    """The equilibrium angle and the stiffness over the two muscles' pressures
    (:class:`pamsim.joints.static.EquilibriumMap`), with lines of equal angle drawn on the stiffness:
    along one, co-contraction changes the stiffness and not the angle."""
    fig = Figure(figsize=(10.0, 4.4), layout="constrained")
    ax_theta, ax_k = fig.subplots(1, 2, sharey=True)
    a, b = emap.p_first_Pa / PA_PER_BAR, emap.p_second_Pa / PA_PER_BAR
    theta_deg = np.degrees(emap.theta_rad)
    for ax, values, label in ((ax_theta, theta_deg, "equilibrium angle [deg]"),
                              (ax_k, emap.k_Nm_per_rad, "stiffness -dtau/dtheta [N m/rad]")):
        mesh = ax.pcolormesh(b, a, values, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=label)
        ax.set_xlabel(f"{emap.names[1]} gauge pressure [bar]")
    lines = ax_k.contour(b, a, theta_deg, colors="w", linewidths=0.8)
    ax_k.clabel(lines, fmt="%.0f deg", fontsize="x-small")
    ax_theta.contour(b, a, theta_deg, colors="w", linewidths=0.8)
    limited = emap.on_limit != ""
    if limited.any():
        i, j = np.nonzero(limited)
        ax_theta.plot(b[j], a[i], "x", color="C3", ms=4, label="on a joint limit")
        ax_theta.legend(loc="lower right", fontsize="x-small")
    ax_theta.set_ylabel(f"{emap.names[0]} gauge pressure [bar]")
    fig.suptitle("Joint at rest: angle and stiffness over the two pressures (white: lines of equal angle)",
                 fontsize="medium")
    return fig


def closed_loop_figure(run, names, title: str) -> Figure:
    """A closed-loop joint run (:class:`pamsim.joints.control.ClosedLoopJoint`): the angle against its
    reference, the two muscles' pressures (``names``, in the scenario's order), and the stiffness against
    its target."""
    fig = Figure(figsize=(7.5, 8.0), layout="constrained")
    ax_theta, ax_p, ax_k = fig.subplots(3, 1, sharex=True)
    t = run.t_s
    ax_theta.plot(t, np.degrees(run.reference_rad), label="reference", **series(1, "C7"))
    ax_theta.plot(t, np.degrees(run.theta_rad), color="k", label="angle")
    ax_theta.set_ylabel("joint angle [deg]")
    ax_theta.legend(loc="best", fontsize="small")
    for k, name in enumerate(names):
        ax_p.plot(t, run.p_Pa[:, k] / PA_PER_BAR, label=name, **series(k))
    ax_p.set_ylabel("gauge pressure [bar]\n(the controller's outputs)")
    ax_p.legend(loc="best", fontsize="small")
    ax_k.plot(t, run.k_Nm_per_rad, color="k", label="stiffness at rest at the angle and pressures")
    ax_k.axhline(run.k_target_Nm_per_rad, **series(1, "C3"), label="commanded")
    ax_k.set_ylabel("stiffness [N m/rad]")
    ax_k.set_xlabel("time [s]")
    ax_k.legend(loc="best", fontsize="small")
    fig.suptitle(title, fontsize="medium")
    return fig
