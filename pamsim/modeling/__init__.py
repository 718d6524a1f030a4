"""The modelling layer: components with declared variables and ports, assemblies of them, the flat
model they make, and the code generated from it (Python, C, exact Jacobians).

This layer knows nothing about muscles.  Components (:mod:`pamsim.components`) write their equations
once, with operations that work on CasADi symbols; :class:`Assembly` connects them into one
:class:`FlatModel`, whose right-hand side, outputs, event indicators and mode transitions are CasADi
expressions of the states, inputs, parameters and modes.  From those come the generated Python
(:mod:`pamsim.modeling.pygen`), the C (:mod:`pamsim.modeling.cgen`) and the Jacobians.
"""

from . import code_cache, smath
from .assembly import Assembly, AssemblyError
from .component import Component, Equations, Symbols
from .flat import FlatModel
from .variables import LINEAR, PNEUMATIC, ROTATIONAL, SIGNAL, TRANSLATIONAL, Port, PortKind, Var, non_negative, positive

__all__ = ["Assembly", "AssemblyError", "Component", "Equations", "FlatModel", "PNEUMATIC", "Port", "PortKind",
           "LINEAR", "ROTATIONAL", "SIGNAL", "Symbols", "TRANSLATIONAL", "Var", "code_cache", "non_negative", "positive", "smath"]
