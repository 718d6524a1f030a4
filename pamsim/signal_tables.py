"""Signals given as TOML tables (``{kind = "step", time_s = 1.0, final_gauge_bar = 3.6}``).

Scenario files use these tables for the prescribed pressure, the valve command
and the external force.  The functions take a validator ``v`` of the file they
read (its ``origin``, ``fail``, ``number``, ``required`` and ``error``), so every
mistake names that file, the key and the value.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, Mapping

import numpy as np

import dataclasses

from .signals import (MAX_PWM_FREQUENCY_HZ, MAX_PWM_SWITCHES, Constant, FirstOrderLag, OnOff, PiecewiseConstant, Pwm,
                      Ramp, Step, Trace, complementary)
from .table_checks import choices_hint

# Signal kind -> (keys without a unit, value keys that take the unit suffix of where the signal is used).
SIGNAL_KINDS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "constant": ((), ("value",)),
    "step": (("time_s",), ("initial", "final")),
    "ramp": (("start_s", "end_s"), ("initial", "final")),
    "lag": (("time_s", "tau_s"), ("initial", "final")),
    "trace": (("file", "time_column", "value_column"), ()),
    "steps": (("times_s",), ("values",)),
    "linear": (("times_s",), ("values",)),
    "pwm": (("start_s", "end_s", "frequency_Hz", "duty", "delay_on_s", "delay_off_s", "rise_s", "fall_s"),
            ("low", "high")),
}


def signal_from_table(v, where: str, spec: Any, suffix: str, scale: float, base_dir: Path,
            alt_suffix: tuple[str, float] | None = None):
    """Build a signal from a table ``{kind = ..., ...}``; values are named ``initial<suffix>``, ``final<suffix>``."""
    if not isinstance(spec, dict):
        v.fail(where, spec, "must be a table with a 'kind'")
    kind = v.required(spec, "kind", prefix=f"{where}.")
    if not isinstance(kind, str) or kind not in SIGNAL_KINDS:
        v.fail(f"{where}.kind", kind, "unknown signal kind", choices=SIGNAL_KINDS)
    suffixes = [(suffix, scale)] + ([alt_suffix] if alt_suffix else [])
    _check_keys(v, where, spec, kind, suffixes)
    if kind == "steps":
        return PiecewiseConstant(*_knots(v, where, spec, suffixes))
    if kind == "linear":  # straight lines between the knots: cycles of any shape (triangles, minor loops)
        times, values = _knots(v, where, spec, suffixes)
        return Trace(np.array(times), np.array(values), "linear")
    if kind == "trace":
        return _trace(v, where, spec, suffixes, base_dir)
    return _SHAPES[kind](_Entries(v, where, spec, suffixes))


def _check_keys(v, where: str, spec: Mapping, kind: str, suffixes) -> None:
    """Refuse a key that signal ``kind`` does not take (with the value keys in each of the ``suffixes``)."""
    times, values = SIGNAL_KINDS[kind]
    known = ["kind", *times, *(f"{n}{s}" for n in values for s, _ in suffixes)]
    for key in spec:
        if key not in known:
            raise v.error(f"{v.origin}: unknown key {where}.{key} for kind = {kind!r}"
                          + choices_hint(key, known, "known:"))


class _Entries:
    """The entries of one signal table, read as they are asked for (so the first mistake asked is reported)."""

    def __init__(self, v, where: str, spec: Mapping, suffixes):
        self.v, self.where, self.spec, self.suffixes = v, where, spec, suffixes

    def value(self, name: str, default: float | None = None) -> float:
        """``name<suffix>`` in SI, in the first of the suffixes it is given with; ``default`` if none (None:
        required)."""
        for s, k in self.suffixes:
            if f"{name}{s}" in self.spec:
                return self.v.number(f"{self.where}.{name}{s}", self.spec[f"{name}{s}"]) * k
        if default is None:
            raise self.v.error(f"{self.v.origin}: missing key {self.where}.{name}{self.suffixes[0][0]}")
        return default

    def time(self, name: str) -> float:
        """Required time ``name`` [s], not negative."""
        value = self.v.number(f"{self.where}.{name}", self.v.required(self.spec, name, prefix=f"{self.where}."))
        if value < 0:
            self.v.fail(f"{self.where}.{name}", value, "must not be negative")
        return value

    def after(self, name: str, start_name: str, start: float) -> float:
        """Required time ``name`` [s], after ``start`` (time ``start_name``)."""
        end = self.time(name)
        if end <= start:
            self.v.fail(f"{self.where}.{name}", end, f"must be after {start_name} = {start}")
        return end

    def positive_time(self, name: str) -> float:
        """Required time ``name`` [s], above zero."""
        tau = self.time(name)
        if tau <= 0:
            self.v.fail(f"{self.where}.{name}", tau, "must be positive")
        return tau


def _ramp(e: _Entries) -> Ramp:
    start = e.time("start_s")
    return Ramp(start, e.after("end_s", "start_s", start), e.value("initial", 0.0), e.value("final"))


def _lag(e: _Entries) -> FirstOrderLag:
    tau = e.positive_time("tau_s")  # read before time_s: the order the mistakes were always reported in
    return FirstOrderLag(e.time("time_s"), e.value("initial", 0.0), e.value("final"), tau)


def _pwm(e: _Entries) -> Pwm:
    """A PWM command: its period's frequency in (0, MAX_PWM_FREQUENCY_HZ], its duty in [0, 1], the valve's
    delays and opening and closing times not negative, and no more than MAX_PWM_SWITCHES switches."""
    start = e.time("start_s")
    end = e.after("end_s", "start_s", start)
    f = e.v.number(f"{e.where}.frequency_Hz", e.v.required(e.spec, "frequency_Hz", prefix=f"{e.where}."))
    if not 0.0 < f <= MAX_PWM_FREQUENCY_HZ:
        e.v.fail(f"{e.where}.frequency_Hz", f, f"must lie in (0, {MAX_PWM_FREQUENCY_HZ:g}] Hz" + (
            "" if f <= 0.0 else " (solenoid valves switch in 1 to 3 ms: faster PWM than that is a valve's "
            "proportional opening, not its switching)"))
    if (end - start) * f * 2 > MAX_PWM_SWITCHES:
        e.v.fail(f"{e.where}.frequency_Hz", f, f"{(end - start) * f * 2:.0f} switches from start_s to end_s, "
                 f"more than {MAX_PWM_SWITCHES}")
    duty = e.v.number(f"{e.where}.duty", e.v.required(e.spec, "duty", prefix=f"{e.where}."))
    if not 0.0 <= duty <= 1.0:
        e.v.fail(f"{e.where}.duty", duty, "must lie in [0, 1]")
    timing = {k: e.time(k) if k in e.spec else 0.0 for k in ("delay_on_s", "delay_off_s", "rise_s", "fall_s")}
    return Pwm(start, end, f, duty, e.value("low", 0.0), e.value("high"), **timing)


# The signals of a few entries each, by kind (steps and trace read lists and files of their own).
_SHAPES = {
    "constant": lambda e: Constant(e.value("value")),
    "step": lambda e: Step(e.time("time_s"), e.value("initial", 0.0), e.value("final")),
    "ramp": _ramp,
    "lag": _lag,
    "pwm": _pwm,
}


ON_OFF_KINDS = ("constant", "step", "steps", "pwm", "complementary")
"""The commands of an on/off valve (``[pressure.inlet.command]``, ``[pressure.exhaust.command]``): a boolean
held, stepped once or stepped at times (0 closed, 1 open), PWM, or the inlet's command inverted (the
exhaust's alone)."""
VALVE_TIMING = ("delay_on_s", "delay_off_s", "rise_s", "fall_s")
"""An on/off valve's delays and opening and closing times, keys of its own table (not of its command)."""


