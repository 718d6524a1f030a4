"""Figures of an uncertainty study: histograms and empirical CDFs of the summarised outputs.

Each function returns a matplotlib ``Figure`` (no pyplot state) for a
:class:`pamsim.sweep.uncertainty.UncertaintyResult`;
:data:`pamsim.sweep.figures.UNCERTAINTY_FIGURES` names them.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..figure_style import series
from .uncertainty import QUANTITIES, UncertaintyResult

def _panels(result: UncertaintyResult, title: str):
    fig = Figure(figsize=(13, 4))  # fixed margins: a layout engine's extra pass costs a third of the time
    axes = fig.subplots(1, len(QUANTITIES), gridspec_kw=dict(left=0.05, right=0.99, top=0.88, bottom=0.13, wspace=0.25))
    fig.suptitle(f"{title}: {result.spec.samples} samples, seed {result.spec.seed}")
    for ax, (q, label) in zip(axes, QUANTITIES.items()):
        scale = 1e3 if q.endswith("_m") else 1.0
        ax.set_xlabel(label)
        for k, f in enumerate(result.runs):
            yield fig, ax, f, series(k), np.sort(result.values(f, q)) * scale


def histogram_figure(result: UncertaintyResult) -> Figure:
    """One histogram panel per quantity, one outline per friction model, its median a thin line of its style."""
    fig = None
    for fig, ax, f, style, v in _panels(result, "Histograms"):
        if v.size:
            ax.hist(v, bins=min(50, max(5, int(np.sqrt(v.size)))), histtype="step", label=f,
                    color=style["color"], linestyle=style["linestyle"])
            ax.axvline(np.median(v), lw=0.8, color=style["color"], linestyle=style["linestyle"])
        ax.set_ylabel("runs")
        if ax.get_legend_handles_labels()[0]:  # none when every run of the study failed
            ax.legend(fontsize=8)
    return fig


def ecdf_figure(result: UncertaintyResult) -> Figure:
    """One empirical-CDF panel per quantity, with the study's quantiles marked."""
    fig = None
    for fig, ax, f, style, v in _panels(result, "Empirical CDF"):
        if v.size:
            ax.step(v, np.arange(1, v.size + 1) / v.size, where="post", label=f, **style)
        for p in result.spec.quantiles:
            ax.axhline(p, lw=0.5, color="0.7")
        ax.set_ylabel("fraction of runs <= value")
        ax.set_ylim(0, 1)
        if ax.get_legend_handles_labels()[0]:  # none when every run of the study failed
            ax.legend(fontsize=8)
    return fig

