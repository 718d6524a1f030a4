"""Figures of identification results (kept apart from the fits)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np
from matplotlib.figure import Figure

from ..constants import PA_PER_BAR
from ..figure_style import save, series
from .equilibrium import equilibrium_m

if TYPE_CHECKING:
    from .dynamic_fit import DynamicFit
    from .static_fit import StaticFit


def _save(fig: Figure, path, dpi: int | None) -> Figure:
    """Write ``fig`` to ``path``, if given, as PNG, PDF or SVG by its suffix, at ``dpi`` dots per inch (default 110)."""
    if path is not None:
        save(fig, path, dpi=dpi)
    return fig


def plot_static_fit(fit: "StaticFit", path=None, dpi: int | None = None) -> Figure:
    """Measured contraction against pressure, one colour per load, with the fitted equilibrium curves."""
    d = fit.problem.data
    fig = Figure(figsize=(8, 5.5), constrained_layout=True)
    ax = fig.subplots()
    force = fit.problem.force(fit.theta).force_N
    x_high = fit.problem.stops(fit.theta).x_high_m
    p_grid = np.linspace(0.0, max(d.pressure_gauge_Pa.max(), 1.0) * 1.05, 200)
    loads = np.unique(np.round(d.load_N, 6))
    for i, w in enumerate(loads):
        rows = np.isclose(d.load_N, w)
        style = series(i)
        color = style["color"]
        cens = rows & fit.problem.censored
        ax.plot(d.pressure_gauge_Pa[rows & ~cens] / PA_PER_BAR, d.contraction_m[rows & ~cens] * 1e3, "o",
                color=color, label=f"{w:g} N measured")
        ax.plot(d.pressure_gauge_Pa[cens] / PA_PER_BAR, d.contraction_m[cens] * 1e3, "x", color=color)
        x_fit = equilibrium_m(force, p_grid, np.full_like(p_grid, w), x_high)
        ax.plot(p_grid / PA_PER_BAR, x_fit * 1e3, lw=1.2, **style)
    ax.set_xlabel("gauge pressure [bar]")
    ax.set_ylabel("contraction [mm]")
    ax.set_title(f"{fit.problem.model}, {fit.problem.objective} objective: lines = fitted equilibrium, "
                 "x = censored (not lifted)", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    return _save(fig, path, dpi)


def plot_static_residuals(fit: "StaticFit", path=None, dpi: int | None = None) -> Figure:
    """Equilibrium error (fitted minus measured) against pressure, and the objective's residuals."""
    d = fit.problem.data
    fig = Figure(figsize=(8, 6), constrained_layout=True)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    p = d.pressure_gauge_Pa / PA_PER_BAR
    cens = fit.problem.censored
    err = (fit.predicted_m - d.contraction_m) * 1e3
    ax1.scatter(p[~cens], err[~cens], c=d.load_N[~cens], cmap="viridis", label="lifted")
    ax1.scatter(p[cens], err[cens], marker="x", color="grey", label="censored")
    ax1.axhline(0.0, color="k", lw=0.8)
    ax1.set_ylabel("equilibrium - measured [mm]")
    ax1.legend(fontsize=8)
    ax2.scatter(p, fit.residuals, c=d.load_N, cmap="viridis")
    ax2.axhline(0.0, color="k", lw=0.8)
    unit = "N" if fit.problem.objective == "force" else "mm"
    ax2.set_ylabel(f"objective residual [{unit}]" if fit.problem.weights is None else "objective residual / sigma")
    ax2.set_xlabel("gauge pressure [bar] (colour: load)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    return _save(fig, path, dpi)


def plot_correlation(names: Sequence[str], corr: np.ndarray, path=None, dpi: int | None = None) -> Figure:
    """The correlation matrix of the fitted coefficients, with its values printed."""
    k = len(names)
    fig = Figure(figsize=(1.2 + 0.9 * k, 1.0 + 0.8 * k), constrained_layout=True)
    ax = fig.subplots()
    im = ax.imshow(corr, vmin=-1, vmax=1, cmap="RdBu_r")
    ax.set_xticks(range(k), names, rotation=45, ha="right", fontsize=8)
    ax.set_yticks(range(k), names, fontsize=8)
    for i in range(k):
        for j in range(k):
            ax.text(j, i, f"{corr[i, j]:.2f}", ha="center", va="center", fontsize=7)
    fig.colorbar(im, ax=ax, shrink=0.8)
    return _save(fig, path, dpi)


def plot_comparison(rows: Sequence[dict], path=None, dpi: int | None = None) -> Figure:
    """RMS and cross-validated RMS contraction error of each compared model."""
    fig = Figure(figsize=(1.5 + 1.3 * len(rows), 4.5), constrained_layout=True)
    ax = fig.subplots()
    idx = np.arange(len(rows))
    ax.bar(idx - 0.2, [r["rms_contraction_mm"] for r in rows], 0.4, label="fit RMS")
    ax.bar(idx + 0.2, [r["cv_rms_contraction_mm"] for r in rows], 0.4, label="cross-validated RMS", hatch="//",
           edgecolor="white")  # hatched: told apart in grey print too
    ax.set_xticks(idx, [f"{r['model']}\n({r['n_free']} free, Akaike weight {r['akaike_weight']:.2g})" for r in rows],
                  fontsize=8)
    ax.set_ylabel("contraction error RMS [mm]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    return _save(fig, path, dpi)


def plot_dynamic_fit(fit: "DynamicFit", path=None, dpi: int | None = None) -> Figure:
    """Measured and fitted contraction of every trace, with the residuals below."""
    n = len(fit.traces)
    fig = Figure(figsize=(9, 3.2 * n + 1), constrained_layout=True)
    axes = fig.subplots(2 * n, 1, squeeze=False, height_ratios=[3, 1] * n)[:, 0]
    for i, tr in enumerate(fit.traces):
        ax, axr = axes[2 * i], axes[2 * i + 1]
        mask = fit.windows[i]
        ax.plot(tr.t_s, tr.x_m * 1e3, ".", ms=2, color="0.5", label="measured")
        ax.plot(tr.t_s, fit.simulated_m[i] * 1e3, **series(0), label="fitted")
        if fit.start_simulated_m:
            ax.plot(tr.t_s, fit.start_simulated_m[i] * 1e3, **series(1), lw=0.8, label="start")
        ax.axvspan(tr.t_s[mask][0], tr.t_s[mask][-1], color="C2", alpha=0.06)
        ax.set_ylabel("contraction [mm]")
        ax.set_title(f"{Path(tr.origin).name} ({fit.loads_N[i]:g} N): RMS {fit.rms_contraction_mm[i]:.3f} mm in the window",
                     fontsize=9)
        ax.legend(fontsize=8)
        axr.plot(tr.t_s[mask], (fit.simulated_m[i][mask] - tr.x_m[mask]) * 1e3, color="C3", lw=0.8)
        axr.axhline(0.0, color="k", lw=0.6)
        axr.set_ylabel("fit - meas. [mm]", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    return _save(fig, path, dpi)
