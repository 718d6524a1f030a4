"""Physical components: each element of a muscle system, its variables and ports, written once.

Each module holds one component.  The physics stays in the elements (:mod:`pamsim.elements`) and the
static force library (:mod:`pamsim.static_models`): a component declares the variables and ports
around an element and calls the element's own functions with symbols, so the equations exist in one
place and every generated form comes from them.
"""

from .catalogue import COMPONENT_TYPES, register_component
from .chamber import Chamber
from .damping import ViscousDamping
from .external_force import ExternalForce
from .friction import CoulombFriction
from .hanging_load import HangingLoad, LoadMode
from .linear_slider import LinearSlider
from .pressure import PressureSignal
from .pulley import Pulley, SliderTendon
from .reservoir import Reservoir
from .rotary_joint import RotaryJoint
from .spring import LinearSpring
from .static_force import MuscleStaticForce
from .supply import RegulatedSupply
from .tube import Tube
from .valve import ProportionalValve, SuppliedValve

__all__ = ["COMPONENT_TYPES", "Chamber", "CoulombFriction", "ExternalForce", "HangingLoad", "LinearSlider",
           "LinearSpring", "LoadMode",
           "MuscleStaticForce", "PressureSignal", "ProportionalValve", "Pulley", "RegulatedSupply", "Reservoir",
           "RotaryJoint", "SliderTendon", "SuppliedValve", "Tube", "ViscousDamping",
           "register_component"]
