"""Figures of a sweep, as matplotlib ``Figure`` objects (no pyplot global state).

Each ``*_figure`` function returns a Figure; :data:`pamsim.sweep.figures.SWEEP_FIGURES` names
them, and :mod:`.figures` renders them (the caller stages the files atomically).

The functions take a :class:`pamsim.sweep.SweepResult` but do not import it:
the result imports this module to write itself, and one direction is enough.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np
from matplotlib.colors import TwoSlopeNorm
from matplotlib.figure import Figure

from ..constants import PA_PER_BAR
from ..figure_style import REFERENCE, series
from ..plotting import draw_measured, measured_labels


def _grid_pressure(row: Mapping) -> float:
    """Row position on the pressure axis: the nominal step when measured data give it, else the case pressure."""
    p = row["pressure_step_bar"]
    return p if math.isfinite(p) else row["pressure_bar"]


def _empty(fig: Figure, text: str) -> Figure:
    ax = fig.subplots()
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes)
    ax.set_axis_off()
    return fig


def error_heatmap_figure(result: "SweepResult") -> Figure:
    """Contraction error (model minus measured, mm) over pressure x load, one panel per quantity."""
    rows = [r for r in result.rows if math.isfinite(r["measured_contraction_m"])]
    fig = Figure(figsize=(13, 6))
    if not rows:
        return _empty(fig, "no measured data to compare with")
    grid = _TestGrid.of(rows)
    first = result.spec.friction_models[0]
    panels = [("equilibrium_error_m", "static equilibrium - measured"),
              ("error_m", f"simulated final ({first} friction) - measured")]
    values = [grid.values_mm(col) for col, _ in panels]
    limit = _colour_limit(values)
    norm = TwoSlopeNorm(vcenter=0.0, vmin=-limit, vmax=limit)
    # Fixed margins rather than a layout engine: its extra layout pass is a third of a figure's time.
    axes = fig.subplots(1, 2, sharey=True, gridspec_kw=dict(left=0.05, right=0.9, top=0.89, bottom=0.09, wspace=0.05))
    for ax, g, (col, title) in zip(axes, values, panels):
        im = ax.imshow(g, origin="lower", cmap="RdBu_r", norm=norm, aspect="auto")
        ax.set_facecolor("0.85")  # missing tests show grey
        grid.label_cells(ax, g, limit)
        grid.set_ticks(ax)
        ax.set_xlabel("hanging weight [N]")
        ax.set_title(title, fontsize=10, y=1.0)
    axes[0].set_ylabel("pressure step [bar]")
    fig.colorbar(im, cax=fig.add_axes((0.915, 0.09, 0.012, 0.8)), label="contraction error [mm]")
    thr = result.spec.capability_min_equilibrium_m * 1e3
    fig.suptitle(f"{result.spec.name}: contraction error; hatched = beyond force capability "
                 f"(static equilibrium < {thr:g} mm), bold = within")
    return fig


def _colour_limit(values: list[np.ndarray]) -> float:
    """The largest absolute error of the panels, which both colour scales reach (1 where all are missing)."""
    if any(np.isfinite(g).any() for g in values):
        return max(float(np.nanmax(np.abs(g))) for g in values)
    return 1.0


@dataclass(frozen=True)
class _TestGrid:
    """The measured cases on the heatmap's pressure x load grid."""

    rows: list[Mapping]
    pressures: list[float]
    weights: list[float]

    @classmethod
    def of(cls, rows: list[Mapping]) -> "_TestGrid":
        return cls(rows, sorted({_grid_pressure(r) for r in rows}), sorted({r["weight_N"] for r in rows}))

    def values_mm(self, col: str) -> np.ndarray:
        """Column ``col`` of the rows [mm] on the grid, NaN where no test was measured."""
        g = np.full((len(self.pressures), len(self.weights)), np.nan)
        for r in self.rows:
            g[self.pressures.index(_grid_pressure(r)), self.weights.index(r["weight_N"])] = r[col] * 1e3
        return g

    def label_cells(self, ax, g: np.ndarray, limit: float) -> None:
        """Write each cell's error, bold within force capability, the cell hatched beyond it."""
        for i, p in enumerate(self.pressures):
            for j, w in enumerate(self.weights):
                if not math.isfinite(g[i, j]):
                    ax.text(j, i, "no data", ha="center", va="center", fontsize=7, color="0.4")
                    continue
                row = next(r for r in self.rows if _grid_pressure(r) == p and r["weight_N"] == w)
                ax.text(j, i, f"{g[i, j]:+.1f}", ha="center", va="center", fontsize=8,
                        color="white" if abs(g[i, j]) > 0.6 * limit else "black",
                        fontweight="bold" if row["within_capability"] else "normal")
                if not row["within_capability"]:
                    ax.add_patch(_hatch(j, i))

    def set_ticks(self, ax) -> None:
        ax.set_xticks(range(len(self.weights)), [f"{w:g}" for w in self.weights])
        ax.set_yticks(range(len(self.pressures)), [f"{p:g}" for p in self.pressures])


