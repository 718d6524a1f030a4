"""SI base units of the unit strings in the FMU's variable table (``<BaseUnit>`` in
``modelDescription.xml``), so that importers can convert bar, degrees and the like.

A unit string is a product of symbols with integer powers, optionally divided by one symbol or a
parenthesised product: ``N``, ``m/s^2``, ``N s^2/m^2``, ``J/(kg K)``, ``N/(bar m^2)``; ``1`` is
dimensionless.
"""

from __future__ import annotations

import math
from collections import Counter

BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
"""The exponents an FMI ``<BaseUnit>`` carries, in the standard's order."""

SYMBOLS: dict[str, tuple[float, dict[str, int]]] = {
    "1": (1.0, {}),
    "kg": (1.0, {"kg": 1}),
    "m": (1.0, {"m": 1}),
    "s": (1.0, {"s": 1}),
    "Hz": (1.0, {"s": -1}),
    "K": (1.0, {"K": 1}),
    "N": (1.0, {"kg": 1, "m": 1, "s": -2}),
    "Pa": (1.0, {"kg": 1, "m": -1, "s": -2}),
    "bar": (1.0e5, {"kg": 1, "m": -1, "s": -2}),
    "J": (1.0, {"kg": 1, "m": 2, "s": -2}),
    "W": (1.0, {"kg": 1, "m": 2, "s": -3}),
    "deg": (math.pi / 180.0, {"rad": 1}),
    "rad": (1.0, {"rad": 1}),
}
"""Symbol: (factor to SI, base-unit exponents)."""


def _product(text: str, sign: int, exponents: Counter) -> float:
    factor = 1.0
    for token in text.strip().strip("()").split():
        symbol, _, power = token.partition("^")
        if symbol not in SYMBOLS:
            raise ValueError(f"unit symbol {symbol!r} is not in pamsim.fmu.units.SYMBOLS")
        n = sign * (int(power) if power else 1)
        f, exps = SYMBOLS[symbol]
        factor *= f ** n
        for base, e in exps.items():
            exponents[base] += e * n
    return factor


def base_unit(unit: str) -> tuple[float, dict[str, int]]:
    """``(factor, {base: exponent})`` with value_SI = factor * value for a value in ``unit``."""
    numerator, _, denominator = unit.partition("/")
    exponents: Counter = Counter()
    factor = _product(numerator, 1, exponents)
    if denominator:
        factor *= _product(denominator, -1, exponents)
    return factor, {b: exponents[b] for b in BASE_UNITS if exponents[b]}
