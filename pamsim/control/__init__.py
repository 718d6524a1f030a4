"""Control design with python-control: the muscle as an I/O system, operating
points, linearisations and a closed-loop position controller.

python-control is imported as ``ct``; this package never shadows it.  See
``docs/control.md``.
"""

from .linear import LinearModel, MechanicalMode, linearize
from .operating_point import OperatingPoint, held_equilibrium, open_valve_equilibrium, trajectory_point
from .system import INPUTS, OUTPUTS, STATES, FrictionTreatment, MusclePlant, muscle_nlsys

__all__ = ["FrictionTreatment", "INPUTS", "LinearModel", "MechanicalMode", "MusclePlant", "OUTPUTS",
           "OperatingPoint", "STATES", "held_equilibrium", "linearize", "muscle_nlsys", "open_valve_equilibrium",
           "trajectory_point"]
