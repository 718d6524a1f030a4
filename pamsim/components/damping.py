"""Viscous damping between the muscle and its load: a branch on the load's flange."""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var
from .element import ElementParameters, element_parameters


class ViscousDamping(ElementParameters, Component):
    """Any damping law of :mod:`pamsim.elements.damping`: a force ``-F_damp(v)`` on the flange.

    State ``E_damping_J``: the work of the damping force, integral of ``F_damp v`` (positive when it
    dissipates).
    """

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    states = (Var("E_damping_J", "J", "work done against the damping force", 0.1),)
    outputs = (Var("F_damping_N", "N", "damping force on the load along x"),)

    def __init__(self, name: str, element):
        self.element = element
        super().__init__(name, element_parameters(element))

    def equations(self, s: Symbols) -> Equations:
        v = s.port["flange"]["v_m_s"]
        F = self.symbolic_element(s.p).force_N(v)
        return Equations(der={"E_damping_J": F * v}, outputs={"F_damping_N": -F}, port={"flange": {"F_N": -F}})
