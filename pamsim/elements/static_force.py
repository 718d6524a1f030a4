"""Static (quasi-static) force of the muscle, F_static(x, p).

Positive force contracts the muscle (lifts the load).  The models live in the
static-model library :mod:`pamsim.static_models` (one registry); any of them
meets :class:`pamsim.elements.contracts.StaticForce`.  ``STATIC_FORCE_MODELS``
is a read-only view of that registry, restricted to the models that the
built-in parameter sets can build, which maps a scenario's ``static_force`` key
to a builder ``builder(params, options)``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Iterator

from ..parameters import PARAMETER_SETS
from ..static_models import REGISTRY
from ..static_models.acra2012 import Acra2012Polynomial
from .contracts import NO_OPTIONS, Builder, ElementOptions, StaticForce

__all__ = ["Acra2012Polynomial", "STATIC_FORCE_MODELS"]


class _Builders(Mapping[str, Builder[StaticForce]]):
    """name -> ``builder(params, options)`` for the library models a built-in parameter set can build."""

    def __init__(self):
        self._names = tuple(name for name, spec in REGISTRY.items()
                            if any(not spec.missing(ps) for ps in PARAMETER_SETS.values()))

    def __getitem__(self, name: str) -> Builder[StaticForce]:
        if name not in self._names:
            raise KeyError(name)
        spec = REGISTRY[name]

        def build(params: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> StaticForce:
            return spec.build(params)
        return build

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)


STATIC_FORCE_MODELS: Mapping[str, Builder[StaticForce]] = _Builders()