def on_off_command(v, where: str, spec: Any, timing: Mapping[str, float], inlet=None):
    """The opening of an on/off valve (0 closed, 1 open) as it follows the command table ``spec`` at ``where``,
    with the valve's ``timing`` (:data:`VALVE_TIMING`, seconds): a :class:`~pamsim.signals.Pwm` from 0 to 1,
    or an :class:`~pamsim.signals.OnOff` of a boolean ``constant``, ``step`` or ``steps``; with ``inlet`` (the
    inlet's opening), ``kind = "complementary"`` is that command inverted (:func:`~pamsim.signals.complementary`).

    ``v`` refuses, naming the key: an unknown kind, a timing or level key in the command (they are the
    valve's), a value other than 0 or 1, a complementary inlet or one with keys besides its kind."""
    kind = _on_off_kind(v, where, spec, inlet is not None)
    if kind == "complementary":
        for key in spec:
            if key != "kind":
                v.fail(f"{where}.{key}", spec[key], "a complementary command takes no keys: it is the inlet's inverted")
        return complementary(inlet, **timing)
    table = {k: x for k, x in spec.items() if k != "model"}
    if kind == "pwm":
        table["high"] = 1.0  # open while on, closed (low 0) while off
    signal = signal_from_table(v, where, table, "", 1.0, Path("."))
    if isinstance(signal, Pwm):
        return dataclasses.replace(signal, **timing)
    states = _boolean_states(v, where, signal, table)
    commands = tuple(zip(signal.times_s, states)) if isinstance(signal, PiecewiseConstant) else (
        ((signal.time_s, states[-1]),) if isinstance(signal, Step) else ())
    return OnOff(commands, float(states[0]), **timing)


