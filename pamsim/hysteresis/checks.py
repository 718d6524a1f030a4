"""Checks of a hysteresis model's parameters: a bad value raises one :class:`~pamsim.errors.InputError` line
naming the key and the value."""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError

MAX_ELEMENTS = 100
"""The most elements (Maxwell-slip) or play operators (Prandtl-Ishlinskii) a model may have."""


def count(key: str, n) -> int:
    """``n`` as a count of elements, 1 to :data:`MAX_ELEMENTS`."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_ELEMENTS:
        raise InputError(f"{key} = {n!r}: must be an integer from 1 to {MAX_ELEMENTS}")
    return int(n)


def vector(key: str, values, minimum: float | None = None, strict: bool = False) -> np.ndarray:
    """``values`` as a finite 1-D float array of 1 to :data:`MAX_ELEMENTS` entries, each at least ``minimum``
    (above it with ``strict``); the message names the entry (``key[i]``)."""
    v = np.atleast_1d(np.asarray(values, dtype=float))
    if v.ndim != 1 or not 1 <= v.size <= MAX_ELEMENTS:
        raise InputError(f"{key}: {v.size} values: give 1 to {MAX_ELEMENTS} numbers, one per element")
    for i, x in enumerate(v.tolist()):
        low = minimum is not None and (x <= minimum if strict else x < minimum)
        if not math.isfinite(x) or low:
            why = "must be finite" if not math.isfinite(x) else \
                f"must be {'above' if strict else 'at least'} {minimum:g}"
            raise InputError(f"{key}[{i}] = {x!r}: {why}")
    return v


def number(key: str, value, minimum: float | None = None, strict: bool = False, infinite: bool = False) -> float:
    """``value`` as a float, finite unless ``infinite``, at least (above, ``strict``) ``minimum``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{key} = {value!r}: must be a number") from None
    if math.isnan(x) or (math.isinf(x) and not (infinite and x > 0)):
        raise InputError(f"{key} = {value!r}: must be a finite number")
    if minimum is not None and (x <= minimum if strict else x < minimum):
        raise InputError(f"{key} = {value!r}: must be {'above' if strict else 'at least'} {minimum:g}")
    return x
