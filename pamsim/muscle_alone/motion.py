"""The ``[motion]`` table: the contraction a muscle alone is driven along, as knots joined by straight lines.

A scenario with a ``[motion]`` table drives the muscle of the scenario by its length (a prescribed-length
test: the machine moves the muscle's end and measures its pull), through the muscle-only assembly
(:mod:`pamsim.assemblies.muscle_only`).  Three kinds:

- ``linear``: ``times_s`` and ``contraction_m``, straight lines between the knots;
- ``triangle``: from ``center_m``, turns at ``center_m + a_1``, ``center_m - a_2``, ``center_m + a_3``, ...
  (``amplitudes_m = [a_1, a_2, ...]``, which may fall turn by turn for minor loops), straight lines between
  them, each leg from one turn to the next lasting ``period_s / 2`` (the first, from the centre, ``period_s / 4``);
- ``sine``: the same turns, each leg a half cosine (a quarter sine from the centre) through
  ``points_per_leg`` knots, straight lines between them.

After the last knot the contraction holds.  The length is ``L0 - x`` and the lengthening velocity the
length's exact derivative, constant between knots, so every knot is a breakpoint of the inputs and each
backend integrates between knots with inputs that are exactly linear (the native engine and the FMU carry
such inputs exactly).  Within a leg the contraction is monotone, so an element's deflection is too, and its
slip is found as an event.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..signals import PiecewiseConstant, Trace
from ..table_checks import TableChecker

KINDS = ("linear", "triangle", "sine")
"""The kinds of motion a ``[motion]`` table takes."""

KEYS = {"linear": {"kind", "times_s", "contraction_m"},
        "triangle": {"kind", "center_m", "amplitudes_m", "period_s"},
        "sine": {"kind", "center_m", "amplitudes_m", "period_s", "points_per_leg"}}
"""The keys each kind takes."""

POINTS_PER_LEG = 16
"""Default ``points_per_leg`` of a sine: knots per half cosine.  Assumed: the chord of a half cosine on 16
points misses it by at most 1 - cos(pi / 32) = 0.5 % of the leg's half amplitude, below the loops' widths
in the shipped scenarios; more points follow it closer at the cost of more breakpoints."""
MAX_POINTS_PER_LEG = 1000
"""The most knots a sine's leg takes."""

REFUSED_TABLES = {"controller": "a muscle driven by its length has no load to control",
                  "compensation": "a tracking study drives a load, not a length"}
"""Tables a scenario with ``[motion]`` refuses, and why."""


@dataclass(frozen=True)
class Motion:
    """The contraction ``x_m`` [m] at the knots ``t_s`` [s] (strictly increasing, from 0), straight lines
    between them; the muscle's rest length ``L0_m`` [m]; ``kind`` as the table gives it."""

    kind: str
    t_s: np.ndarray
    x_m: np.ndarray
    L0_m: float

    @property
    def velocity_m_s(self) -> np.ndarray:
        """The contraction velocity on each leg between knots [m/s] (one fewer than the knots)."""
        return np.diff(self.x_m) / np.diff(self.t_s)

    def contraction_m(self, t) -> np.ndarray:
        """The contraction at times ``t`` [s]."""
        return np.interp(t, self.t_s, self.x_m)

    def length_signal(self) -> Trace:
        """The muscle's length ``L0 - x`` [m], the model input ``length_m``."""
        return Trace(self.t_s, self.L0_m - self.x_m, "motion")

    def velocity_signal(self) -> PiecewiseConstant:
        """The length's derivative [m/s], the model input ``lengthening_velocity_m_s``: constant on each
        leg, zero after the last knot."""
        return PiecewiseConstant(tuple(float(t) for t in self.t_s), (*(-self.velocity_m_s).tolist(), 0.0))

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """The knots' times [s]: the velocity jumps there."""
        return tuple(float(t) for t in self.t_s)


