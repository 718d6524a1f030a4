"""Time signals that drive a simulation: valve command, supply or prescribed
pressure, external force.

Every signal is evaluated with ``signal(t)`` for a float or an array of times,
and lists its ``breakpoints``: the times at which it jumps or kinks, where the
simulator restarts the integrator instead of letting the error control stumble
over a discontinuity.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np


class _Signal:
    """Breakpoints are the values of the fields named in ``_break_fields``.

    ``max_step_s`` is the longest step over which the signal is monotonic: a
    held load's release is only sure to be seen if the integrator does not
    step over a rise and fall of its inputs.
    """

    _break_fields: ClassVar[tuple[str, ...]] = ()
    max_step_s: ClassVar[float] = math.inf

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return tuple(getattr(self, f) for f in self._break_fields)

    @property
    def final_value(self) -> float:
        return self.final


@dataclass(frozen=True)
class Constant(_Signal):
    """A constant value."""

    value: float

    def __call__(self, t):
        return self.value + 0.0 * t


    @property
    def final_value(self) -> float:
        """The constant value."""
        return self.value


@dataclass(frozen=True)
class Step(_Signal):
    """``initial`` before ``time_s``, ``final`` from then on."""

    time_s: float
    initial: float
    final: float
    _break_fields: ClassVar[tuple[str, ...]] = ("time_s",)

    def __call__(self, t):
        if isinstance(t, float):  # numpy float64 is a float; np.ndim costs more than the signal
            return self.final if t >= self.time_s else self.initial
        return np.where(np.asarray(t) >= self.time_s, self.final, self.initial)


@dataclass(frozen=True)
class Ramp(_Signal):
    """Linear from ``initial`` at ``start_s`` to ``final`` at ``end_s``."""

    start_s: float
    end_s: float
    initial: float
    final: float
    _break_fields: ClassVar[tuple[str, ...]] = ("start_s", "end_s")

    def __call__(self, t):
        if isinstance(t, float):
            return float(np.interp(t, (self.start_s, self.end_s), (self.initial, self.final)))
        return np.interp(t, (self.start_s, self.end_s), (self.initial, self.final))


@dataclass(frozen=True)
class FirstOrderLag(_Signal):
    """A step from ``initial`` to ``final`` at ``time_s`` through a first-order lag ``tau_s``."""

    time_s: float
    initial: float
    final: float
    tau_s: float
    _break_fields: ClassVar[tuple[str, ...]] = ("time_s",)

    def __call__(self, t):
        if isinstance(t, float):  # numpy float64 is a float; np.ndim costs more than the signal
            if t < self.time_s:
                return self.initial
            return self.final + (self.initial - self.final) * math.exp(-(t - self.time_s) / self.tau_s)
        t = np.asarray(t, dtype=float)
        lag = self.final + (self.initial - self.final) * np.exp(-np.maximum(t - self.time_s, 0.0) / self.tau_s)
        return np.where(t >= self.time_s, lag, self.initial)


@dataclass(frozen=True)
class Trace(_Signal):
    """A measured signal, linearly interpolated, held constant outside its span."""

    t_s: np.ndarray = field(repr=False)
    values: np.ndarray = field(repr=False)
    source: str = ""

    def __call__(self, t):
        if isinstance(t, float):  # numpy float64 is a float; np.ndim costs more than the signal
            return float(np.interp(t, self.t_s, self.values))
        return np.interp(t, self.t_s, self.values)


    @property
    def final_value(self) -> float:
        """The last sample's value."""
        return float(self.values[-1])

    @property
    def max_step_s(self) -> float:
        return float(np.min(np.diff(self.t_s)))


@dataclass(frozen=True)
class PiecewiseConstant(_Signal):
    """``values[k]`` from ``times_s[k]`` until ``times_s[k + 1]``, the last value from its time on, and
    ``values[0]`` before ``times_s[0]``: a sampled command held between its samples (a zero-order hold),
    such as a controller's or a reinforcement-learning agent's actions.

    Every time is a breakpoint, also where the value does not change: the integrator restarts there,
    as it does at each step of a controller that sets its output every sample, so a run of this signal
    takes the steps that such a controller's run takes.
    """

    times_s: tuple[float, ...]
    values: tuple[float, ...]

    def __call__(self, t):
        if isinstance(t, float):  # numpy float64 is a float; np.ndim costs more than the signal
            return self.values[max(bisect.bisect_right(self.times_s, t) - 1, 0)]
        k = np.searchsorted(np.asarray(self.times_s), np.asarray(t, dtype=float), side="right") - 1
        return np.asarray(self.values, dtype=float)[np.maximum(k, 0)]

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Every time of the signal."""
        return tuple(self.times_s)

    @property
    def final_value(self) -> float:
        """The last value."""
        return float(self.values[-1])


def max_step_hint_s(*signals) -> float:
    """The smallest ``max_step_s`` of some signals (callables without one count as smooth)."""
    return min((getattr(sig, "max_step_s", math.inf) for sig in signals if sig is not None), default=math.inf)
