"""Figures of a static-model atlas (:mod:`pamsim.atlas`): one per pressure and a combined one."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .constants import PA_PER_BAR
from .figure_style import save, series


def _draw(ax, atlas, p_Pa: float, legend: bool) -> None:
    for i, c in enumerate(c for c in atlas.curves if c.pressure_Pa == p_Pa):
        ax.plot(c.x_m * 1e3, c.F_N, lw=1.2, label=c.model, **series(i))
    pts = atlas.measured_near(p_Pa)
    if len(pts):
        ax.plot(pts[:, 1] * 1e3, pts[:, 2], "ko", ms=4, label="measured")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_title(f"{p_Pa / PA_PER_BAR:g} bar")
    ax.set_xlabel("contraction [mm]")
    ax.set_ylabel("force [N]")
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=7, ncol=2)


def plot_pressure(atlas, p_Pa: float, path, dpi: int | None = None) -> Figure:
    """Every model's force against contraction at one pressure, measured points overlaid; written to ``path``
    (PNG, PDF or SVG by its suffix) at ``dpi`` dots per inch (default 110)."""
    fig = Figure(figsize=(8, 5.5), constrained_layout=True)
    ax = fig.subplots()
    _draw(ax, atlas, p_Pa, legend=True)
    ax.set_title(f"{atlas.muscle.name}: static models at {p_Pa / PA_PER_BAR:g} bar")
    save(fig, path, dpi=dpi)
    return fig


def plot_all(atlas, path, dpi: int | None = None) -> Figure:
    """One panel per pressure, all models; one shared legend; written as :func:`plot_pressure` writes
    (default 100 dots per inch)."""
    n = len(atlas.pressures_Pa)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(4.2 * cols + 2.5, 3.4 * rows), constrained_layout=True)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax, p in zip(axes, atlas.pressures_Pa):
        _draw(ax, atlas, p, legend=False)
    for ax in axes[n:]:
        ax.set_visible(False)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside right upper", fontsize=7)
    fig.suptitle(f"{atlas.muscle.name}: isobaric force-contraction curves")
    save(fig, path, dpi=dpi, default_dpi=100)
    return fig
