"""Bode plot and pole-zero map of a linearisation (matplotlib Figures, no pyplot state)."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .linear import LinearModel

_BODE_CHANNELS = (("valve_command", "contraction_m"), ("valve_command", "p_gauge_Pa"),
                  ("supply_gauge_Pa", "contraction_m"), ("F_ext_N", "contraction_m"))


def bode_figure(lin: LinearModel) -> Figure:
    """Magnitude and phase of the main channels, each normalised to its own low-frequency level."""
    omega = lin.frequency_grid_rad_s()
    fig = Figure(figsize=(8, 7), constrained_layout=True)
    ax_m, ax_p = fig.subplots(2, 1, sharex=True)
    for inp, out in _BODE_CHANNELS:
        data = lin.bode(inp, out, omega)
        mag = np.asarray(data["magnitude"])
        if not np.any(mag > 0):
            continue  # a channel the operating point switches off (e.g. a saturated valve)
        ax_m.loglog(data["frequency_Hz"], mag, label=f"{inp} -> {out}")
        ax_p.semilogx(data["frequency_Hz"], data["phase_deg"])
    f_n = lin.mechanical_mode().natural_frequency_Hz
    for ax in (ax_m, ax_p):
        ax.axvline(f_n, color="k", ls=":", lw=1)
        ax.grid(alpha=0.3, which="both")
    ax_m.set_ylabel("magnitude [SI output / SI input]")
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
    zeros = lin.sys["contraction_m", "valve_command"].zeros()
    ax.plot(poles.real, poles.imag, "x", ms=9, mew=2, label="poles")
    if zeros.size:
        ax.plot(zeros.real, zeros.imag, "o", mfc="none", ms=9, label="zeros valve -> contraction")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    # Pressure poles can sit a decade beyond the mechanical pair; symlog keeps both readable.
    w = max(lin.mechanical_mode().omega_n_rad_s, 1.0)
    ax.set_xscale("symlog", linthresh=max(w / 10.0, 1e-3))
    ax.set_xlabel("real [1/s]")
    ax.set_ylabel("imaginary [rad/s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    mode = lin.mechanical_mode()
    ax.set_title(f"f_n = {mode.natural_frequency_Hz:.3g} Hz, zeta = {mode.damping_ratio:.3g}"
                 + ("" if math.isfinite(mode.damping_ratio) else ""))
    return fig
