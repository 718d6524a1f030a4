"""Checks of what a user writes: scenario, sweep and muscle files, and command-line options.

Every mistake raises one line that names the file (where there is one), the key and the value,
with the closest valid name when one is close: the readers of scenarios, signal tables, sweeps,
uncertainty studies and muscle files, and the command line, build their messages here so that a
typo reads the same wherever it is made.
"""

from __future__ import annotations

import difflib
import math
from typing import Any, Mapping, NoReturn

from .errors import InputError


def did_you_mean(value: Any, choices) -> str:
    """`` (did you mean 'x'?)`` for the choice closest to ``value``, or an empty string."""
    close = difflib.get_close_matches(str(value), [str(c) for c in choices], n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def choices_hint(value: Any, choices, listing: str = "choose from") -> str:
    """:func:`did_you_mean`, or, when no choice is close, `` (LISTING a, b, c)``."""
    return did_you_mean(value, choices) or f" ({listing} {', '.join(map(str, choices))})"


def option_error(key: str, value: Any, why: str, choices=None) -> NoReturn:
    """Raise :class:`InputError` ``KEY = VALUE: WHY`` for a value that no file holds (an option, an argument)."""
    raise InputError(f"{key} = {value!r}: {why}" + (did_you_mean(value, choices) if choices else ""))


_TYPE_PHRASES = {bool: "true or false", int: "an integer", float: "a decimal number", str: "a string",
                 dict: "a table", list: "a list"}


def type_phrase(kind: type) -> str:
    """How a message names a value's type: ``an integer``, ``a table``, ``a decimal number`` (TOML's names)."""
    name = kind.__name__
    return _TYPE_PHRASES.get(kind, f"an {name}" if name[:1].lower() in "aeiou" else f"a {name}")


def value_phrase(value: Any) -> str:
    """How a message names the type of a value that is not the one expected: ``a string``, ``a boolean``."""
    return "a boolean" if isinstance(value, bool) else type_phrase(type(value))


def number_problem(value: Any) -> str | None:
    """Why ``value`` read from a file is not a finite number, or None: a boolean or any other type is named
    as the file writes it (``not a string``), NaN and the infinities are not finite."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"must be a number, not {value_phrase(value)}"
    return None if math.isfinite(value) else "must be a finite number"


SHOWN_ITEMS = 6
"""Items of a list a message shows before it says how many more there are."""


def shown(value: Any) -> str:
    """``value`` as a message shows it: a boolean as the file writes it (``true``), a long list by its first
    :data:`SHOWN_ITEMS` and its length, anything else by its repr."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list) and len(value) > SHOWN_ITEMS:
        return f"[{', '.join(shown(x) for x in value[:SHOWN_ITEMS])}, ... ({len(value)} values)]"
    return repr(value)


class TableChecker:
    """The checks of the tables of one file: a mistake raises ``error`` naming ``origin``, the key and the value.

    ``prefix`` arguments are the dotted path of the table a key is in (``"measured."``), so that
    the message shows the key as the user would write it in full; ``document`` names the top level
    (prefix ``""``) when it is not a table.
    """

    def __init__(self, origin: str, error: type[InputError] = InputError, document: str = "file"):
        self.origin = origin
        self.error = error
        self.document = document

    def fail(self, key: str, value: Any, why: str, choices=None) -> NoReturn:
        """Raise ``ORIGIN: KEY = VALUE: WHY``, with the closest of ``choices`` or all of them."""
        msg = f"{self.origin}: {key} = {shown(value)}: {why}"
        if choices is not None:
            msg += choices_hint(value, choices)
        raise self.error(msg)

    def check_keys(self, where: str, prefix: str, table: Any, known: set[str], what: str = "key") -> None:
        """``table`` must be a table whose keys are all in ``known``; ``where`` names it in the message."""
        if not isinstance(table, dict):
            self.fail(prefix.rstrip(".") or self.document, table, "must be a table")
        for key in table:
            if key not in known:
                raise self.error(f"{self.origin}: unknown {what} {prefix}{key!s} in {where}"
                                 + choices_hint(key, sorted(known), "known:"))

    def required(self, table: Mapping, key: str, kind: type | None = None, prefix: str = ""):
        """``table[key]``, of type ``kind`` when one is given (see :meth:`typed`); missing, an error."""
        if key not in table:
            raise self.error(f"{self.origin}: missing key {prefix}{key}")
        return table[key] if kind is None else self.typed(prefix + key, table[key], kind)

    def typed(self, key: str, value: Any, kind: type):
        """``value`` if it is a ``kind``; ``float`` means any finite number (:meth:`number`)."""
        if kind is float:
            return self.number(key, value)
        if not isinstance(value, kind):
            self.fail(key, value, f"must be {type_phrase(kind)}, not {value_phrase(value)}")
        return value

    def number(self, key: str, value: Any) -> float:
        """``value`` as a float; a boolean, a non-number or a non-finite number is an error."""
        why = number_problem(value)
        if why:
            self.fail(key, value, why)
        return float(value)

    def positive(self, key: str, value: float) -> float:
        """``value`` if it is above zero."""
        if value <= 0:
            self.fail(key, value, "must be positive")
        return value

    def number_list(self, key: str, value: Any) -> list[float]:
        """A non-empty list of finite numbers, as floats."""
        if not isinstance(value, list):
            self.fail(key, value, "must be a list of numbers")
        if not value:
            self.fail(key, value, "is empty: give at least one value")
        return [self.number(f"{key}[{i}]", v) for i, v in enumerate(value)]


PRESSURE_UNITS_PA = {"_gauge_Pa": 1.0, "_Pa": 1.0, "_kPa": 1e3, "_gauge_bar": 1e5, "_bar": 1e5, "_psi": 6894.757293168}
"""Gauge pressure suffixes of a measurement file's column names and their factor to Pa (psi: 0.45359237 kg *
9.80665 / 0.0254^2)."""
LENGTH_UNITS_M = {"_mm": 1e-3, "_m": 1.0}
"""Contraction suffixes of a measurement file's column names and their factor to metres."""


def unit_suffix(name: str, units: Mapping[str, float]) -> str | None:
    """The suffix of ``units`` that ``name`` ends in, the longest one (``_kPa`` before ``_Pa``), or None."""
    return next((s for s in sorted(units, key=len, reverse=True) if name.endswith(s)), None)


def unit_columns(header, stems: tuple[str, ...], units: Mapping[str, float]) -> list[str]:
    """Every column of ``header`` whose name starts with one of ``stems`` and ends in a unit of ``units``, in
    order.  Measurement files name their columns so (``pressure_bar``, ``contraction_mm``, ``weight_N``): the
    readers of fits and of a muscle's measured points find them by this one rule."""
    return [name for name in header if name.startswith(stems) and unit_suffix(name, units) is not None]


def unit_column(header, stems: tuple[str, ...], units: Mapping[str, float]) -> tuple[str, float] | None:
    """The first of :func:`unit_columns`, with its unit's factor to SI; None if there is none."""
    for name in unit_columns(header, stems, units)[:1]:
        return name, units[unit_suffix(name, units)]
    return None
