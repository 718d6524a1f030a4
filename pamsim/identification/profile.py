"""Profile-likelihood intervals of least-squares coefficients.

The Wald interval ``theta +- t se`` trusts the linearisation at the optimum; where the residuals bend
(the equilibrium objective, censoring, a coefficient near where the model stops lifting a load) it
can be far off on one side.  The profile interval of coefficient ``j`` holds the values ``v`` for
which the sum of squares with ``theta_j = v`` and every other coefficient refitted stays within
``t^2 s^2`` of the minimum (``t`` the Student quantile of the fit's degrees of freedom, ``s^2`` its
residual variance): the likelihood-ratio test with an estimated variance (Bates and Watts, *Nonlinear
Regression Analysis*, 1988, sec. 6.1).  For residuals linear in the coefficients the two intervals are
the same.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.optimize import brentq, least_squares
from scipy.stats import t as student_t

LEVEL = 0.95
"""Coverage the intervals are made for."""
_MAX_DOUBLINGS = 8
"""The search for the far end of an interval doubles its step from the Wald half-width this often (256
half-widths) before calling that side open."""


def t_quantile(dof: int, level: float = LEVEL) -> float:
    """The two-sided Student-t quantile of ``dof`` degrees of freedom (NaN without any)."""
    return float(student_t.ppf(0.5 + level / 2.0, dof)) if dof > 0 else math.nan


class _Profile:
    """Sum of squares of the residuals with one coefficient held, the others refitted."""

    def __init__(self, residuals: Callable, jacobian: Callable, theta: np.ndarray, covariance: np.ndarray,
                 bounds: tuple[np.ndarray, np.ndarray], j: int):
        self.residuals, self.jacobian, self.theta, self.j = residuals, jacobian, theta, j
        self.others = np.arange(theta.size) != j
        # Start the others where the covariance says they move with theta_j: exact for linear residuals.
        self.slope = covariance[self.others, j] / covariance[j, j]
        self.lo, self.hi = bounds[0][self.others], bounds[1][self.others]
        self.scale = np.where(np.abs(theta[self.others]) > 0, np.abs(theta[self.others]), 1.0)

    def full(self, v: float, z: np.ndarray) -> np.ndarray:
        out = self.theta.copy()
        out[self.j] = v
        out[self.others] = z * self.scale
        return out

    def _start(self, v: float) -> np.ndarray:
        """Where the covariance says the others go with ``theta_j = v``, or where they are at the optimum if
        that fits better (the linear guess may leave the model's domain)."""
        moved = np.clip(self.theta[self.others] + self.slope * (v - self.theta[self.j]), self.lo, self.hi)
        kept = self.theta[self.others]
        cost = [float(np.sum(self.residuals(self.full(v, z / self.scale)) ** 2)) for z in (moved, kept)]
        return moved if cost[0] <= cost[1] else kept

    def _jacobian(self, theta: np.ndarray) -> np.ndarray:
        """The others' columns, scaled; zero where the model cannot be differentiated there (a refit that
        reached the edge of its domain stops, and the sum of squares there says how far it got)."""
        try:
            return self.jacobian(theta)[:, self.others] * self.scale
        except (ValueError, ArithmeticError):
            return np.zeros((self.residuals(theta).size, int(self.others.sum())))

    def ssr(self, v: float) -> float:
        if not self.others.any():
            r = self.residuals(self.full(v, np.empty(0)))
            return float(r @ r)
        res = least_squares(lambda z: self.residuals(self.full(v, z)), self._start(v) / self.scale,
                            jac=lambda z: self._jacobian(self.full(v, z)),
                            bounds=(self.lo / self.scale, self.hi / self.scale), method="trf",
                            xtol=1e-8, ftol=1e-8, gtol=1e-8)
        return float(2.0 * res.cost)


def _far_end(excess: Callable[[float], float], centre: float, step: float, limit: float) -> float:
    """Where ``excess`` (negative at ``centre``) turns positive going from ``centre`` by ``step`` towards
    ``limit``; ``limit`` (or an infinity) where it does not within the search."""
    inner = centre
    for _ in range(_MAX_DOUBLINGS):
        outer = centre + step
        if (outer - limit) * np.sign(step) >= 0:
            if math.isfinite(limit) and excess(limit) > 0:
                return brentq(excess, inner, limit, xtol=1e-3 * abs(step))
            return limit if math.isfinite(limit) else math.copysign(math.inf, step)
        if excess(outer) > 0:
            return brentq(excess, inner, outer, xtol=1e-3 * abs(step))
        inner, step = outer, 2.0 * step
    return math.copysign(math.inf, step)


def profile_intervals(residuals: Callable, jacobian: Callable, theta: np.ndarray, standard_errors: np.ndarray,
                      correlation: np.ndarray, bounds: tuple[np.ndarray, np.ndarray], dof: int,
                      level: float = LEVEL) -> np.ndarray:
    """``(k, 2)`` array of the profile intervals of the coefficients ``theta`` (NaN where the standard error
    is not finite: not identified, or no degrees of freedom; an infinity or a bound where the sum of squares
    never rises enough on that side).

    Parameters
    ----------
    residuals, jacobian : callables of the coefficients (physical units), as the fit's.
    theta : the least-squares optimum.
    standard_errors, correlation : the linearised uncertainty at ``theta``, which sets the search's first
        step and the starting point of the refits.
    bounds : the coefficients' bounds.
    dof : degrees of freedom of the residual variance.
    level : coverage.
    """
    theta = np.asarray(theta, dtype=float)
    se = np.asarray(standard_errors, dtype=float)
    out = np.full((theta.size, 2), math.nan)
    tq = t_quantile(dof, level)
    r0 = residuals(theta)
    ssr0 = float(r0 @ r0)
    if not (math.isfinite(tq) and ssr0 > 0):
        return out
    allowed = tq ** 2 * ssr0 / dof
    cov = np.where(np.isfinite(correlation), correlation, 0.0) * np.outer(np.nan_to_num(se), np.nan_to_num(se))
    for j in np.flatnonzero(np.isfinite(se) & (se > 0)):
        prof = _Profile(residuals, jacobian, theta, cov, bounds, int(j))

        def excess(v, prof=prof):
            return prof.ssr(v) - ssr0 - allowed
        out[j] = [_far_end(excess, theta[j], -tq * se[j], bounds[0][j]),
                  _far_end(excess, theta[j], tq * se[j], bounds[1][j])]
    return out
