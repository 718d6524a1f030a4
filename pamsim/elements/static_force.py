"""Static (quasi-static) force of the muscle, F_static(x, p).

Positive force contracts the muscle (lifts the load).  The models live in the
static-model library :mod:`pamsim.static_models` (one registry); any of them
meets :class:`pamsim.elements.contracts.StaticForce`.  ``STATIC_FORCE_MODELS``
is a read-only view of that registry which maps a scenario's ``static_force``
key to a builder ``builder(params, options)`` of the force as the dynamics
apply it, over the contractions between the stops that ``options["upper_stop"]``
chooses (:func:`pamsim.elements.muscle_force.dynamics_static_force`: tabulated
if implicit, clipped at zero unless ``static_force_negative = "keep"``).
Whether a model applies to a muscle is checked where the muscle is known
(:func:`pamsim.muscle_setup.applicable_model`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Iterator

from ..static_models import REGISTRY
from ..static_models.acra2012 import Acra2012Polynomial
from .contracts import NO_OPTIONS, Builder, ElementOptions, StaticForce
from .muscle_force import dynamics_static_force
from .stops import UPPER_STOP_DEFAULT, EndStops

__all__ = ["Acra2012Polynomial", "STATIC_FORCE_MODELS"]


class _Builders(Mapping[str, Builder[StaticForce]]):
    """name -> ``builder(params, options)`` for every library model."""

    def __getitem__(self, name: str) -> Builder[StaticForce]:
        if name not in REGISTRY:
            raise KeyError(name)

        def build(params: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> StaticForce:
            variant = options.get("static_force_variant")
            raw = REGISTRY[name].build(params, variant)
            stops = EndStops.for_model(params, raw.domain.x_max_m, options.get("upper_stop", UPPER_STOP_DEFAULT))
            return dynamics_static_force(name, params, (0.0, stops.x_high_m), variant,
                                         options.get("static_force_negative", "clip"), built=raw)
        return build

    def __iter__(self) -> Iterator[str]:
        return iter(REGISTRY)

    def __len__(self) -> int:
        return len(REGISTRY)


STATIC_FORCE_MODELS: Mapping[str, Builder[StaticForce]] = _Builders()
