"""Figures of a hysteresis fit (kept apart from the fit): the loop measured and fitted, and the residuals."""

from __future__ import annotations

from typing import TYPE_CHECKING

from matplotlib.figure import Figure

from ..figure_style import REFERENCE, save, series

if TYPE_CHECKING:
    from .fit import HysteresisFit


def plot_loop(fit: "HysteresisFit", path=None, dpi: int | None = None) -> Figure:
    """Force against contraction: the measured loop and every model's best fit."""
    d = fit.data
    fig = Figure(figsize=(7, 5), constrained_layout=True)
    ax = fig.subplots()
    ax.plot(d.x_m * 1e3, d.force_N, ".", color="0.6", markersize=2, label="measured")
    for i, (name, f) in enumerate(fit.models.items()):
        chosen = " (reported)" if f is fit.chosen else ""
        ax.plot(d.x_m * 1e3, f.force_N, **series(i + 1), label=f"{f.label}: RMS {f.rms_N:.3g} N{chosen}")
    ax.set_xlabel("contraction [mm]")
    ax.set_ylabel("force [N]")
    ax.legend(fontsize="small")
    if path is not None:
        save(fig, path, dpi=dpi)
    return fig


def plot_residuals(fit: "HysteresisFit", path=None, dpi: int | None = None) -> Figure:
    """The reported model's residual (measured minus fitted force) against time and against contraction."""
    d, f = fit.data, fit.chosen
    fig = Figure(figsize=(8, 5), constrained_layout=True)
    top, bottom = fig.subplots(2, 1)
    top.plot(d.t_s, f.residual_N, **series(0))
    top.axhline(0.0, **REFERENCE)
    top.set_xlabel("time [s]")
    top.set_ylabel("residual [N]")
    top.set_title(f"{f.label}: RMS {f.rms_N:.3g} N", fontsize="medium")
    bottom.plot(d.x_m * 1e3, f.residual_N, ".", markersize=2, color=series(0)["color"])
    bottom.axhline(0.0, **REFERENCE)
    bottom.set_xlabel("contraction [mm]")
    bottom.set_ylabel("residual [N]")
    if path is not None:
        save(fig, path, dpi=dpi)
    return fig


__all__ = ["plot_loop", "plot_residuals"]
