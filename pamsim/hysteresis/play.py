"""The play operator, the rate-independent memory that the Maxwell-slip and Prandtl-Ishlinskii models are
built from, evaluated exactly for an input that is linear between its samples.

A play of half-width ``r`` has the state ``z`` and follows ``z <- min(max(z, u - r), u + r)``.  Between two
reversals of the input (a monotone run) it is ``max(z_a, u - r)`` on a rising run and ``min(z_a, u + r)`` on a
falling one, ``z_a`` its state where the run starts: the loop over samples becomes a loop over runs, with
numpy over the samples of each run and over the thresholds.  Since the input is monotone between two samples,
the state at each sample is exactly what a continuous input through the same points would leave (no step
size, no time: the operator is rate independent by construction).
"""

from __future__ import annotations

import numpy as np


def monotone_runs(u: np.ndarray) -> list[tuple[int, int, int]]:
    """``(start, stop, sign)`` of the monotone runs of ``u``: samples ``start..stop`` (inclusive) move in one
    direction, ``sign`` +1 rising, -1 falling.  A flat stretch belongs to the run before it (it changes no
    play); an input that never moves is one run of sign 0.  Consecutive runs share their end sample.
    """
    d = np.sign(np.diff(u))
    moving = np.flatnonzero(d)
    if moving.size == 0:
        return [(0, len(u) - 1, 0)]
    signs = d[moving]
    turns = moving[1:][signs[1:] != signs[:-1]]  # the interval where the direction changes
    starts = np.concatenate(([0], turns))
    stops = np.concatenate((turns, [len(u) - 1]))
    run_signs = np.concatenate(([signs[0]], signs[1:][signs[1:] != signs[:-1]]))
    return [(int(a), int(b), int(s)) for a, b, s in zip(starts, stops, run_signs)]


def reversals(u: np.ndarray, dead_band: float = 0.0) -> int:
    """The number of reversals of ``u``: direction changes after a move of more than ``dead_band`` back from
    the last extreme (so that a measured input's noise does not count)."""
    count, direction, extreme = 0, 0, float(u[0])
    for value in map(float, u):
        if direction == 0:
            if abs(value - extreme) > dead_band:
                direction = 1 if value > extreme else -1
                extreme = value
        elif (value - extreme) * direction >= 0:
            extreme = value
        elif abs(value - extreme) > dead_band:
            count += 1
            direction, extreme = -direction, value
    return count


def play(u: np.ndarray, r: np.ndarray, z0: np.ndarray | None = None) -> np.ndarray:
    """The play operators of half-widths ``r`` (shape ``(m,)``, each >= 0) driven by ``u`` (shape ``(n,)``).

    Parameters
    ----------
    u : ndarray
        The input samples; the input is taken as linear between them.
    r : ndarray
        Half-widths of the plays, in the unit of ``u``.
    z0 : ndarray, optional
        The states before the first sample (default 0, the relaxed state at ``u = 0``); the first output
        is ``clip(z0, u[0] - r, u[0] + r)``, as if the input had jumped there.

    Returns
    -------
    ndarray
        ``(n, m)``: the state of every play at every sample.
    """
    u, r = _inputs(u, r)
    z = np.zeros(r.shape) if z0 is None else np.asarray(z0, dtype=float)
    return _by_runs(u, np.minimum(np.maximum(z, u[0] - r), u[0] + r),
                    lambda z, seg, u_a: np.maximum(z, seg - r), lambda z, seg, u_a: np.minimum(z, seg + r))


def stop(u: np.ndarray, r: np.ndarray, e0: np.ndarray | None = None) -> np.ndarray:
    """The stop operators of half-widths ``r``, ``u - play``: each follows the input's moves and is held
    within ``+-r`` (an elastic-perfectly-plastic element's deflection).  Computed from its own run formula,
    ``min(r, e_a + u - u_a)`` on a rising run, so that a held stop is ``+-r`` exactly (the difference
    ``u - play`` is not, to the rounding of ``u``, which a stiff element multiplies).

    ``e0`` are the states at the first sample (default 0), clipped to ``+-r``; returns ``(n, m)``.
    """
    u, r = _inputs(u, r)
    e = np.zeros(r.shape) if e0 is None else np.asarray(e0, dtype=float)
    return _by_runs(u, np.clip(e, -r, r),
                    lambda e, seg, u_a: np.minimum(r, e + (seg - u_a)),
                    lambda e, seg, u_a: np.maximum(-r, e + (seg - u_a)))


def _inputs(u, r) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(u, dtype=float), np.atleast_1d(np.asarray(r, dtype=float))


def _by_runs(u: np.ndarray, first: np.ndarray, rising, falling) -> np.ndarray:
    """The states at every sample, ``first`` at the first: on each monotone run ``rising(s_a, u_run, u_a)``
    or ``falling(...)`` of the state ``s_a`` and input ``u_a`` where the run starts, ``u_run`` its samples
    after the start as a column."""
    out = np.empty((u.size, first.size))
    out[0] = first
    for start, end, sign in monotone_runs(u):
        rows = slice(start + 1, end + 1)
        if sign == 0:  # an input that never moves holds every state
            out[rows] = out[start]
        else:
            out[rows] = (rising if sign > 0 else falling)(out[start], u[rows, None], u[start])
    return out
