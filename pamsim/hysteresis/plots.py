"""Figures of a hysteresis fit (kept apart from the fit): the loop measured and fitted, the residuals, and a
compensation study's identification and tracking errors."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from ..figure_style import REFERENCE, save, series

if TYPE_CHECKING:
    from .compensation import CompensationStudy
    from .fit import HysteresisFit
    from .loop_data import LoopData


HANGING_LOAD_FORCE = "W - F_static"
"""What a loop measured at a hanging load fits in place of a measured force: the weight less the muscle's
static force at the measured contraction and pressure (:mod:`pamsim.hysteresis.hanging_load`)."""


def force_quantity(data: "LoopData") -> str:
    """The name of the loop's fitted quantity: ``W - F_static`` for a loop at a hanging load, else ``force``.

    A loop at a hanging load carries its friction law's level (``level_N``), as ``report.md`` tells it by.
    """
    return HANGING_LOAD_FORCE if data.level_N is not None else "force"


def plot_loop(fit: "HysteresisFit", path=None, dpi: int | None = None) -> Figure:
    """Force (at a hanging load ``W - F_static``) against contraction: the loop and every model's best fit."""
    d = fit.data
    quantity = force_quantity(d)
    fig = Figure(figsize=(7, 5), constrained_layout=True)
    ax = fig.subplots()
    measured = "measured" if quantity == "force" else f"{quantity} at the measured x and p"
    ax.plot(d.x_m * 1e3, d.force_N, ".", color="0.6", markersize=2, label=measured)
    for i, (name, f) in enumerate(fit.models.items()):
        chosen = " (reported)" if f is fit.chosen else ""
        ax.plot(d.x_m * 1e3, f.force_N, **series(i + 1), label=f"{f.label}: RMS {f.rms_N:.3g} N{chosen}")
    ax.set_xlabel("contraction [mm]")
    ax.set_ylabel(f"{quantity} [N]")
    ax.legend(fontsize="small")
    if path is not None:
        save(fig, path, dpi=dpi)
    return fig


def plot_residuals(fit: "HysteresisFit", path=None, dpi: int | None = None) -> Figure:
    """The reported model's residual (measured minus fitted force, at a hanging load ``W - F_static`` minus
    its fit) against time and against contraction."""
    d, f = fit.data, fit.chosen
    ylabel = "residual [N]" if force_quantity(d) == "force" else f"residual of {force_quantity(d)} [N]"
    fig = Figure(figsize=(8, 5), constrained_layout=True)
    top, bottom = fig.subplots(2, 1)
    top.plot(d.t_s, f.residual_N, **series(0))
    top.axhline(0.0, **REFERENCE)
    top.set_xlabel("time [s]")
    top.set_ylabel(ylabel)
    top.set_title(f"{f.label}: RMS {f.rms_N:.3g} N", fontsize="medium")
    bottom.plot(d.x_m * 1e3, f.residual_N, ".", markersize=2, color=series(0)["color"])
    bottom.axhline(0.0, **REFERENCE)
    bottom.set_xlabel("contraction [mm]")
    bottom.set_ylabel(ylabel)
    if path is not None:
        save(fig, path, dpi=dpi)
    return fig


def plot_compensation(study: "CompensationStudy", path=None, dpi: int | None = None) -> Figure:
    """The identification loop with the compensator's fit, then at each frequency the tracking error without
    and with compensation."""
    runs = study.runs
    fig = Figure(figsize=(7, 2.6 * (1 + len(runs))), constrained_layout=True)
    axes = fig.subplots(1 + len(runs), 1)
    d, c = study.identification.loop, study.identification.compensator
    axes[0].plot(d.x_m * 1e3, d.force_N, ".", color="0.6", markersize=1.5, label="identification loop (noisy)")
    axes[0].plot(d.x_m * 1e3, c.force_N, **series(1), label=f"compensator {c.label}: RMS {c.rms_N:.3g} N")
    axes[0].set_xlabel("contraction [mm]")
    axes[0].set_ylabel(f"{HANGING_LOAD_FORCE} [N]")
    axes[0].legend(fontsize="small")
    for ax, run in zip(axes[1:], runs):
        for i, (kind, res) in enumerate(run.results.items()):
            error_mm = (res.x_m - np.interp(res.t_s, run.signals[kind].t_s, run.signals[kind].reference_m)) * 1e3
            ax.plot(res.t_s, error_mm, **series(i), label=f"{kind}: RMS {run.rms_m[kind] * 1e3:.3f} mm")
        ax.axhline(0.0, **REFERENCE)
        ax.axvline(run.from_s, **REFERENCE)
        ax.set_title(f"{run.frequency_Hz:g} Hz: {run.reduction_percent:.0f} % lower with compensation "
                     f"({study.backend})", fontsize="medium")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("x - r [mm]")
        ax.legend(fontsize="small")
    if path is not None:
        save(fig, path, dpi=dpi)
    return fig


__all__ = ["plot_compensation", "plot_loop", "plot_residuals"]
