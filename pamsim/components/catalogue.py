"""The components a scenario can add to the rig by name (``[[component]]`` tables).

A component is listed here if it is made from a name and its declared parameters alone
(``cls(name, values)``); the rig's own components, built around its elements, are not.  A class may also
offer choices of form by name (``choices``: ``{key: names}``, the first the default, passed as keywords:
a reservoir's ``law``), declare its table's keys per choice (``scenario_parameters(options)``) and give
defaults for some (``defaults``).  A package built on pamsim adds its own with :func:`register_component`.
"""

from __future__ import annotations

from ..modeling import Component
from .elasto_slide import ElastoSlide
from .reservoir import Reservoir
from .spring import LinearSpring
from .supply import RegulatedSupply
from .tube import Tube

COMPONENT_TYPES: dict[str, type[Component]] = {"linear_spring": LinearSpring, "elasto_slide": ElastoSlide,
                                               "supply": RegulatedSupply, "reservoir": Reservoir, "tube": Tube}
"""``{type name: component class}``."""


def register_component(type_name: str, cls: type[Component]) -> None:
    """Let scenarios add components of class ``cls`` as ``type = "type_name"``."""
    if not (isinstance(cls, type) and issubclass(cls, Component)):
        raise TypeError(f"register_component({type_name!r}, {cls!r}): not a Component subclass")
    COMPONENT_TYPES[type_name] = cls
