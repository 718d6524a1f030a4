"""Library of static force models of McKibben muscles: one registry, one contract.

``REGISTRY`` maps a model name to its :class:`StaticModelSpec`; ``get(name)``
returns one (``InputError`` with a did-you-mean for an unknown name) and
``spec.build(muscle_parameters)`` the built model, whose ``force_N(x_m,
p_gauge_Pa)`` is the raw pulling force.  See ``docs/static_models.md``.
"""

from __future__ import annotations

from types import MappingProxyType

from ..errors import InputError
from . import acra2012, elastic_survey, force_map, gaylord, hyperelastic, kothera, phenomenological, two_phase
from ..table_checks import did_you_mean
from .base import KINDS, Domain, StaticForce, StaticModelDomainError, StaticModelSpec

_FAMILIES = (acra2012, gaylord, kothera, hyperelastic, elastic_survey, phenomenological, two_phase, force_map)

REGISTRY = MappingProxyType({spec.name: spec for family in _FAMILIES for spec in family.SPECS})
"""name -> :class:`StaticModelSpec` for every library model."""


def names() -> list[str]:
    """Registry names in library order."""
    return list(REGISTRY)


def get(name: str) -> StaticModelSpec:
    """The spec of model ``name``.

    Raises
    ------
    InputError
        Naming the unknown name, with the closest known name.
    """
    try:
        return REGISTRY[name]
    except KeyError:
        raise InputError(f"static model = {name!r}: unknown model{did_you_mean(name, REGISTRY)} "
                         f"(known: {', '.join(REGISTRY)})") from None


__all__ = ["REGISTRY", "get", "names", "StaticModelSpec", "StaticForce", "Domain", "StaticModelDomainError",
           "KINDS"]
