"""A linear spring in parallel with the muscle: a branch on the load's flange.

Parameters and their sources are the scenario's: a spring is something a user adds to the rig (a
return spring, a compliant mounting), so its stiffness comes from its data sheet or a measurement.
"""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, non_negative


class LinearSpring(Component):
    """``F = -k (x - x_free)`` on the flange: it pulls the load back toward the contraction ``x_free_m``
    at which it carries no force, and pushes as well as pulls.

    State ``W_spring_J``: the work the spring does on the load, the integral of ``F v``.
    """

    parameters = (non_negative("k_N_per_m", "N/m", "stiffness"),
                  Var("x_free_m", "m", "contraction at which the spring carries no force"))
    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    states = (Var("W_spring_J", "J", "work done by the spring on the load", 0.1),)
    outputs = (Var("F_spring_N", "N", "spring force on the load along x"),)

    def equations(self, s: Symbols) -> Equations:
        x, v = s.port["flange"]["x_m"], s.port["flange"]["v_m_s"]
        F = -s.p["k_N_per_m"] * (x - s.p["x_free_m"])
        return Equations(der={"W_spring_J": F * v}, outputs={"F_spring_N": F}, port={"flange": {"F_N": F}},
                         initial={"W_spring_J": 0.0})
