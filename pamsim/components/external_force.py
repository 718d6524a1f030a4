"""A prescribed force on the load (an input), positive along the contraction.

It goes to the load as a signal rather than a flange branch: the load adds it after its weight, the
order in which pamsim has always summed the forces (the results stay the same to the last bit).
"""

from __future__ import annotations

from ..modeling import Component, Equations, Symbols, Var


class ExternalForce(Component):
    """Input ``F_N``, passed to the load.  State ``W_external_J``: its work, integral of ``F v``."""

    inputs = (Var("F_N", "N", "force on the load along x"), Var("v_m_s", "m/s", "velocity of the load"))
    states = (Var("W_external_J", "J", "work of the external force", 0.1),)
    outputs = (Var("F_external_N", "N", "external force on the load along x"),)

    def equations(self, s: Symbols) -> Equations:
        F = s.u["F_N"]
        return Equations(der={"W_external_J": F * s.u["v_m_s"]}, outputs={"F_external_N": F})
