"""Static models that need a numerical solve, tabulated once for the dynamics.

An implicit library model (kind ``"implicit"``) solves an equation at every
point, far too slow for the ODE's inner loop.  :func:`tabulate` samples it once
over contraction and pressure and returns a :class:`TabulatedStaticForce`: the
bicubic interpolating spline of the samples
(:class:`pamsim.static_models.spline.SplineSurface`, the scheme of a measured
force map), evaluated by SciPy in Python and by CasADi's B-spline in the C the
native engine runs, so both backends run one table.  Outside the grid the
force is held at its edge.  Tables are cached in memory per model, variant,
parameter values and grid, so a sweep builds each one once per process.

The grid starts uniform and follows the model where it varies: a cell whose
centre the spline misses by more than :data:`REFINE_TOL` of the force scale is
split there, along contraction and along pressure, until none does.  An
interpolating spline is global, so one unresolved sample spoils cells far from
it: a bladder model's push diverges as the inverse square root of the distance
to its domain's end (the bladder filling the braid), and on a uniform grid the
spline rings back from the last node with alternating sign, falling only by
2 + sqrt(3) per cell, into cells where the force should be clipped to zero.
Splitting grades the grid toward such an end until the spline follows it.

The table error is measured by :func:`table_error` (at the cell centres) and
documented in docs/model.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from ..static_models.spline import SplineSurface

N_X = 65
"""Grid points along the contraction that refinement starts from (a pamsim choice: the grid of the
FMU's force table; the smooth library models need no more, docs/model.md)."""
N_P = 33
"""Grid points along the pressure that refinement starts from."""
REFINE_TOL = 2.5e-4
"""Largest miss of the spline at a cell centre, relative to the larger of the table's largest pull and
the force there (a pamsim choice: a quarter of the 0.1 % of the blocked force the tables are held to,
docs/model.md, leaving room for the points between the centres)."""
MAX_NODES = 513
"""Most grid points along either axis that refinement makes (a pamsim choice: a bound on the build's
cost where a model cannot be followed, such as a jump)."""
_CACHE_SIZE = 64
_CACHE: dict[tuple, "TabulatedStaticForce"] = {}


@dataclass(frozen=True, eq=False)
class TabulatedStaticForce:
    """The interpolating spline of ``F[i, j] = F(x_i, p_j)`` on a grid [m, Pa, N], held at the grid's edges.

    ``name`` and ``domain`` are those of the tabulated model.
    """

    name: str
    domain: object
    x_grid_m: np.ndarray = field(repr=False)
    p_grid_Pa: np.ndarray = field(repr=False)
    F_N: np.ndarray = field(repr=False)

    def __post_init__(self):
        object.__setattr__(self, "_surface", SplineSurface(self.x_grid_m, self.p_grid_Pa, self.F_N))

    def force_N(self, x_m, p_gauge_Pa):
        """Interpolated force [N] at contraction ``x_m`` [m] and gauge pressure [Pa] (floats, arrays or
        CasADi MX symbols)."""
        return self._surface(x_m, p_gauge_Pa)


def grid_limits(domain, x_range_m: tuple[float, float], p_range_Pa: tuple[float, float]):
    """The part of ``x_range_m`` x ``p_range_Pa`` inside the model's domain: ``(x_lo, x_hi, p_lo, p_hi)``."""
    x_lo, x_hi = max(domain.x_min_m, x_range_m[0]), min(domain.x_max_m, x_range_m[1])
    p_lo, p_hi = max(domain.p_min_Pa, p_range_Pa[0]), min(domain.p_max_Pa, p_range_Pa[1])
    if not (x_lo < x_hi and p_lo < p_hi and all(map(math.isfinite, (x_lo, x_hi, p_lo, p_hi)))):
        raise ValueError(f"no finite grid: contraction [{x_lo:g}, {x_hi:g}] m, pressure [{p_lo:g}, {p_hi:g}] Pa")
    return x_lo, x_hi, p_lo, p_hi


def _sample(model, X: np.ndarray, P: np.ndarray) -> np.ndarray:
    """The model on a grid: one vectorised call, or point by point when it only takes floats."""
    try:
        F = np.asarray(model.force_N(X, P), dtype=float)
        if F.shape == X.shape:
            return F
    except (TypeError, ValueError):
        pass
    return np.array([float(model.force_N(float(x), float(p))) for x, p in zip(X.ravel(), P.ravel())]).reshape(X.shape)


def tabulate(model, x_range_m: tuple[float, float], p_range_Pa: tuple[float, float], n_x: int = N_X,
             n_p: int = N_P, key: tuple | None = None, refine_tol: float | None = REFINE_TOL) -> TabulatedStaticForce:
    """Tabulate ``model.force_N`` over the ranges clipped to its domain, on an ``n_x`` x ``n_p`` uniform
    grid refined where the model varies (module docstring).

    Parameters
    ----------
    model : a built static model (``force_N``, ``name``, ``domain``).
    x_range_m, p_range_Pa : the region the dynamics can reach (stops, 0 .. rating).
    n_x, n_p : grid points to start from.
    key : identifies the model for the in-memory cache (for example the model
        name, variant and parameter values); None disables the cache.
    refine_tol : :data:`REFINE_TOL`, or None for the uniform grid as it is.

    Raises
    ------
    ValueError
        If the model gives a non-finite value on the grid.
    """
    limits = grid_limits(model.domain, x_range_m, p_range_Pa)
    full_key = None if key is None else (key, limits, n_x, n_p, refine_tol)
    if full_key is not None and full_key in _CACHE:
        return _CACHE[full_key]
    x = np.linspace(limits[0], limits[1], n_x)
    p = np.linspace(limits[2], limits[3], n_p)
    X, P = np.meshgrid(x, p, indexing="ij")
    F = _sample(model, X, P)
    if not np.all(np.isfinite(F)):
        i, j = np.argwhere(~np.isfinite(F))[0]
        raise ValueError(f"static model {model.name!r} is not finite at x = {x[i]:g} m, p = {p[j]:g} Pa")
    if refine_tol is not None:
        x, p, F = _refined(model, x, p, F, refine_tol)
    table = TabulatedStaticForce(model.name, model.domain, x, p, F)
    if full_key is not None:
        if len(_CACHE) >= _CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[full_key] = table
    return table


def _refined(model, x: np.ndarray, p: np.ndarray, F: np.ndarray, tol: float):
    """The grid ``(x, p, F)`` with cells split at their centres, along x and along p in turn, until the
    spline misses no centre by more than ``tol`` of the larger of the largest pull and the force there."""
    positive = float(F.max())
    scale = positive if positive > 0.0 else float(np.abs(F).max())
    samples = _Samples(model)
    while True:
        x, F, split_x = _split_cells(samples.at, x, p, F, tol, scale)
        p, Ft, split_p = _split_cells(lambda P, X: samples.at(X, P), p, x, F.T, tol, scale)
        F = Ft.T
        if not (split_x or split_p):
            return x, p, F


class _Samples:
    """The model's values, each point solved once however often refinement asks for it (an implicit
    model's solve is the build's cost)."""

    def __init__(self, model):
        self.model, self.known = model, {}

    def at(self, X: np.ndarray, P: np.ndarray) -> np.ndarray:
        keys = list(zip(X.ravel().tolist(), P.ravel().tolist()))
        new = [k for k in dict.fromkeys(keys) if k not in self.known]
        if new:
            xs, ps = np.array(new).T
            self.known.update(zip(new, _sample(self.model, xs, ps).tolist()))
        return np.array([self.known[k] for k in keys]).reshape(X.shape)


def _split_cells(sample, x: np.ndarray, p: np.ndarray, F: np.ndarray, tol: float, scale: float):
    """Split every cell along ``x`` whose centre, at the nodes ``p``, the spline of ``F`` misses by more
    than ``tol * max(scale, |F|)``: the centre's samples (``sample(X, P)``) become a row of ``F``.
    Returns ``(x, F, split)``; nothing is split once ``x`` would grow past :data:`MAX_NODES`."""
    centres = 0.5 * (x[1:] + x[:-1])
    X, P = np.meshgrid(centres, p, indexing="ij")
    exact = sample(X, P)
    miss = np.abs(SplineSurface(x, p, F)(X, P) - exact).max(axis=1)
    bad = miss > tol * np.maximum(scale, np.abs(exact).max(axis=1))  # False where the model is not finite
    if not bad.any() or len(x) + int(bad.sum()) > MAX_NODES:
        return x, F, False
    order = np.argsort(np.concatenate([x, centres[bad]]), kind="stable")
    return np.concatenate([x, centres[bad]])[order], np.concatenate([F, exact[bad]])[order], True


def table_error(model, table: TabulatedStaticForce) -> float:
    """Largest ``|table - model|`` [N] at the centres of the table's cells (where interpolation is worst)."""
    x, p = table.x_grid_m, table.p_grid_Pa
    X, P = np.meshgrid(0.5 * (x[1:] + x[:-1]), 0.5 * (p[1:] + p[:-1]), indexing="ij")
    return float(np.max(np.abs(_sample(model, X, P) - table.force_N(X, P))))


def clear_cache() -> None:
    """Forget every cached table."""
    _CACHE.clear()


def cache_key(model_name: str, variant: str | None, params: Mapping[str, float]) -> tuple:
    """Cache key of a model built from ``params``: the muscle is its parameter values."""
    return (model_name, variant, tuple(sorted((k, v if isinstance(v, float) else str(v)) for k, v in params.items())))
