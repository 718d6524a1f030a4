"""Elementary functions for code that runs on floats and on CasADi symbols alike.

A float takes Python's own operation (the result is bit for bit what the plain code gives); anything
else CasADi's.  :mod:`math` itself must not see a symbol: it converts it to ``nan`` silently.
"""

from __future__ import annotations


def _casadi():
    import casadi
    return casadi


def fmin(a, b):
    """The smaller of ``a`` and ``b`` (C's ``fmin``), on floats or symbols."""
    return min(a, b) if isinstance(a, (int, float)) and isinstance(b, (int, float)) else _casadi().fmin(a, b)


def fmax(a, b):
    """The larger of ``a`` and ``b`` (C's ``fmax``), on floats or symbols."""
    return max(a, b) if isinstance(a, (int, float)) and isinstance(b, (int, float)) else _casadi().fmax(a, b)


def clip(a, low, high):
    """``a`` held within ``[low, high]`` (on floats, ``min(max(a, low), high)``, as ``numpy.clip``)."""
    return fmin(fmax(a, low), high)


def if_else(condition, if_true, if_false):
    """``if_true`` where ``condition`` holds, else ``if_false`` (both are evaluated for a symbol)."""
    if isinstance(condition, (bool, int, float)):
        return if_true if condition else if_false
    return _casadi().if_else(condition, if_true, if_false)
