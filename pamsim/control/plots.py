"""Bode plot and pole-zero map of a linearisation (matplotlib Figures, no pyplot state)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..figure_style import series
from ..plotting import X_LABEL, draw_line_pressures, shade_held
from .linear import LinearModel

_BODE_CHANNELS = ((None, "contraction_m"), (None, "p_gauge_Pa"),
                  ("supply_gauge_Pa", "contraction_m"), ("F_ext_N", "contraction_m"))
"""The channels drawn, None for the valve's input (its command, or an averaged PWM valve's duty)."""


def bode_figure(lin: LinearModel) -> Figure:
    """Magnitude and phase of the main channels, each normalised to its own low-frequency level."""
    omega = lin.frequency_grid_rad_s()
    fig = Figure(figsize=(8, 7), constrained_layout=True)
    ax_m, ax_p = fig.subplots(2, 1, sharex=True)
    for k, (inp, out) in enumerate(_BODE_CHANNELS):  # a channel keeps its style whichever others are drawn
        inp = inp or lin.valve_input
        data = lin.bode(inp, out, omega)
        mag = np.asarray(data["magnitude"])
        if not np.any(mag > 0):
            continue  # a channel the operating point switches off (e.g. a saturated valve)
        ax_m.loglog(data["frequency_Hz"], mag, label=f"{inp} -> {out}", **series(k))
        ax_p.semilogx(data["frequency_Hz"], data["phase_deg"], **series(k))
    f_n = lin.mechanical_mode().natural_frequency_Hz
    for ax in (ax_m, ax_p):
        ax.axvline(f_n, color="k", ls=(0, (1, 3)), lw=1)  # sparse dots: no channel's style
        ax.grid(alpha=0.3, which="both")
    ax_m.set_ylabel("magnitude [SI output / SI input]")
    if ax_m.get_legend_handles_labels()[0]:  # every channel switched off: matplotlib would warn of an empty legend
        ax_m.legend(fontsize=8)
    ax_p.set_ylabel("phase [deg]")
    ax_p.set_xlabel("frequency [Hz]")
    fig.suptitle(f"Bode: {lin.op.kind}, {lin.friction.kind} friction; mechanical mode {f_n:.3g} Hz (dotted)")
    return fig


def pole_zero_figure(lin: LinearModel) -> Figure:
    """Poles of the linear model and zeros of the valve-command -> contraction channel."""
    fig = Figure(figsize=(6.5, 5.5), constrained_layout=True)
    ax = fig.subplots()
    poles = lin.sys.poles()
    channel = lin.sys["contraction_m", lin.valve_input]
    # A channel the operating point switches off (saturated valve) has no zeros to show.
    zeros = channel.zeros() if np.any(channel.B) else np.array([])
    zeros = zeros[np.isfinite(zeros)]
    ax.plot(poles.real, poles.imag, "x", ms=9, mew=2, label="poles")
    if zeros.size:
        ax.plot(zeros.real, zeros.imag, "o", mfc="none", ms=9, label="zeros valve -> contraction")
    else:
        ax.plot([], [], " ", label="valve -> contraction: no finite zeros")
    reals = np.concatenate([poles.real, zeros.real, [0.0]])
    span = max(np.max(np.abs(reals)), 1e-3)
    ax.set_xlim(min(reals.min(), -0.1 * span) * 1.3, max(reals.max(), 0.1 * span) * 1.3)
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    # Pressure poles can sit a decade beyond the mechanical pair: then symlog keeps both readable;
    # when every real part is small a linear axis reads better.
    w = max(lin.mechanical_mode().omega_n_rad_s, 1.0)
    if np.max(np.abs(reals)) > w / 10.0:
        ax.set_xscale("symlog", linthresh=w / 10.0)
    ax.set_xlabel("real [1/s]")
    ax.set_ylabel("imaginary [rad/s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    mode = lin.mechanical_mode()
    ax.set_title(f"f_n = {mode.natural_frequency_Hz:.3g} Hz, zeta = {mode.damping_ratio:.3g}")
    return fig


def closed_loop_figure(run) -> Figure:
    """Contraction against reference and linear prediction, pressure (the chamber's and those of the line's
    components, a tube's), and valve command (with a spool valve's position) of a closed-loop run."""
    res = run.result
    fig = Figure(figsize=(9, 8.5), constrained_layout=True)
    ax_x, ax_p, ax_u = fig.subplots(3, 1, sharex=True)
    shade_held(ax_x, res.t_s, res.mode)
    ax_x.plot(res.t_s, res.signals["reference_m"] * 1e3, lw=1, label="reference", **series(1, "k"))
    ax_x.plot(run.linear_t_s, run.linear_x_m * 1e3, lw=1, label="linear loop (design model)", **series(2, "C1"))
    ax_x.plot(res.t_s, res.x_m * 1e3, label="hybrid model", **series(0, "C0"))
    ax_x.set_ylabel(X_LABEL)
    ax_x.legend(loc="lower right", fontsize=8)
    ax_p.plot(res.t_s, res.p_gauge_Pa / 1e5, label="chamber", **series(0, "C3"))
    ax_p.plot(res.t_s, res.signals["feedforward_gauge_Pa"] / 1e5, label="holding pressure (feedforward)",
              **series(3, "k"))
    draw_line_pressures(ax_p, res, lw=1)
    ax_p.set_ylabel("gauge pressure [bar]")
    ax_p.legend(loc="lower right", fontsize=8)
    ax_u.plot(res.t_s, res.signals["valve_command"], label="command", **series(0, "C2"))
    if "spool_position" in res.signals:
        ax_u.plot(res.t_s, res.signals["spool_position"], lw=1, label="spool position", **series(1, "C9"))
        ax_u.legend(loc="upper right", fontsize=8)
    ax_u.set_ylabel("valve command [-]")
    ax_u.set_xlabel("time [s]")
    for ax in (ax_x, ax_p, ax_u):
        ax.grid(alpha=0.3)
    m = run.metrics
    fig.suptitle(f"{res.name}: rise {m['rise_time_s'] * 1e3:.0f} ms, overshoot {m['overshoot_percent']:.1f} %, "
                 f"settling {m['settling_time_s'] * 1e3:.0f} ms, steady-state error {m['steady_state_error_mm']:.3f} mm")
    return fig
