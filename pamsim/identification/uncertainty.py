"""How far to trust fitted coefficients: standard errors and correlations from the Jacobian at the
optimum, the pairs the data cannot separate, and information criteria for model comparison.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

CORRELATION_LIMIT = 0.95
"""Above this absolute correlation two coefficients are reported as not separable by the data."""


@dataclass(frozen=True)
class Uncertainty:
    """Linearised uncertainty of a least-squares fit.

    ``covariance = s^2 (J^T J)^+`` with ``s^2 = SSR / (n - k)``, ``n`` the observations: rows of
    the Jacobian whose residual or derivatives are not all zero (a censored test the model does not lift
    observes nothing).  With no degrees of freedom left (``n <= k``) the standard errors are NaN but the correlations (which do not depend on
    ``s^2``) are still given.
    """

    names: tuple[str, ...]
    standard_errors: np.ndarray
    correlation: np.ndarray
    sigma: float
    identified: np.ndarray
    """Per coefficient: False where the data carry no information on it (its error is NaN)."""
    dof: int
    """Degrees of freedom of ``sigma``: observations minus coefficients."""

    def not_identified(self) -> tuple[str, ...]:
        """Coefficients the data carry no information on."""
        return tuple(n for n, ok in zip(self.names, self.identified) if not ok)

    def inseparable_pairs(self, limit: float = CORRELATION_LIMIT) -> list[tuple[str, str, float]]:
        """``(a, b, r)`` for every pair with ``|r| > limit``, strongest first."""
        out = []
        for i in range(len(self.names)):
            for j in range(i + 1, len(self.names)):
                r = float(self.correlation[i, j])
                if abs(r) > limit:
                    out.append((self.names[i], self.names[j], r))
        return sorted(out, key=lambda t: -abs(t[2]))

    def separable(self, limit: float = CORRELATION_LIMIT) -> tuple[str, ...]:
        """Coefficients correlated with no other beyond ``limit``."""
        tied = {n for a, b, _ in self.inseparable_pairs(limit) for n in (a, b)}
        return tuple(n for n in self.names if n not in tied)

    def groups(self, limit: float = CORRELATION_LIMIT) -> list[tuple[str, ...]]:
        """Sets of coefficients linked by correlations beyond ``limit`` (connected components)."""
        out: list[set[str]] = []
        for a, b, _ in self.inseparable_pairs(limit):
            hit = [g for g in out if a in g or b in g]
            merged = set().union({a, b}, *hit)
            out = [g for g in out if g not in hit] + [merged]
        return [tuple(n for n in self.names if n in g) for g in out]

    def best_combination(self, group: tuple[str, ...]) -> tuple[np.ndarray, float]:
        """The combination of ``group`` the data determine best, and its standard error.

        In coefficients measured in their standard errors (``theta_i / se_i``) it is the
        eigenvector of the group's correlation matrix with the smallest eigenvalue.  Returns the
        weights ``w`` (per unit of each coefficient; the combination is ``w . theta``) and the
        standard error of ``w . theta``.
        """
        idx = [self.names.index(n) for n in group]
        R = self.correlation[np.ix_(idx, idx)]
        vals, vecs = np.linalg.eigh(R)
        e = vecs[:, 0] * (1.0 if vecs[np.argmax(np.abs(vecs[:, 0])), 0] > 0 else -1.0)
        return e / self.standard_errors[idx], float(math.sqrt(max(vals[0], 0.0)))

    def identifiable(self, theta: np.ndarray, relative: float = 0.05, limit: float = CORRELATION_LIMIT) -> tuple[str, ...]:
        """Coefficients separable from all others whose standard error is at most ``relative`` of
        their value (so a two-sigma interval is within twice that)."""
        sep = set(self.separable(limit))
        return tuple(n for n, v, s in zip(self.names, theta, self.standard_errors)
                     if n in sep and math.isfinite(s) and s <= relative * abs(v))

    def correlation_table(self) -> dict:
        """``{"names": [...], "matrix": [[...]]}`` for JSON."""
        return {"names": list(self.names), "matrix": [[_num(v) for v in row] for row in self.correlation]}


RANK_TOLERANCE = 1.5e-8
"""Singular values of the column-scaled Jacobian below this fraction of the largest are taken as zero:
about the square root of the machine epsilon, the noise of the force sensitivities' differences."""
NULL_WEIGHT = 1e-6
"""A coefficient with at least this weight in a direction the data do not see is not identified."""


def linearised_uncertainty(names, jacobian: np.ndarray, residuals: np.ndarray) -> Uncertainty:
    """Standard errors and correlation of the coefficients ``names`` from the Jacobian of the residuals
    with respect to them (physical units) at the optimum.

    A coefficient along a direction the Jacobian does not see (a zero column, two columns alike) is
    not identified: its standard error and its correlations are NaN, never the 0 a pseudo-inverse
    would give.
    """
    J = np.asarray(jacobian, dtype=float)
    r = np.asarray(residuals, dtype=float)
    k = J.shape[1]
    # A row with no residual and no derivative (a censored test the model does not lift) observes
    # nothing: counted in n it shrinks s^2 and the errors with it.
    n = int(np.count_nonzero((r != 0.0) | np.any(J != 0.0, axis=1)))
    dof = n - k
    sigma2 = float(r @ r) / dof if dof > 0 else math.nan
    # Scale the columns before inverting: the coefficients differ by orders of magnitude.
    col = np.linalg.norm(J, axis=0)
    col[col == 0.0] = 1.0
    Js = J / col
    # Only V is used: the thin decomposition gives all of it (k x k) unless there are fewer rows than
    # coefficients; the full one would also form U, n x n, 0.5 GB and seconds for an 8 s trace at 1 kHz.
    _, sv, vt = np.linalg.svd(Js, full_matrices=J.shape[0] < k)
    sv = np.concatenate([sv, np.zeros(k - sv.size)])
    seen = sv > RANK_TOLERANCE * (sv[0] if sv.size and sv[0] > 0 else 1.0)
    identified = ~np.any(np.abs(vt[~seen]) >= NULL_WEIGHT, axis=0)
    with np.errstate(divide="ignore"):
        inv_sv2 = np.where(seen, 1.0 / np.where(seen, sv, 1.0) ** 2, 0.0)
    cov_s = (vt.T * inv_sv2) @ vt
    cov_unit = cov_s / np.outer(col, col)
    d = np.where(identified, np.sqrt(np.clip(np.diag(cov_unit), 0.0, None)), math.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov_unit / np.outer(d, d)
    corr = np.where(np.outer(d, d) > 0, corr, np.nan)
    np.fill_diagonal(corr, 1.0)
    return Uncertainty(tuple(names), d * math.sqrt(sigma2) if dof > 0 else np.full(k, math.nan),
                       np.clip(corr, -1.0, 1.0), math.sqrt(sigma2) if dof > 0 else math.nan, identified, dof)


def information_criteria(ssr: float, n: int, k: int, n_effective: float | None = None) -> tuple[float, float]:
    """(AIC, BIC) of a least-squares fit with Gaussian residuals: ``n ln(SSR/n) + 2k`` and ``+ k ln n``.

    With ``n_effective`` (the independent samples of a correlated residual), the likelihood and the BIC's
    penalty count those: ``n_eff ln(SSR/n) + 2k`` and ``+ k ln n_eff``."""
    if n == 0 or ssr <= 0.0:
        return -math.inf, -math.inf
    m = n if n_effective is None else n_effective
    base = m * math.log(ssr / n)
    return base + 2 * k, base + k * math.log(m)


def _num(v: float):
    return None if not math.isfinite(v) else float(v)
