"""Frequency and damping of an oscillating trace, from its turning points.

The load of a McKibben muscle under Coulomb friction does not ring like a
viscous oscillator: its swings shrink linearly and it usually sticks at a
turning point.  Both cases share one property that this estimator relies on:
successive turning points (where the velocity is zero) are half a period apart
(``pi / omega_d`` for viscous damping, ``pi / omega_n`` for Coulomb friction).
So the frequency comes from the spacing of turning points, over whole periods
only: the swing up and the swing down need not last as long (with a
load-dependent friction they do not), and averaging an odd number of
half-periods would weight one direction more.  The damping comes from
the ratio of successive swings (peak-to-peak excursions), which needs no
estimate of the centre the trace oscillates about.

A turning point is accepted only once the trace has moved back from it by more
than a hysteresis (a fraction of the trace's range), so solver ripple and
slow creep do not count as oscillation.  A trace that ends stuck on a plateau
counts the start of the plateau as its last turning point: the load stopped
there with zero velocity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

HYSTERESIS_FRACTION = 0.005
"""Reversal needed to confirm a turning point, as a fraction of the trace's range (0.5 %)."""

MIN_HYSTERESIS_M = 1e-6
"""Floor of the hysteresis [m]: swings below 1 micrometre are numerical ripple, not motion."""


@dataclass(frozen=True)
class Oscillation:
    """What :func:`estimate_oscillation` found.

    Attributes
    ----------
    frequency_Hz : float
        Damped oscillation frequency: whole periods counted, divided by the time
        they span (the last half-period is left out when their number is odd);
        NaN with fewer half-periods than asked for.
    damping_ratio : float
        Equivalent viscous damping ratio from the mean logarithmic decrement of
        successive swings; NaN with fewer than three turning points.
    n_half_cycles : int
        Number of half-periods (intervals between turning points) measured.
    turning_times_s : tuple of float
        Times of the accepted turning points.
    half_period_asymmetry : float
        ``(mean rising half-period - mean falling half-period) / mean half-period``:
        how much longer the swing up lasts than the swing down; NaN without one of each.
    """

    frequency_Hz: float
    damping_ratio: float
    n_half_cycles: int
    turning_times_s: tuple[float, ...]
    half_period_asymmetry: float = math.nan


def estimate_oscillation(t_s, x, t_start_s: float | None = None, hysteresis: float | None = None,
                         min_half_cycles: int = 2) -> Oscillation:
    """Estimate frequency and damping of ``x(t)`` after ``t_start_s``.

    Parameters
    ----------
    t_s : array_like
        Sample times [s], strictly increasing (uniform sampling not required).
    x : array_like
        The oscillating quantity (any unit; the hysteresis is in the same unit).
    t_start_s : float, optional
        Ignore samples before this time (for example the valve opening); the
        first motion after it, from rest, is not counted as a turning point.
    hysteresis : float, optional
        Reversal that confirms a turning point.  Default: ``HYSTERESIS_FRACTION``
        of the range of ``x`` after ``t_start_s``, at least ``MIN_HYSTERESIS_M``.
    min_half_cycles : int
        Fewest half-periods that give a frequency (default 2, one whole period: one
        lone swing that ends in a stick is too easily shaped by the still-changing
        input).  With 1, a lone half-period T gives ``1 / (2 T)``.

    Returns
    -------
    Oscillation
        NaN frequency and damping when the trace turns too few times to say
        (an overdamped creep, or a load that sticks on its first overshoot).
    """
    t = np.asarray(t_s, dtype=float)
    y = np.asarray(x, dtype=float)
    if t.shape != y.shape or t.ndim != 1:
        raise ValueError("t_s and x must be 1-D arrays of the same length")
    if t_start_s is not None:
        keep = t >= t_start_s
        t, y = t[keep], y[keep]
    if y.size < 3:
        return Oscillation(math.nan, math.nan, 0, ())
    if hysteresis is None:
        hysteresis = max(HYSTERESIS_FRACTION * float(np.ptp(y)), MIN_HYSTERESIS_M)
    idx = _turning_indices(y, hysteresis)
    times = np.array([_refine_time(t, y, i) for i in idx])
    n_half = max(len(idx) - 1, 0)
    frequency = math.nan
    if n_half >= max(min_half_cycles, 2):
        n_full = n_half // 2
        frequency = n_full / float(times[2 * n_full] - times[0])
    elif n_half == 1 and min_half_cycles <= 1:
        frequency = 1.0 / (2.0 * float(times[1] - times[0]))
    asymmetry = math.nan
    if n_half >= 2:
        halves = np.diff(times)
        rising = y[idx[1:]] > y[idx[:-1]]  # the half-period ends on a maximum: the swing went up
        if rising.any() and (~rising).any():
            asymmetry = float((halves[rising].mean() - halves[~rising].mean()) / halves.mean())
    damping = math.nan
    if len(idx) >= 3:
        swings = np.abs(np.diff(y[idx]))
        # Each swing spans half a period; the full-period log decrement is twice the half-period one.
        delta = 2.0 * float(np.mean(np.log(swings[:-1] / swings[1:])))
        damping = delta / math.sqrt(4.0 * math.pi ** 2 + delta ** 2)
    return Oscillation(frequency, damping, n_half, tuple(float(v) for v in times), asymmetry)


