"""Static equilibrium of many (pressure, load) pairs at once, and its sensitivity.

The same definition as :func:`pamsim.static.equilibrium_contraction_m` (the smallest x in
``[0, x_max]`` where the static force falls through the load; 0 if it cannot lift it, ``x_max`` if
it still pulls harder there), vectorised over the tests so that a fit can evaluate all of them in
a few numpy calls: a grid brackets the first fall, then bisection refines every bracket together.
"""

from __future__ import annotations

import numpy as np

N_GRID = 200
"""Grid points over [0, x_max] that bracket the first fall (0.6 mm apart for the Shadow muscle)."""
N_BISECT = 48
"""Bisection halvings of each bracket: 0.6 mm / 2**48 is below 1e-17 m."""


def equilibrium_m(force_N, p_gauge_Pa: np.ndarray, load_N: np.ndarray, x_max_m: float,
                  n_grid: int = N_GRID) -> np.ndarray:
    """Equilibrium contraction [m] of each test.

    Parameters
    ----------
    force_N : callable
        ``force_N(x_m, p_gauge_Pa)``, vectorised with numpy broadcasting.
    p_gauge_Pa, load_N : array
        Gauge pressure [Pa] and load [N] of each test.
    x_max_m : float
        Upper end of the search (the upper stop).
    """
    p = np.asarray(p_gauge_Pa, dtype=float)
    w = np.asarray(load_N, dtype=float)
    x = np.linspace(0.0, x_max_m, n_grid)
    g = force_N(x[None, :], p[:, None]) - w[:, None]
    falls = (g[:, :-1] > 0.0) & (g[:, 1:] <= 0.0)
    has_fall = falls.any(axis=1)
    first = np.argmax(falls, axis=1)
    out = np.where(g[:, 0] <= 0.0, 0.0, x_max_m)
    idx = np.flatnonzero(has_fall & (g[:, 0] > 0.0))
    if idx.size:
        lo = x[first[idx]]
        hi = x[first[idx] + 1]
        pi, wi = p[idx], w[idx]
        for _ in range(N_BISECT):
            mid = 0.5 * (lo + hi)
            above = force_N(mid, pi) - wi > 0.0
            lo = np.where(above, mid, lo)
            hi = np.where(above, hi, mid)
        out[idx] = 0.5 * (lo + hi)
    return out


def slope_N_per_m(force_N, x_m: np.ndarray, p_gauge_Pa: np.ndarray, h_m: float = 1e-6) -> np.ndarray:
    """dF/dx [N/m] by a central difference (the force is smooth in x)."""
    return (force_N(x_m + h_m, p_gauge_Pa) - force_N(x_m - h_m, p_gauge_Pa)) / (2.0 * h_m)
