"""Square root, power, exponential and logarithm that stay real: NaN where the real function has no value.

Python's ``v ** 0.5`` of a negative float is a complex number and ``math.log(0)``
raises, so a model evaluated outside its domain (a bladder that would overfill
the braid, a contraction past the rest length, a pressure below zero) would
return a complex "force" or stop with an exception.  NaN is what the domain
machinery expects of such a point (``pamsim.elements.force_domain`` then holds
the dynamics at the domain's edge).  Python floats take the plain path, which
keeps the ODE's scalar inner loop fast (a root stays ``v ** 0.5``, as the models
always computed it); arrays take numpy's, which already gives NaN; CasADi
symbols (a model traced into a component) take CasADi's, with the same NaNs.
"""

from __future__ import annotations

import math

import numpy as np

_NAN = math.nan


def _symbolic(*values) -> bool:
    return any(type(v).__module__.startswith("casadi") for v in values)


def sqrt(v):
    """``sqrt(v)``, NaN for ``v < 0``."""
    if isinstance(v, (float, int)):
        return v ** 0.5 if v >= 0.0 else _NAN
    if _symbolic(v):
        import casadi
        return casadi.sqrt(v)
    with np.errstate(invalid="ignore"):
        return np.sqrt(v)


def power(base, exponent):
    """``base ** exponent`` for a stretch or a length ratio: NaN for a negative base (no real power)."""
    if isinstance(base, (float, int)) and isinstance(exponent, (float, int)):
        return base ** exponent if base >= 0.0 else _NAN
    if _symbolic(base, exponent):
        import casadi
        return casadi.if_else(base >= 0.0, base ** exponent, _NAN)
    base = np.asarray(base, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(base >= 0.0, np.power(base, exponent), _NAN)


def exp(v):
    """``exp(v)``; ``inf`` where a float would overflow (as numpy gives)."""
    if isinstance(v, (float, int)):
        try:
            return math.exp(v)
        except OverflowError:
            return math.inf
    if _symbolic(v):
        import casadi
        return casadi.exp(v)
    with np.errstate(over="ignore"):
        return np.exp(v)


def log(v):
    """``ln(v)``, NaN for ``v <= 0`` (no finite real value)."""
    if isinstance(v, (float, int)):
        return math.log(v) if v > 0.0 else _NAN
    if _symbolic(v):
        import casadi
        return casadi.if_else(v > 0.0, casadi.log(v), _NAN)
    v = np.asarray(v, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(v > 0.0, np.log(v), _NAN)
