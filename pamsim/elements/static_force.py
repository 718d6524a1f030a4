"""Static (quasi-static) force of the muscle, F_static(x, p).

Positive force contracts the muscle (lifts the load).  The models themselves
live in the static-model library :mod:`pamsim.static_models` (one registry);
``STATIC_FORCE_MODELS`` is a read-only view of it that maps a scenario's
``static_force`` key to a builder taking the muscle's parameters.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Callable, Iterator, Protocol

from ..static_models import REGISTRY
from ..static_models.acra2012 import Acra2012Polynomial

__all__ = ["StaticForceModel", "Acra2012Polynomial", "STATIC_FORCE_MODELS"]


class StaticForceModel(Protocol):
    """What the simulator needs of a static force model."""

    name: str

    def force_N(self, x_m, p_gauge_Pa):
        """Static force [N] at contraction ``x_m`` [m] and gauge pressure [Pa]."""


class _Builders(Mapping[str, Callable]):
    """name -> ``spec.build`` for every model of the library registry."""

    def __getitem__(self, name: str) -> Callable:
        return REGISTRY[name].build

    def __iter__(self) -> Iterator[str]:
        return iter(REGISTRY)

    def __len__(self) -> int:
        return len(REGISTRY)


STATIC_FORCE_MODELS: Mapping[str, Callable] = _Builders()
