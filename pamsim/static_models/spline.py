"""One interpolating spline surface F(x, p), evaluated on floats by SciPy and on symbols by CasADi.

A measured force map (:mod:`pamsim.static_models.force_map`) and the table of a static model that
needs a numerical solve (:mod:`pamsim.elements.force_table`) are both this: the bicubic
interpolating spline of values on a rectangular grid (``scipy.interpolate.RectBivariateSpline``,
``s = 0``; the degree lowered to ``n - 1`` along an axis of fewer than four values).  Its knots and
coefficients are the one description of the surface.  On floats and numpy arrays SciPy evaluates
them (FITPACK); on CasADi MX symbols the same knots and coefficients become a CasADi B-spline
(``casadi.Function.bspline``), which CasADi differentiates and writes as C for the native engine and
the FMU.  The two agree to rounding (``tests/test_spline_table.py``).

Outside the grid the surface is held at its edge (the nearest point of the grid), never
extrapolated: a cubic's extrapolation runs away.
"""

from __future__ import annotations

import numpy as np


def _is_symbol(value) -> bool:
    return type(value).__module__.startswith("casadi")


class SplineSurface:
    """The interpolating spline of ``F_N[i, j]`` at ``(x_m[i], p_Pa[j])`` (strictly increasing grids).

    Parameters
    ----------
    x_m, p_Pa : the grid's contractions [m] and gauge pressures [Pa].
    F_N : the values [N], shape ``(len(x_m), len(p_Pa))``.
    """

    def __init__(self, x_m: np.ndarray, p_Pa: np.ndarray, F_N: np.ndarray):
        from scipy.interpolate import RectBivariateSpline  # on use: `pamsim --help` starts without it

        x, p = np.asarray(x_m, dtype=float), np.asarray(p_Pa, dtype=float)
        self.degrees = (min(3, len(x) - 1), min(3, len(p) - 1))
        self._spline = RectBivariateSpline(x, p, np.asarray(F_N, dtype=float), kx=self.degrees[0],
                                           ky=self.degrees[1], s=0)
        self.x_lo, self.x_hi, self.p_lo, self.p_hi = float(x[0]), float(x[-1]), float(p[0]), float(p[-1])
        self._casadi = None

    @property
    def knots(self) -> tuple[np.ndarray, np.ndarray]:
        """The full knot vectors along x and p (boundary knots repeated degree + 1 times)."""
        tx, ty, _ = self._spline.tck
        return tx, ty

    @property
    def coefficients(self) -> np.ndarray:
        """The B-spline coefficients, shape ``(len(tx) - kx - 1, len(ty) - ky - 1)``."""
        tx, ty, c = self._spline.tck
        return np.asarray(c).reshape(len(tx) - self.degrees[0] - 1, len(ty) - self.degrees[1] - 1)

    def code_key(self) -> tuple:
        """What code generated from the surface depends on: degrees, knots and coefficients (a hash), the
        same in every process (:func:`pamsim.components.element.structure_key` asks for it)."""
        import hashlib

        h = hashlib.sha256()
        for a in (*self.knots, self.coefficients):
            h.update(np.ascontiguousarray(a, dtype=float).tobytes())
        return ("spline", self.degrees, h.hexdigest())

    def __call__(self, x_m, p_gauge_Pa):
        """F at ``(x_m, p_gauge_Pa)`` held inside the grid: floats, numpy arrays or CasADi MX symbols."""
        if _is_symbol(x_m) or _is_symbol(p_gauge_Pa):
            return self._symbolic(x_m, p_gauge_Pa)
        if type(x_m) is float and type(p_gauge_Pa) is float:
            x = min(max(x_m, self.x_lo), self.x_hi)
            p = min(max(p_gauge_Pa, self.p_lo), self.p_hi)
            return float(self._spline.ev(x, p))
        x, p = np.broadcast_arrays(np.asarray(x_m, dtype=float), np.asarray(p_gauge_Pa, dtype=float))
        out = self._spline.ev(np.clip(x, self.x_lo, self.x_hi), np.clip(p, self.p_lo, self.p_hi))
        return out if np.ndim(out) else float(out)

    def _symbolic(self, x, p):
        import casadi as ca

        if self._casadi is None:
            tx, ty = self.knots
            # CasADi takes the coefficients with the first dimension fastest (column-major).
            self._casadi = ca.Function.bspline("force_spline", [list(tx), list(ty)],
                                               list(self.coefficients.ravel(order="F")), list(self.degrees), 1, {})
        held = ca.vertcat(ca.fmin(ca.fmax(x, self.x_lo), self.x_hi), ca.fmin(ca.fmax(p, self.p_lo), self.p_hi))
        return self._casadi(held)