def _hatch(j: int, i: int):
    from matplotlib.patches import Rectangle

    return Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, hatch="///", edgecolor="0.5", lw=0)


def steady_state_figure(result: "SweepResult") -> Figure:
    """Measured against modelled steady-state contraction versus pressure, one colour per load."""
    fig = Figure(figsize=(13, 6))
    rows = result.rows
    if not rows:
        return _empty(fig, "no cases")
    first = result.spec.friction_models[0]
    axes = fig.subplots(1, 2, sharey=True, gridspec_kw=dict(left=0.05, right=0.99, top=0.9, bottom=0.09, wspace=0.04))
    panels = [("equilibrium_contraction_m", "static equilibrium (paper polynomial)"),
              ("final_contraction_m", f"simulated final contraction ({first} friction, 8 s run)")]
    weights = sorted({r["weight_N"] for r in rows})
    for ax, (col, title) in zip(axes, panels):
        for k, w in enumerate(weights):
            rs = sorted((r for r in rows if r["weight_N"] == w), key=lambda r: r["pressure_bar"])
            p = np.array([r["pressure_bar"] for r in rs])
            style = series(k)
            meas = np.array([r["measured_contraction_m"] for r in rs]) * 1e3
            if np.isfinite(meas).any():
                ax.plot(p, meas, "o", color=style["color"], ms=6, mfc="none", mew=1.5)
            ax.plot(p, np.array([r[col] for r in rs], dtype=float) * 1e3, lw=1.8, label=f"{w:g} N", **style)
        ax.set_xlabel("pressure [bar] (measured stable pressure)")
        ax.set_title(title, fontsize=10, y=1.0)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("steady-state contraction [mm]")
    axes[0].plot([], [], "ko", mfc="none", label="measured (Table 2)")
    axes[0].plot([], [], "k-", label="model")
    axes[0].legend(fontsize=8, loc="upper left", ncol=2)
    fig.suptitle(f"{result.spec.name}: steady-state contraction, measured (circles) and modelled (lines)")
    return fig


def time_responses_figure(result: "SweepResult") -> Figure:
    """Contraction against time for each response scenario, one line style per friction model."""
    names = list(result.responses)
    height_in = 3.2 * max(1, math.ceil(len(names) / 2))
    fig = Figure(figsize=(13, height_in))
    if not names:
        return _empty(fig, "no [time_responses] in the sweep file")
    measured = {s.name: s.measured_steady_state() for s in result.spec.time_responses}
    axes, ncols = _response_axes(fig, len(names), height_in, any(m is not None for m in measured.values()))
    for ax, name in zip(axes, names):
        _response_panel(ax, name, result.responses[name], measured.get(name))
    for ax in axes[len(names):]:
        ax.set_axis_off()
    for ax in axes[max(0, len(names) - ncols):len(names)]:
        ax.set_xlabel("time [s]")
    fig.suptitle(_responses_title(measured))
    return fig


