"""A measured pressure as the input of a fit's simulations: piecewise linear between knots that are
also breakpoints of the simulation.

A measured trace sampled at 1 kHz makes the simulator cap its step while the load is held at the
sample spacing (it must not step over a rise and fall of the input, or it could miss a release).
Thinning the trace to the knots of a piecewise-linear approximation within a tolerance
(Ramer-Douglas-Peucker) and declaring the knots where the polyline turns (rising to falling or
back) breakpoints makes the input monotonic between breakpoints, so the cap is not needed: the same
input to within the tolerance, a few restarts of the integrator instead of one step per sample.

The input is a :class:`pamsim.signals.Trace` of its knots, so the native backend takes it as it takes a
scenario's trace: cut at every knot and evaluated exactly inside the integrator
(:func:`pamsim.native.backend.exact_segments`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..signals import Trace
from .choices import KNOT_TOLERANCE_PA


@dataclass(frozen=True)
class PiecewiseLinearInput(Trace):
    """A trace linear between its knots ``(t_s, values)``, constant outside them, whose turning knots are
    breakpoints, so the Python backend's step is not capped at the knot spacing."""

    max_step_s = math.inf

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Interior knots where the polyline turns; between them it is monotonic."""
        s = np.sign(np.diff(self.values))
        turns = np.flatnonzero(s[1:] != s[:-1]) + 1
        return tuple(float(t) for t in self.t_s[turns])


def knots(t_s: np.ndarray, values: np.ndarray, tolerance: float) -> np.ndarray:
    """Indices of the samples kept by Ramer-Douglas-Peucker: the polyline through them stays within
    ``tolerance`` (in the values' unit, measured vertically) of every sample."""
    keep = np.zeros(len(t_s), dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, len(t_s) - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        seg = slice(i + 1, j)
        line = values[i] + (values[j] - values[i]) * (t_s[seg] - t_s[i]) / (t_s[j] - t_s[i])
        dev = np.abs(values[seg] - line)
        k = int(np.argmax(dev))
        if dev[k] > tolerance:
            m = i + 1 + k
            keep[m] = True
            stack += [(i, m), (m, j)]
    return np.flatnonzero(keep)


def thinned_input(t_s: np.ndarray, p_gauge_Pa: np.ndarray, tolerance_Pa: float = KNOT_TOLERANCE_PA,
                  source: str = "") -> PiecewiseLinearInput:
    """The measured pressure thinned to its knots (times relative to the trace's first sample)."""
    idx = knots(t_s, p_gauge_Pa, tolerance_Pa)
    return PiecewiseLinearInput(t_s[idx] - t_s[0], p_gauge_Pa[idx], source)
