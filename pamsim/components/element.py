"""An element's numbers as a component's parameters, and the element rebuilt around symbols.

The elements are frozen dataclasses of numbers with pure methods.  Rebuilt with CasADi symbols in
place of the numbers, the same methods give the component's equations: the physics is not copied.
Fields that choose a form rather than give a number (``name``, ``negative_level``) stay as they are.
"""

from __future__ import annotations

import dataclasses
import hashlib
from typing import Any, Mapping

import numpy as np

from ..modeling import Var
from ..parameter_schema import unit_of

STRUCTURAL = ("name", "negative_level")
"""Fields that are choices or metadata, never parameters."""


def _numbers(element, out: dict[str, float]) -> None:
    for f in dataclasses.fields(element):
        value = getattr(element, f.name)
        if f.name in STRUCTURAL:
            continue
        if dataclasses.is_dataclass(value):
            _numbers(value, out)
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            if f.name in out:
                raise ValueError(f"{type(element).__name__}: parameter {f.name!r} appears twice")
            out[f.name] = float(value)


def element_parameters(element) -> dict[str, float]:
    """``{field name: value}`` of every number in ``element`` (nested elements included)."""
    out: dict[str, float] = {}
    _numbers(element, out)
    return out


def structure_key(element, baked: bool = False) -> tuple:
    """What of ``element`` shapes its equations, as a value equal across processes: its type and every
    field that is not a parameter (a choice, a tuple of coefficients), recursively.  Two
    elements with one key differ only in parameter values, so they share one generated model.

    Only the numbers of dataclass elements become parameters (:func:`element_parameters`); an element
    of another kind (a static model class holding its derived constants) is traced with its numbers
    as constants, so they are part of its key (``baked``).
    """
    if dataclasses.is_dataclass(element):
        items = []
        for f in dataclasses.fields(element):
            value = getattr(element, f.name)
            if f.name in STRUCTURAL or baked or not _is_number(value):
                items.append((f.name, _stable(value, baked or f.name in STRUCTURAL)))
        return (type(element).__module__, type(element).__qualname__, tuple(items))
    return _stable(element, True)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _stable(value, baked: bool):
    """``value`` as something whose equality and repr do not depend on the process (no addresses)."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (tuple, list)):
        return tuple(_stable(v, baked) for v in value)
    if isinstance(value, np.ndarray):
        return ("ndarray", value.shape, str(value.dtype), hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest())
    if dataclasses.is_dataclass(value):
        return structure_key(value, baked)
    if isinstance(value, Mapping):
        return tuple(sorted((str(k), _stable(v, baked)) for k, v in value.items()))
    if callable(value) and hasattr(value, "__qualname__"):
        return ("callable", getattr(value, "__module__", ""), value.__qualname__)
    if hasattr(value, "__dict__"):
        return (type(value).__module__, type(value).__qualname__,
                tuple(sorted((k, _stable(v, True)) for k, v in vars(value).items())))
    return repr(value)


def parameter_vars(values: Mapping[str, float], descriptions: Mapping[str, str] | None = None) -> tuple[Var, ...]:
    """Declarations of parameters named with their unit as suffix (``D1_N_s_per_m``)."""
    descriptions = descriptions or {}
    return tuple(Var(name, unit_of(name), descriptions.get(name, "")) for name in values)


def symbolic(element, symbols: Mapping[str, Any]):
    """``element`` with each number replaced by ``symbols[field name]`` (nested elements too)."""
    changes = {}
    for f in dataclasses.fields(element):
        value = getattr(element, f.name)
        if f.name in STRUCTURAL:
            continue
        if dataclasses.is_dataclass(value):
            changes[f.name] = symbolic(value, symbols)
        elif f.name in symbols:
            changes[f.name] = symbols[f.name]
    return dataclasses.replace(element, **changes)


class ElementParameters:
    """Mixin: a component whose parameters are the numbers of its element (``self.element``)."""

    element: Any
    extra_parameters: tuple[Var, ...] = ()

    def parameter_vars(self) -> tuple[Var, ...]:
        return parameter_vars(element_parameters(self.element)) + self.extra_parameters

    def symbolic_element(self, p: Mapping[str, Any]):
        return symbolic(self.element, p)

    def structure_key(self) -> tuple:
        return super().structure_key() + (structure_key(self.element),)