def _response_axes(fig: Figure, n: int, height_in: float, two_line_title: bool) -> tuple[np.ndarray, int]:
    """Axes for ``n`` panels, two to a row (one if alone), with fixed margins for a title of one or two lines;
    and the number of columns."""
    ncols = 2 if n > 1 else 1
    nrows = math.ceil(n / ncols)
    title_in = 0.75 + (0.2 if two_line_title else 0.0)
    margins = dict(left=0.05, right=0.95, top=1 - title_in / height_in, bottom=0.5 / height_in, wspace=0.2, hspace=0.42)
    return np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False, gridspec_kw=margins).ravel()), ncols


def _response_panel(ax, name: str, runs: Mapping[str, dict], measured) -> None:
    """Scenario ``name``'s contraction under each friction model (a failed run said in red), its measured end if
    any, and the pressure of its first successful run on a grey right axis."""
    for k, (f, out) in enumerate(runs.items()):
        if out.get("error"):
            ax.text(0.5, 0.2 + 0.1 * k, f"{f}: failed", transform=ax.transAxes, color="red")
            continue
        ax.plot(out["t_s"], out["x_m"] * 1e3, lw=1.6, label=f"{f} friction", **series(k))
    if measured is not None:
        draw_measured(ax, measured, measured.contraction_mm, measured_labels(measured)[0])
    pax = ax.twinx()
    first = next((o for o in runs.values() if not o.get("error")), None)
    if first is not None:
        pax.plot(first["t_s"], first["p_gauge_Pa"] / PA_PER_BAR, **REFERENCE)
    pax.set_ylabel("pressure [bar]", color="0.5", fontsize=8)
    pax.tick_params(axis="y", colors="0.5", labelsize=8)
    # An explicit y spares matplotlib the search for tick labels above each axes (a third of the
    # figure's drawing time with the twin axes); nothing is drawn above these axes.
    ax.set_title(name, fontsize=10, y=1.0)
    ax.set_ylabel("contraction [mm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")


def _responses_title(measured: Mapping) -> str:
    """The figure's title, with a line on the measured tests' sources if any panel has one."""
    title = "Time responses: load-dependent against constant friction (grey dots: muscle pressure, right axis)"
    sources = sorted({m.source for m in measured.values() if m is not None})
    if sources:
        title += (f"\nmeasured: the final contraction only ({'; '.join(sources)}); "
                  "the paper draws the traces but does not give them as numbers")
    return title


def frequency_figure(result: "SweepResult") -> Figure:
    """Estimated oscillation frequency against load for each friction model."""
    fig = Figure(figsize=(8, 5.5))
    rows = result.frequency_rows
    if not rows:
        return _empty(fig, "no [frequency] study in the sweep file")
    models = result.spec.friction_models
    # The half-cycle counts go in a strip of their own under the plot, one row per friction model,
    # so that no label can sit on a marker.
    ax, strip = fig.subplots(2, 1, sharex=True, height_ratios=[5, 0.35 * len(models) + 0.3],
                             gridspec_kw=dict(left=0.16, right=0.98, top=0.92, bottom=0.09, hspace=0.08))
    w = np.array([r["weight_N"] for r in rows])
    for k, f in enumerate(models):
        freq = np.array([r[f"{f}_frequency_Hz"] for r in rows], dtype=float)
        n = [r[f"{f}_n_half_cycles"] for r in rows]
        ax.plot(w, freq, ms=7, mfc="none" if k else None, label=f"{f} friction", **series(k, points=True))
        for wi, fi, ni in zip(w, freq, n):
            strip.text(wi, len(models) - k, f"{ni}" if math.isfinite(fi) else "-", ha="center", va="center",
                       fontsize=8, color=f"C{k}")
    strip.set_ylim(0.4, len(models) + 0.6)
    strip.set_yticks(range(len(models), 0, -1), [f"n ({f})" for f in models], fontsize=7)
    strip.tick_params(axis="y", length=0)
    for side in ("top", "right", "left"):
        strip.spines[side].set_visible(False)
    strip.set_xlabel("hanging weight [N]")
    ax.set_ylabel("oscillation frequency [Hz]")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.suptitle(f"Oscillation frequency at {result.spec.frequency.pressure_bar:g} bar "
                 "(n: half-cycles seen after the pressure settled)", fontsize=11)
    return fig
