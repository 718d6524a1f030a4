"""A muscle's tendon on a pulley of the joint it turns: the muscle's contraction follows the joint angle,
and its pull becomes a torque; a tendon only pulls.

The pulley is the node of its muscle's flange (the static force, damping and friction are branches on
it, as on the hanging load) and a branch on the joint's shaft.  A muscle whose forces add up to a push
(pushed past the contraction at which it pulls nothing) leaves its tendon slack: no force, no torque,
no friction on the joint.  The slack's start and end are kinks in the torque, which the integrators'
step control resolves, not events.
"""

from __future__ import annotations

from ..modeling import ROTATIONAL, TRANSLATIONAL, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else
from .friction import equivalent_mass_kg


class Pulley(Component):
    """``x = x_at_zero + side r theta`` and ``v = side r omega`` for the muscle; a tendon force
    ``T = max(F, 0)`` from the sum ``F`` of the muscle's forces; ``tau = side r T`` on the shaft.

    ``side`` is +1 for a muscle that contracts as the angle grows (it turns the joint toward larger
    angles), -1 for one that contracts as it falls.  The muscle's Coulomb level reaches the joint as
    ``r F_c`` while the tendon is taut, and the joint's slip direction reaches the muscle's friction as
    ``side`` times it.  The load-dependent friction law reads the load a muscle holds as a mass: here
    the mass whose weight equals its static force, ``max(F_static, 0) / g``.

    State ``W_tendon_J``: the work the tendon does on the joint, integral of ``T v``.
    """

    parameters = (positive("radius_m", "m", "pulley radius (the tendon's lever arm)"),
                  Var("side", "1", "+1: the muscle turns the joint toward larger angles; -1: toward smaller",
                      lower=-1.0, upper=1.0),
                  Var("x_at_zero_m", "m", "the muscle's contraction at joint angle zero"),
                  positive("g_m_s2", "m/s^2", "gravitational acceleration (the load-dependent friction's mass)"))
    ports = (Port("shaft", ROTATIONAL, "branch"), Port("flange", TRANSLATIONAL, "node"))
    inputs = (Var("friction_level_N", "N", "Coulomb friction level of the muscle"),
              Var("joint_direction", "1", "+1 or -1 while the joint angle grows or falls, 0 while held"),
              Var("F_static_N", "N", "the muscle's static force"))
    states = (Var("W_tendon_J", "J", "work done by the tendon on the joint", 0.1),)
    outputs = (Var("x_m", "m", "the muscle's contraction"), Var("v_m_s", "m/s", "the muscle's contraction velocity"),
               Var("F_tendon_N", "N", "tendon force (zero when slack)"), Var("tau_Nm", "N m", "torque on the joint"),
               Var("taut", "1", "1 while the tendon pulls, 0 while slack"),
               Var("direction", "1", "+1 or -1 while the muscle contracts or extends under the joint's slip, 0 held"),
               Var("load_mass_kg", "kg", "mass whose weight is the muscle's static force"))

    def equations(self, s: Symbols) -> Equations:
        P, shaft = s.p, s.port["shaft"]
        arm = P["side"] * P["radius_m"]
        x = P["x_at_zero_m"] + arm * shaft["theta_rad"]
        v = arm * shaft["omega_rad_s"]
        F = s.port["flange"]["F_N"]
        taut = F > 0.0
        T = if_else(taut, F, 0.0)
        return Equations(
            der={"W_tendon_J": T * v},
            outputs={"x_m": x, "v_m_s": v, "F_tendon_N": T, "tau_Nm": arm * T, "taut": if_else(taut, 1.0, 0.0),
                     "direction": P["side"] * s.u["joint_direction"],
                     "load_mass_kg": equivalent_mass_kg(s.u["F_static_N"], P["g_m_s2"])},
            port={"flange": {"x_m": x, "v_m_s": v},
                  "shaft": {"tau_Nm": arm * T, "tau_level_Nm": if_else(taut, P["radius_m"] * s.u["friction_level_N"], 0.0)}},
            initial={"W_tendon_J": 0.0})
