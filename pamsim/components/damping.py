"""Viscous damping between the muscle and its load: a branch on the load's flange."""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var
from .element import ElementParameters

PROBE_POINTS = tuple((v,) for v in (-0.5, -0.05, -1e-3, 0.0, 1e-3, 0.05, 0.5))
"""Velocities [m/s] at which a law's symbolic form is checked."""


def _force_N(element, v_m_s):
    return element.force_N(v_m_s)


class ViscousDamping(ElementParameters, Component):
    """Any damping law of :mod:`pamsim.elements.damping`: a force ``-F_damp(v)`` on the flange.

    State ``E_damping_J``: the work of the damping force, integral of ``F_damp v`` (positive when it
    dissipates).
    """

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    states = (Var("E_damping_J", "J", "work done against the damping force", 0.1),)
    outputs = (Var("F_damping_N", "N", "damping force on the load along x"),)

    def __init__(self, name: str, element):
        super().__init__(name, self.wrap(element, _force_N, PROBE_POINTS))

    def equations(self, s: Symbols) -> Equations:
        v = s.port["flange"]["v_m_s"]
        F = self.element_call(s, "force_N", v)
        return Equations(der={"E_damping_J": F * v}, outputs={"F_damping_N": -F}, port={"flange": {"F_N": -F}})