def _turning_indices(y: np.ndarray, hysteresis: float) -> list[int]:
    """Indices of turning points confirmed by a reversal larger than ``hysteresis``.

    A zig-zag filter: follow the running extreme in the current direction and
    record it once the trace has come back by more than ``hysteresis``.  It visits
    only :func:`_candidates` (the first sample of every local extremum and the ends),
    which gives the same points as visiting every sample.
    """
    found: list[int] = []
    direction = 0
    extreme = 0
    n = y.size
    idx = _candidates(y).tolist()
    # Python floats of the candidates only: indexing a numpy array per sample costs several times more.
    y = dict(zip(idx, y[idx].tolist()))
    for i in idx[1:]:
        if direction == 0:
            # The first motion away from the start sets the direction; the start itself is not
            # a turning point (the response to a step begins there, not an oscillation).
            if abs(y[i] - y[0]) > hysteresis:
                direction = 1 if y[i] > y[0] else -1
                extreme = i
        elif direction * (y[i] - y[extreme]) > 0.0:
            extreme = i
        elif direction * (y[extreme] - y[i]) > hysteresis:
            found.append(extreme)
            direction = -direction
            extreme = i
    # The last running extreme is a turning point if the trace stopped there (stuck, or
    # turned back by less than the hysteresis) rather than still moving at the end.
    if direction != 0 and extreme <= n - 3:
        found.append(extreme)
    return found


def _candidates(y: np.ndarray) -> np.ndarray:
    """The samples the zig-zag filter can stop at: the first sample, the first sample of every local
    extremum and of the last value (a plateau counts from its first sample).

    A sample equal to its predecessor changes nothing in the filter (it neither passes the running
    extreme nor reverses further), and inside a strictly monotone run the running extreme moves on to
    the run's end whether or not the filter turned inside it; so the filter's turning points are among
    these samples.  A flat (stuck) stretch of a trace costs nothing.
    """
    n = y.size
    if n < 3:
        return np.arange(n)
    new = np.concatenate(([0], np.flatnonzero(np.diff(y) != 0.0) + 1))  # first sample of each new value
    rising = np.diff(y[new]) > 0.0
    turns = new[1:-1][rising[1:] != rising[:-1]]
    return np.concatenate(([0], turns, new[-1:] if new[-1] > 0 else [])).astype(np.intp)  # increasing


def _refine_time(t: np.ndarray, y: np.ndarray, i: int) -> float:
    """Sub-sample time of the extremum at ``i`` from the parabola through its neighbours."""
    if i <= 0 or i >= y.size - 1:
        return float(t[i])
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    curvature = y0 - 2.0 * y1 + y2
    if curvature == 0.0 or y2 == y1:
        # A plateau (a stuck load) starts exactly at this sample.
        return float(t[i])
    shift = 0.5 * (y0 - y2) / curvature  # in samples, within [-0.5, 0.5] at a true extremum
    shift = min(max(shift, -0.5), 0.5)
    step = t[i + 1] - t[i] if shift > 0 else t[i] - t[i - 1]
    return float(t[i] + shift * step)
