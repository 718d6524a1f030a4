"""Elementary functions for code that runs on floats and on CasADi symbols alike.

A float takes Python's own operation (the result is bit for bit what the plain code gives); anything
else CasADi's (``fmin``, ``fmax`` and ``clip`` also take numpy arrays, elementwise: CasADi would make a column
of a row).  :mod:`math` itself must not see a symbol: it converts it to ``nan`` silently.
"""

from __future__ import annotations

import numpy as np


def _casadi():
    import casadi
    return casadi


def _arrays(a, b) -> bool:
    """Whether ``a`` and ``b`` are numbers with at least one numpy array (a trace's samples), no symbol."""
    numeric = (int, float, np.ndarray)
    return isinstance(a, numeric) and isinstance(b, numeric) and (isinstance(a, np.ndarray) or isinstance(b, np.ndarray))


def fmin(a, b):
    """The smaller of ``a`` and ``b`` (C's ``fmin``), on floats, arrays (elementwise, their shape kept) or symbols."""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return min(a, b)
    return np.fmin(a, b) if _arrays(a, b) else _casadi().fmin(a, b)


def fmax(a, b):
    """The larger of ``a`` and ``b`` (C's ``fmax``), on floats, arrays (elementwise, their shape kept) or symbols."""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return max(a, b)
    return np.fmax(a, b) if _arrays(a, b) else _casadi().fmax(a, b)


def clip(a, low, high):
    """``a`` held within ``[low, high]`` (on floats, ``min(max(a, low), high)``, as ``numpy.clip``)."""
    return fmin(fmax(a, low), high)


def if_else(condition, if_true, if_false):
    """``if_true`` where ``condition`` holds, else ``if_false`` (both are evaluated for a symbol)."""
    if isinstance(condition, (bool, int, float)):
        return if_true if condition else if_false
    return _casadi().if_else(condition, if_true, if_false)


def _unary(name: str, doc: str):
    import math

    fn = getattr(math, name)

    def op(a):
        return fn(a) if isinstance(a, (int, float)) else getattr(_casadi(), name)(a)

    op.__name__, op.__doc__ = name, doc
    return op


cos = _unary("cos", "``cos(a)`` (radians), on floats (:func:`math.cos`) or symbols.")
sin = _unary("sin", "``sin(a)`` (radians), on floats (:func:`math.sin`) or symbols.")
sqrt = _unary("sqrt", "``sqrt(a)``, on floats (:func:`math.sqrt`) or symbols.")
tanh = _unary("tanh", "``tanh(a)``, on floats (:func:`math.tanh`) or symbols.")


def radians(degrees):
    """``degrees`` in radians, on floats bit for bit as :func:`math.radians` (which multiplies by pi / 180)."""
    return degrees * (3.141592653589793 / 180.0)
