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


MAX_PWM_FREQUENCY_HZ = 1000.0
"""The highest PWM frequency a signal takes [Hz].  Assumed: fast solenoid valves switch in 1-3 ms, so a
few hundred Hz is their limit; above 1 kHz an on/off valve is better modelled by its averaged flow."""
MAX_PWM_SWITCHES = 1_000_000
"""The most switching instants a PWM signal may have (a run's memory for its knots)."""


class _Knotted(_Signal):
    """A valve's opening as knots ``(knots_t_s, knots)`` of a piecewise-linear trace, held before the first
    and after the last; a jump is two knots at one time, and every knot is a breakpoint."""

    def __call__(self, t):
        ts, vs = self.knots_t_s, self.knots
        if isinstance(t, float):
            k = bisect.bisect_right(ts, t)  # after every knot at t: the value just after a jump
            if k == 0 or k == len(ts):
                return vs[0] if k == 0 else vs[-1]
            t0, t1 = ts[k - 1], ts[k]
            return vs[k - 1] + (vs[k] - vs[k - 1]) * (t - t0) / (t1 - t0)
        t = np.asarray(t, dtype=float)
        t_k, v_k = np.asarray(ts), np.asarray(vs)
        k = np.clip(np.searchsorted(t_k, t, side="right"), 1, len(ts) - 1)
        # ts[k - 1] <= t < ts[k] inside the knots (no zero width); outside them, held at the end values
        inside = (t >= t_k[0]) & (t < t_k[-1])
        t0, t1, v0, v1 = t_k[k - 1], t_k[k], v_k[k - 1], v_k[k]
        between = v0 + (v1 - v0) * (t - t0) / np.where(inside, t1 - t0, 1.0)
        return np.where(inside, between, np.where(t < t_k[0], v_k[0], v_k[-1]))

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Every knot time, once."""
        return tuple(sorted(set(self.knots_t_s)))

    @property
    def final_value(self) -> float:
        """The value after the last knot."""
        return self.knots[-1]


@dataclass(frozen=True)
class Pwm(_Knotted):
    """A pulse-width-modulated on/off command as the valve it drives follows it: ``high`` for ``duty`` of
    each period ``1 / frequency_Hz`` from ``start_s`` until ``end_s``, ``low`` otherwise; each switch takes
    effect ``delay_on_s`` or ``delay_off_s`` after it is commanded and moves linearly over ``rise_s`` or
    ``fall_s`` (a valve's opening and closing times).  A pulse shorter than the opening time does not
    open the valve fully; the closing starts from where the opening got.

    Every knot of the piecewise-linear trace is a breakpoint, so each switching instant starts a new
    integration segment: the switches are exact, not sampled.
    """

    start_s: float
    end_s: float
    frequency_Hz: float
    duty: float
    low: float = 0.0
    high: float = 1.0
    delay_on_s: float = 0.0
    delay_off_s: float = 0.0
    rise_s: float = 0.0
    fall_s: float = 0.0
    knots_t_s: tuple = field(default=(), repr=False, compare=False)
    knots: tuple = field(default=(), repr=False, compare=False)

    def __post_init__(self):
        t, level = pwm_levels(self)
        object.__setattr__(self, "knots_t_s", tuple(t))
        object.__setattr__(self, "knots", tuple(self.low + (self.high - self.low) * x for x in level))

    @property
    def switch_times_s(self) -> tuple[float, ...]:
        """The commanded switching instants: on at each period's start, off ``duty`` of a period later."""
        return tuple(t for t, _ in _pwm_commands(self))


def _pwm_commands(p: Pwm) -> list[tuple[float, int]]:
    """The commanded instants and states (1 on, 0 off) of ``p``, in time order."""
    if p.duty <= 0.0:
        return []
    if p.duty >= 1.0:
        return [(p.start_s, 1), (p.end_s, 0)]
    period = 1.0 / p.frequency_Hz
    n = int(math.ceil((p.end_s - p.start_s) * p.frequency_Hz - 1e-12))
    out = []
    for k in range(n):
        on = p.start_s + k * period
        out += [(on, 1), (min(on + p.duty * period, p.end_s), 0)]
    return out


def pwm_levels(p: Pwm) -> tuple[list[float], list[float]]:
    """The valve's opening (0 closed, 1 open) under ``p``'s commands as knots ``(times, levels)``: each
    command takes effect after its delay and ramps at ``1 / rise_s`` or ``1 / fall_s`` toward its level
    until it gets there or the next command comes (a zero ramp: a jump, two knots at one time)."""
    return switching_levels(_pwm_commands(p), 0.0, p)


def switching_levels(commands, initial: float, timing) -> tuple[list[float], list[float]]:
    """The opening (0 closed, 1 open) of a valve at ``initial`` at time 0 under the commanded instants and
    states ``commands`` (``[(t_s, 1 on or 0 off), ...]``) with the delays and opening and closing times of
    ``timing`` (``delay_on_s``, ``delay_off_s``, ``rise_s``, ``fall_s``), as knots ``(times, levels)``
    (see :func:`pwm_levels`)."""
    delayed = [(t + (timing.delay_on_s if on else timing.delay_off_s), on) for t, on in commands]
    # A command that the next one overtakes never takes effect: a pulse shorter than the opening delay less
    # the closing delay does not open the valve (nor does a gap that short close it), rather than the
    # overtaken command's delayed switch landing after the next one's and holding the valve the wrong way.
    events = sorted(e for k, e in enumerate(delayed) if k + 1 == len(delayed) or e[0] < delayed[k + 1][0])
    times, levels = [0.0], [initial]
    level, target, now = initial, initial, 0.0
    for t_event, on in events:
        level, now = _ramp_until(times, levels, level, target, now, t_event, timing)
        if (times[-1], levels[-1]) != (t_event, level):  # where the level stood when the command came
            times.append(t_event)
            levels.append(level)
        target = float(on)
        if (timing.rise_s if on else timing.fall_s) == 0.0 and level != target:
            times.append(t_event)
            levels.append(target)
            level = target
    _ramp_until(times, levels, level, target, now, math.inf, timing)
    return times, levels


def _ramp_until(times, levels, level, target, now, t_end, p) -> tuple[float, float]:
    """Move ``level`` toward ``target`` from ``now`` until ``t_end`` at the ramp's rate, adding the knots."""
    if level == target:
        return level, t_end if math.isfinite(t_end) else now
    ramp = p.rise_s if target > level else p.fall_s
    reach = now + abs(target - level) * ramp
    if reach <= t_end:
        times.append(reach)
        levels.append(target)
        return target, t_end if math.isfinite(t_end) else reach
    level += (t_end - now) / ramp * (1.0 if target > level else -1.0)
    return level, t_end


@dataclass(frozen=True)
class OnOff(_Knotted):
    """An on/off valve's opening (0 closed, 1 open) under a boolean command: ``initial`` (0 or 1) from time 0,
    then each of ``commands`` (``((t_s, 1 on or 0 off), ...)``), taking effect ``delay_on_s`` or
    ``delay_off_s`` after it is commanded and moving linearly over ``rise_s`` or ``fall_s``, as
    :class:`Pwm` does.  Every knot is a breakpoint: the switches are exact, not sampled."""

    commands: tuple
    initial: float = 0.0
    delay_on_s: float = 0.0
    delay_off_s: float = 0.0
    rise_s: float = 0.0
    fall_s: float = 0.0
    knots_t_s: tuple = field(default=(), repr=False, compare=False)
    knots: tuple = field(default=(), repr=False, compare=False)

    def __post_init__(self):
        t, level = switching_levels(self.commands, self.initial, self)
        object.__setattr__(self, "knots_t_s", tuple(t))
        object.__setattr__(self, "knots", tuple(level))

    @property
    def switch_times_s(self) -> tuple[float, ...]:
        """The commanded switching instants."""
        return tuple(t for t, _ in self.commands)


def complementary(command, delay_on_s: float = 0.0, delay_off_s: float = 0.0, rise_s: float = 0.0,
                  fall_s: float = 0.0):
    """The opening of a valve commanded open whenever ``command`` (a :class:`Pwm` from 0 to 1, or an
    :class:`OnOff`) is commanded closed and closed whenever it is open, with this valve's own delays and
    opening and closing times: the exhaust of a pair of 2/2 valves driven as one 3/2 valve.

    Of a :class:`Pwm` it is a :class:`Pwm` from 1 down to 0 (so that its averaged model derives its share
    from its own trace): its rising command closes this valve, so it takes this valve's closing delay and
    time, and its falling command the opening's."""
    if isinstance(command, Pwm):
        return Pwm(command.start_s, command.end_s, command.frequency_Hz, command.duty, low=1.0, high=0.0,
                   delay_on_s=delay_off_s, delay_off_s=delay_on_s, rise_s=fall_s, fall_s=rise_s)
    return OnOff(tuple((t, 1 - on) for t, on in command.commands), 1.0 - command.initial, delay_on_s, delay_off_s,
                 rise_s, fall_s)


def max_step_hint_s(*signals) -> float:
    """The smallest ``max_step_s`` of some signals (callables without one count as smooth)."""
    return min((getattr(sig, "max_step_s", math.inf) for sig in signals if sig is not None), default=math.inf)
