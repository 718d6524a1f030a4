"""Where a dynamic fit may start, and which signs its coefficients may take.

A dynamic fit's cost surface has many local minima: stick/slip switches the motion's shape, and the
friction and damping terms trade against one another.  A fit started from the scenario's values alone
can stop in one of them, far above the noise (docs/identification.md has the measured cases), so the
fit also starts from seeded random points: half of them near the start, the others far, each
coefficient drawn on a log scale up to the size at which its term alone would carry the heaviest hung
weight over the motion the traces show (its *typical scale*), with either sign the bounds allow.  The
points are screened by their cost, one batch of simulations, and the local fit runs from the best of
them.  Then it *hops*: local fits from seeded points near the best fit so far (30 % of each
coefficient), which escape the shallow minima next to the best one far more often than random points
do (``python benchmarks/bench_multistart.py``: 3 of 12 hops from each of two such minima reached the
truth, against 1 and 0 of 12 random points).
"""

from __future__ import annotations

import numpy as np

SIGN_LOWER_BOUNDS = {"N0_N_per_bar": 0.0, "D2_N_s2_per_m2": 0.0}
"""Lower bounds the physics sets on dynamic coefficients, whatever the parameter schema allows.

``N0_N_per_bar``: the Coulomb level at zero contraction, ``(P - phi m) N0``, is a friction force's
magnitude and cannot be negative.  ``D2_N_s2_per_m2``: at high speed the damping ``D1 v + D2 v |v|``
is dominated by the quadratic term, which must oppose the motion.  ``N1`` and ``N2`` shape the level
along the travel and may take either sign as long as the level stays positive; ``D1`` may be negative
(the ACRA 2012 paper's is -1.01 N s/m: the term adds energy at low speed, docs/model.md), so neither
is bounded."""

SCREEN_POINTS_PER_START = 25
"""Random points screened by their cost for every extra start."""
LOG_SPAN_DECADES = 2.5
"""A far random point's magnitude is the typical scale times ``10 ** U(-2.5, 0)``."""
NEAR_SPREAD = 0.3
"""Relative spread of the random points near the start."""
HOP_SPREAD = 0.3
"""Relative spread of a hop around the best fit so far."""


def sign_bounds(free, lower: np.ndarray) -> np.ndarray:
    """``lower`` raised to the physics' sign bounds (:data:`SIGN_LOWER_BOUNDS`) of the coefficients ``free``."""
    return np.array([max(lo, SIGN_LOWER_BOUNDS.get(n, -np.inf)) for n, lo in zip(free, lower)], dtype=float)


def _speed_scale_m_per_s(traces) -> float:
    """The largest speed the traces show, from differences over 10 ms (noise of 0.05 mm makes
    about 7 mm/s there, not the 70 mm/s of neighbouring 1 kHz samples)."""
    speeds = []
    for tr in traces:
        k = max(1, int(np.searchsorted(tr.t_s, tr.t_s[0] + 0.01)))
        if k < len(tr.t_s):
            speeds.append(np.max(np.abs(tr.x_m[k:] - tr.x_m[:-k]) / (tr.t_s[k:] - tr.t_s[:-k])))
    return max(speeds, default=0.0)


def typical_scales(problem, theta0: np.ndarray) -> np.ndarray:
    """Per free coefficient, the value at which its term alone carries the heaviest hung weight over the
    traces' largest contraction, speed and pressure; a coefficient that is no friction or damping term
    keeps the size of its start value (1 where that is 0)."""
    weight = max(problem.loads_N)
    pressures = [tr.p_gauge_Pa.max() for tr in problem.traces if tr.p_gauge_Pa is not None]
    p_bar = max(pressures, default=problem.scenario.final_pressure_gauge_Pa) / 1e5
    x = max(float(np.ptp(tr.x_m)) for tr in problem.traces)
    v = _speed_scale_m_per_s(problem.traces)
    term = {"N0_N_per_bar": p_bar, "N1_N_per_bar_m": p_bar * x, "N2_N_per_bar_m2": p_bar * x ** 2,
            "D1_N_s_per_m": v, "D2_N_s2_per_m2": v ** 2, "coulomb_constant_N": 1.0}
    own = np.where(np.abs(theta0) > 0, np.abs(theta0), 1.0)
    out = np.array([weight / term[n] if term.get(n, 0.0) > 0 else o for n, o in zip(problem.free, own)])
    return np.where(np.isfinite(out) & (out > 0), out, own)


def random_points(theta0: np.ndarray, scales: np.ndarray, bounds: tuple[np.ndarray, np.ndarray], n: int,
                  seed: int) -> np.ndarray:
    """``n`` seeded points (rows), clipped into the bounds: every other one near the start (``theta0`` times
    ``1 + 0.3 N(0, 1)``, the static fit's starts), the rest far (magnitude ``scales * 10 ** U(-2.5, 0)``, a
    random sign where the bounds allow both); a coefficient starting at 0 is drawn far in both."""
    rng = np.random.default_rng(seed)
    lo, hi = bounds
    magnitude = scales * 10.0 ** rng.uniform(-LOG_SPAN_DECADES, 0.0, (n, scales.size))
    sign = rng.choice([-1.0, 1.0], (n, scales.size))
    far = np.where(lo >= 0.0, 1.0, np.where(hi <= 0.0, -1.0, sign)) * magnitude
    near = theta0 * (1.0 + NEAR_SPREAD * rng.standard_normal((n, scales.size)))
    use_near = (np.arange(n) % 2 == 0)[:, None] & (theta0 != 0.0)
    return np.clip(np.where(use_near, near, far), lo, hi)


def global_box(theta0: np.ndarray, scales: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
               span: float) -> list[tuple[float, float]]:
    """Differential evolution's box: the start plus or minus ``span`` times the larger of its size and the
    typical scale, within the bounds (a start of 0 gets a box too)."""
    half = span * np.maximum(np.abs(theta0), scales)
    lo, hi = bounds
    return list(zip(np.maximum(theta0 - half, lo), np.minimum(theta0 + half, hi)))


def hop_point(theta: np.ndarray, scales: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              rng: np.random.Generator) -> np.ndarray:
    """A point near the best fit so far, ``theta``, clipped into the bounds: each coefficient moved by
    ``0.3 N(0, 1)`` times the larger of its size and the smallest far magnitude (``scales * 10 ** -2.5``),
    so that a coefficient fitted to 0 moves too."""
    size = np.maximum(np.abs(theta), scales * 10.0 ** -LOG_SPAN_DECADES)
    return np.clip(theta + HOP_SPREAD * size * rng.standard_normal(theta.size), *bounds)
