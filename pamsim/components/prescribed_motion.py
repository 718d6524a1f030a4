"""A muscle whose length and lengthening velocity are given: the node of its flange for a tool that owns
the mechanics (Simulink/Simscape, OpenModelica, Dymola, a multibody engine), which reads back its force.

The muscle's static force, friction and damping are branches on this node, as on the hanging load; it
sums them into the force the muscle pulls with.  Friction acts against the contraction velocity's
direction, and not at all at zero velocity: with the motion prescribed there is no stick/slip decision
to make (the importer's mechanics make it), so the force jumps by twice the Coulomb level where the
velocity changes sign, a discontinuity the importer's integrator meets as it would any Coulomb term.
"""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else
from .friction import equivalent_mass_kg


class PrescribedMotion(Component):
    """Inputs ``length_m`` (L) and ``velocity_m_s`` (dL/dt); the muscle's contraction ``x = L0 - L`` and
    contraction velocity ``v = -dL/dt`` on the flange; outputs the force the muscle pulls with,
    ``F_N``, the sum of its branches (positive: tension), and friction's direction ``sign(v)``.

    State ``W_muscle_out_J``: the work the muscle does on what moves it, integral of ``F v``.
    """

    parameters = (positive("L0_m", "m", "the muscle's rest length (zero contraction)"),
                  positive("g_m_s2", "m/s^2", "gravitational acceleration (the load-dependent friction's mass)"))
    ports = (Port("flange", TRANSLATIONAL, "node"),)
    inputs = (Var("length_m", "m", "the muscle's length L"), Var("velocity_m_s", "m/s", "its lengthening rate dL/dt"),
              Var("F_static_N", "N", "the muscle's static force"))
    states = (Var("W_muscle_out_J", "J", "work done by the muscle on what moves it", 0.1),)
    outputs = (Var("F_N", "N", "force the muscle pulls with: static, damping and friction (positive: tension)"),
               Var("x_m", "m", "contraction L0 - L"), Var("v_m_s", "m/s", "contraction velocity -dL/dt"),
               Var("direction", "1", "+1 contracting, -1 lengthening, 0 at rest"),
               Var("load_mass_kg", "kg", "mass whose weight is the muscle's static force"))

    def equations(self, s: Symbols) -> Equations:
        P, u = s.p, s.u
        x, v = P["L0_m"] - u["length_m"], -u["velocity_m_s"]
        F = s.port["flange"]["F_N"]
        direction = if_else(v > 0.0, 1.0, if_else(v < 0.0, -1.0, 0.0))
        return Equations(der={"W_muscle_out_J": F * v},
                         outputs={"F_N": F, "x_m": x, "v_m_s": v, "direction": direction,
                                  "load_mass_kg": equivalent_mass_kg(u["F_static_N"], P["g_m_s2"])},
                         port={"flange": {"x_m": x, "v_m_s": v}}, initial={"W_muscle_out_J": 0.0})