def _on_off_kind(v, where: str, spec: Any, exhaust: bool) -> str:
    """The ``kind`` of an on/off valve's command table (``complementary`` for the ``exhaust``'s alone), its
    timing and level keys refused (they are the valve's)."""
    if not isinstance(spec, dict):
        v.fail(where, spec, "must be a table with a 'kind'")
    kind = v.required(spec, "kind", prefix=f"{where}.")
    allowed = ON_OFF_KINDS if exhaust else ON_OFF_KINDS[:-1]
    if not isinstance(kind, str) or kind not in allowed:
        v.fail(f"{where}.kind", kind, "unknown command of an on/off valve", choices=allowed)
    for key in spec:
        table = where.rsplit(".", 1)[0]
        if key in VALVE_TIMING:
            v.fail(f"{where}.{key}", spec[key], f"the valve's timing is a key of its own table ({table}), not of "
                   "its command")
        if key in ("low", "high"):
            v.fail(f"{where}.{key}", spec[key], "an on/off valve's command has no levels: it opens the valve "
                   "(1) or closes it (0); leave the key out")
    return kind


def _boolean_states(v, where: str, signal, spec: Mapping) -> list[int]:
    """The states (0 or 1) a boolean ``constant``, ``step`` or ``steps`` signal (of the table ``spec``) takes,
    in order; any other value is refused naming its key."""
    values = (signal.values if isinstance(signal, PiecewiseConstant)
              else (signal.initial, signal.final) if isinstance(signal, Step) else (signal.value,))
    for value in values:
        if value not in (0.0, 1.0):
            v.fail(_boolean_key(where, spec, value), value, "an on/off valve's command is 0 (closed) or 1 (open)")
    return [int(x) for x in values]


def _boolean_key(where: str, spec: Mapping, value: float) -> str:
    """The key of ``spec`` (a command table) that holds ``value``: ``value``, ``initial``, ``final`` or
    ``values[i]``; ``where`` itself if none does."""
    for key in ("value", "initial", "final"):
        if spec.get(key) == value:
            return f"{where}.{key}"
    listed = spec.get("values")
    if isinstance(listed, list):
        for i, x in enumerate(listed):
            if x == value:
                return f"{where}.values[{i}]"
    return where


def _numbers(v, key: str, value: Any) -> list[float]:
    if not isinstance(value, (list, tuple)) or not value:
        v.fail(key, value, "must be a non-empty list of numbers")
    return [v.number(f"{key}[{k}]", x) for k, x in enumerate(value)]


def _knots(v, where: str, spec: Mapping, suffixes) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """A ``steps`` or ``linear`` table's times (not negative, increasing) and values (in SI), as many of each."""
    times = _numbers(v, f"{where}.times_s", v.required(spec, "times_s", prefix=f"{where}."))
    given = [(f"values{s}", k) for s, k in suffixes if f"values{s}" in spec]
    if not given:
        raise v.error(f"{v.origin}: missing key {where}.values{suffixes[0][0]}")
    key, scale = given[0]
    values = [x * scale for x in _numbers(v, f"{where}.{key}", spec[key])]
    if len(values) != len(times):
        v.fail(f"{where}.{key}", f"{len(values)} values", f"must be as many as times_s ({len(times)})")
    if times[0] < 0:
        v.fail(f"{where}.times_s[0]", times[0], "must not be negative")
    for k in range(1, len(times)):
        if times[k] <= times[k - 1]:
            v.fail(f"{where}.times_s[{k}]", times[k], f"must be after times_s[{k - 1}] = {times[k - 1]:g}")
    return tuple(times), tuple(values)


