"""Figures of a static-model atlas (:mod:`pamsim.atlas`): one per pressure and a combined one.

Models that give the same curve (:attr:`pamsim.atlas.Atlas.groups`) are one line with one legend entry,
``gaylord = de_volder = ...``; each group keeps its line style in every panel and figure.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .constants import PA_PER_BAR
from .figure_style import save, series

MEASURED_LABEL = "measured"
"""Legend entry of the muscle's measured points."""


def group_label(group) -> str:
    """The legend entry of a group of models with the same curve: ``"gaylord = de_volder"``."""
    return " = ".join(group)


def _draw(ax, atlas, p_Pa: float, legend: bool) -> None:
    at_p = {c.model: c for c in atlas.curves if c.pressure_Pa == p_Pa}
    for i, group in enumerate(atlas.groups):  # the style follows the group, whichever are drawn here
        c = at_p.get(group[0])
        if c is not None:
            ax.plot(c.x_m * 1e3, c.F_N, lw=1.2, label=group_label(group), **series(i))
    pts = atlas.measured_near(p_Pa)
    if len(pts):
        ax.plot(pts[:, 1] * 1e3, pts[:, 2], "ko", ms=4, label=MEASURED_LABEL)
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


def grid_shape(n: int) -> tuple[int, int]:
    """Rows and columns for ``n`` panels: one row up to three, else 2, 3 or 4 columns, whichever leaves
    the fewest free cells (at most one: the legend takes it)."""
    if n <= 3:
        return 1, n
    cols = min((3, 2, 4), key=lambda c: math.ceil(n / c) * c - n)
    return math.ceil(n / cols), cols


def plot_all(atlas, path, dpi: int | None = None) -> Figure:
    """One panel per pressure, all models, and one legend for them all: in the grid's free cell if it has
    one, else to the right; written as :func:`plot_pressure` writes (default 100 dots per inch)."""
    n = len(atlas.pressures_Pa)
    rows, cols = grid_shape(n)
    free = rows * cols > n
    longest = max(len(group_label(g)) for g in atlas.groups)
    legend_in = 0.0 if free else max(2.5, 0.6 + 0.055 * longest)  # about 0.055 in a character at 7 points
    fig = Figure(figsize=(4.2 * cols + legend_in, 3.4 * rows), constrained_layout=True)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax, p in zip(axes, atlas.pressures_Pa):
        _draw(ax, atlas, p, legend=False)
    entries = {}  # every panel's lines, each label once, in the order of the groups, "measured" last
    for ax in axes[:n]:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    order = [group_label(g) for g in atlas.groups] + [MEASURED_LABEL]
    labels = [label for label in order if label in entries]
    handles = [entries[label] for label in labels]
    if free:
        axes[n].axis("off")
        axes[n].legend(handles, labels, loc="center", fontsize=7, frameon=False)
    else:
        fig.legend(handles, labels, loc="outside right center", fontsize=7)  # below the title, not beside it
    fig.suptitle(f"{atlas.muscle.name}: isobaric force-contraction curves")
    save(fig, path, dpi=dpi, default_dpi=100)
    return fig
