"""Elementary functions for code that runs on floats and on CasADi symbols alike.

A float goes to :mod:`math` (the result is bit for bit what the plain code gives); anything else to
CasADi.  :mod:`math` itself must not see a symbol: it converts it to ``nan`` silently.
"""

from __future__ import annotations

import math


def _casadi():
    import casadi
    return casadi


def cos(a):
    return math.cos(a) if isinstance(a, (int, float)) else _casadi().cos(a)


def sin(a):
    return math.sin(a) if isinstance(a, (int, float)) else _casadi().sin(a)


def sqrt(a):
    return math.sqrt(a) if isinstance(a, (int, float)) else _casadi().sqrt(a)


def radians(a):
    return math.radians(a) if isinstance(a, (int, float)) else a * (math.pi / 180.0)


def fmin(a, b):
    return min(a, b) if isinstance(a, (int, float)) and isinstance(b, (int, float)) else _casadi().fmin(a, b)


def fmax(a, b):
    return max(a, b) if isinstance(a, (int, float)) and isinstance(b, (int, float)) else _casadi().fmax(a, b)


def clip(a, low, high):
    """``a`` held within ``[low, high]`` (on floats, ``min(max(a, low), high)``, as ``numpy.clip``)."""
    return fmin(fmax(a, low), high)


def if_else(condition, if_true, if_false):
    """``if_true`` where ``condition`` holds, else ``if_false`` (both are evaluated for a symbol)."""
    if isinstance(condition, (bool, int, float)):
        return if_true if condition else if_false
    return _casadi().if_else(condition, if_true, if_false)