def _trace(v, where: str, spec: Mapping, suffixes, base_dir: Path) -> Trace:
    """A measured signal from a CSV file: its time column and the first value column in a known unit.

    Parameters
    ----------
    v : the validator of the file the table is in.
    where : the table's key (``pressure.prescribed``).
    spec : the table: ``file``, optional ``time_column`` (default ``t_s``) and ``value_column``.
    suffixes : ``[(unit suffix, factor to SI), ...]`` that a value column's name may end in.
    base_dir : where a relative file name is found.
    """
    name, path = _trace_file(v, where, spec, base_dir)
    time_col = spec.get("time_column", "t_s")
    header, data = _read_trace(v, where, name, path)
    if time_col not in header:
        v.fail(f"{where}.time_column", time_col, f"no such column in {name} (columns: {', '.join(header)})")
    col, unit = _value_column(v, where, spec, name, header, time_col, suffixes)
    t = _column(v, where, name, header, data, time_col)
    y = _column(v, where, name, header, data, col) * unit
    _check_samples(v, where, name, t, y)
    return Trace(t, y, str(path))


def _trace_file(v, where: str, spec: Mapping, base_dir: Path) -> tuple[str, Path]:
    """``(name as given, path)`` of a trace's file, relative names under ``base_dir``; it must exist."""
    name = v.required(spec, "file", prefix=f"{where}.")
    if not isinstance(name, str):
        v.fail(f"{where}.file", name, "must be a string (a CSV path)")
    path = (base_dir / name) if not Path(name).is_absolute() else Path(name)
    if not path.is_file():
        v.fail(f"{where}.file", name, f"trace file not found at {path}")
    return name, path


def _read_trace(v, where: str, name: str, path: Path) -> tuple[list[str], np.ndarray]:
    """The header row's column names and the numbers below it (one row per line; no rows: as many columns
    as the header)."""
    try:
        with open(path) as fh:
            header = fh.readline().strip().split(",")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # no rows: refused below as too few rows, in one line
            data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except (ValueError, OSError) as exc:
        v.fail(f"{where}.file", name, f"cannot read as CSV with a header row: {exc}")
    if data.size == 0:  # numpy gives no rows one column: give them the header's, so the row count is what fails
        data = np.empty((0, len(header)))
    return header, data


def _column(v, where: str, name: str, header: list[str], data: np.ndarray, column: str) -> np.ndarray:
    """The values of ``column`` (a name in the header); the rows must reach it.

    Raises
    ------
    InputError
        (through ``v``) Rows with fewer numbers than the header has names, up to ``column``.
    """
    i = header.index(column)
    if i >= data.shape[1]:
        v.fail(f"{where}.file", name, f"cannot read as CSV with a header row: its rows have {data.shape[1]} "
               f"column(s), too few to hold {column!r} (column {i + 1} of its header)")
    return data[:, i]


def _value_column(v, where: str, spec: Mapping, name: str, header: list[str], time_col: str,
                  suffixes) -> tuple[str, float]:
    """``(column, factor to SI)``: ``value_column`` if given, else the first column other than the time's;
    its name must end in one of the unit ``suffixes``."""
    if "value_column" in spec:
        col = spec["value_column"] if spec["value_column"] in header else None
    else:
        col = next((c for c in header if c != time_col), None)
    unit = _suffix_factor(col, suffixes)
    if col is None or unit is None:
        want = " or ".join(f"a column ending in {s}" for s, _ in suffixes)
        v.fail(f"{where}.value_column", spec.get("value_column", col), f"{name} needs {want}")
    return col, unit


def _suffix_factor(col: str | None, suffixes) -> float | None:
    """The factor to SI of the first unit suffix that column ``col`` ends in, or None."""
    return next((k for s, k in suffixes if col and col.endswith(s)), None)


def _check_samples(v, where: str, name: str, t: np.ndarray, y: np.ndarray) -> None:
    """At least two rows, every value finite and the time increasing strictly (naming the first bad line)."""
    if len(t) < 2:
        v.fail(f"{where}.file", name, "a trace needs at least two rows")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        row = int(np.flatnonzero(~(np.isfinite(t) & np.isfinite(y)))[0]) + 2
        v.fail(f"{where}.file", name, f"non-finite value on line {row}")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        v.fail(f"{where}.file", name, f"time must increase strictly; line {int(bad[0]) + 3} has t = {t[bad[0] + 1]:g} "
               f"after {t[bad[0]]:g}")


def signal_range(sig) -> tuple[float, float]:
    """``(lowest, highest)`` value a signal takes."""
    if isinstance(sig, Trace):
        return float(sig.values.min()), float(sig.values.max())
    if isinstance(sig, PiecewiseConstant):
        return min(sig.values), max(sig.values)
    if isinstance(sig, Pwm):
        return min(sig.knots), max(sig.knots)
    vals = [getattr(sig, a) for a in ("value", "initial", "final") if hasattr(sig, a)]
    return min(vals), max(vals)
