"""An element's numbers as a component's parameters, and the element rebuilt around symbols.

The elements are frozen dataclasses of numbers with pure methods.  Rebuilt with CasADi symbols in
place of the numbers, the same methods give the component's equations: the physics is not copied.
Fields that choose a form rather than give a number (``name``, ``negative_level``, a ``domain``) stay
as they are.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Mapping

from ..modeling import Var
from ..parameter_schema import unit_of

STRUCTURAL = ("name", "domain", "negative_level")
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


def structure_key(element) -> tuple:
    """What of ``element`` shapes its equations: its type and every field that is not a parameter (a
    choice, a tuple of coefficients, a domain), recursively.  Two elements with one key differ only in
    parameter values, so they share one generated model."""
    items = []
    for f in dataclasses.fields(element):
        value = getattr(element, f.name)
        if f.name not in STRUCTURAL and dataclasses.is_dataclass(value):
            items.append((f.name, structure_key(value)))
        elif f.name in STRUCTURAL or not isinstance(value, (int, float)) or isinstance(value, bool):
            items.append((f.name, repr(value)))
    return (type(element).__module__, type(element).__qualname__, tuple(items))


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