def turns(center_m: float, amplitudes_m, period_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The knots of a triangle: the centre at 0, then each turn ``center_m -+ a_k`` (up first), the first a
    quarter period after the start and each next one half a period after the last."""
    x = [center_m] + [center_m + (a if k % 2 == 0 else -a) for k, a in enumerate(amplitudes_m)]
    t = [0.0] + [period_s / 4.0 + k * period_s / 2.0 for k in range(len(amplitudes_m))]
    return np.array(t), np.array(x)


def cosine_legs(t_turns: np.ndarray, x_turns: np.ndarray, points: int) -> tuple[np.ndarray, np.ndarray]:
    """The knots of a sine through the turns: each leg a half cosine on ``points`` intervals, the first a
    quarter sine from the centre (its start has the speed the others have at their middle)."""
    ts, xs = [t_turns[:1]], [x_turns[:1]]
    for k in range(1, len(t_turns)):
        s = np.linspace(0.0, 1.0, points + 1)[1:]
        if k == 1:
            shape = np.sin(0.5 * np.pi * s)
        else:
            shape = 0.5 * (1.0 - np.cos(np.pi * s))
        ts.append(t_turns[k - 1] + s * (t_turns[k] - t_turns[k - 1]))
        xs.append(x_turns[k - 1] + shape * (x_turns[k] - x_turns[k - 1]))
    return np.concatenate(ts), np.concatenate(xs)


def motion_of(scenario) -> Motion:
    """The :class:`Motion` of ``scenario``'s ``[motion]`` table, checked against the muscle's range (its end
    stops).

    Raises
    ------
    InputError
        One line naming the key and the value: an unknown kind or key, a negative amplitude, knot times
        that do not increase, a contraction outside the muscle's range, a table the motion cannot use.
    """
    v = TableChecker(scenario.origin, InputError)
    table = scenario.spec["motion"]
    for name, why in REFUSED_TABLES.items():
        if name in scenario.spec:
            v.fail(name, scenario.spec[name], f"{why}; leave it out with [motion]")
    if "initial_contraction_m" in scenario.spec["simulation"]:
        v.fail("simulation.initial_contraction_m", scenario.spec["simulation"]["initial_contraction_m"],
               "with [motion] the run starts at the motion's first contraction; leave it out")
    kind = v.required(table, "kind", prefix="motion.")
    if kind not in KINDS:
        v.fail("motion.kind", kind, "unknown kind of motion", choices=KINDS)
    v.check_keys("[motion]", "motion.", table, KEYS[kind])
    t, x, key = _linear(v, table) if kind == "linear" else _cycles(v, table, kind)
    _within_range(v, scenario, key, t, x)
    return Motion(kind, t, x, float(scenario.parameters["L0_m"]))


def _linear(v: TableChecker, table: dict) -> tuple[np.ndarray, np.ndarray, str]:
    t = np.array(v.number_list("motion.times_s", v.required(table, "times_s", prefix="motion.")))
    x = np.array(v.number_list("motion.contraction_m", v.required(table, "contraction_m", prefix="motion.")))
    if len(t) != len(x) or len(t) < 2:
        v.fail("motion.contraction_m", x.tolist(), f"give one per time ({len(t)} times), at least 2")
    if t[0] != 0.0:
        v.fail("motion.times_s", t.tolist(), "must start at 0 (the run's start)")
    if not np.all(np.diff(t) > 0.0):
        k = int(np.flatnonzero(np.diff(t) <= 0.0)[0])
        v.fail("motion.times_s", t.tolist(), f"must increase strictly ({t[k + 1]:g} s follows {t[k]:g} s)")
    return t, x, "motion.contraction_m"


def _cycles(v: TableChecker, table: dict, kind: str) -> tuple[np.ndarray, np.ndarray, str]:
    center = v.number("motion.center_m", v.required(table, "center_m", prefix="motion."))
    amplitudes = v.number_list("motion.amplitudes_m", v.required(table, "amplitudes_m", prefix="motion."))
    for k, a in enumerate(amplitudes):
        if not a > 0.0:
            v.fail(f"motion.amplitudes_m[{k}]", a, "must be positive")
    period = v.positive("motion.period_s", v.number("motion.period_s", v.required(table, "period_s",
                                                                                      prefix="motion.")))
    t, x = turns(center, amplitudes, period)
    if kind == "sine":
        points = table.get("points_per_leg", POINTS_PER_LEG)
        if isinstance(points, bool) or not isinstance(points, int) or not 1 <= points <= MAX_POINTS_PER_LEG:
            v.fail("motion.points_per_leg", points, f"must be an integer from 1 to {MAX_POINTS_PER_LEG}")
        t, x = cosine_legs(t, x, points)
    return t, x, "motion.amplitudes_m"


def _within_range(v: TableChecker, scenario, key: str, t: np.ndarray, x: np.ndarray) -> None:
    """Every knot's contraction between the muscle's stops (the range its static force is defined on)."""
    stops = scenario._stops
    bad = np.flatnonzero((x < stops.x_low_m) | (x > stops.x_high_m))
    if bad.size:
        k = int(bad[0])
        v.fail(key, float(x[k]), f"the contraction at {t[k]:g} s lies outside the muscle's range, "
               f"{stops.x_low_m:g} to {stops.x_high_m:.6g} m (between its stops)")


__all__ = ["KINDS", "Motion", "motion_of", "turns", "cosine_legs", "POINTS_PER_LEG"]
