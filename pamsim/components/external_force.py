"""A prescribed force on the load (an input), positive along the contraction."""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var


class ExternalForce(Component):
    """Input ``F_N`` applied to the flange.  State ``W_external_J``: its work, integral of ``F v``."""

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    inputs = (Var("F_N", "N", "force on the load along x"),)
    states = (Var("W_external_J", "J", "work of the external force", 0.1),)
    outputs = (Var("F_external_N", "N", "external force on the load along x"),)

    def equations(self, s: Symbols) -> Equations:
        F = s.u["F_N"]
        return Equations(der={"W_external_J": F * s.port["flange"]["v_m_s"]}, outputs={"F_external_N": F},
                         port={"flange": {"F_N": F}})
