"""How a muscle's tendon turns a joint: on a pulley (a constant lever arm), or from an anchor on the base
to a point on the link (a lever arm that changes with the angle).  The muscle's contraction follows
the joint angle, and its pull becomes a torque; a tendon only pulls.

An attachment is the node of its muscle's flange (the static force, damping and friction are branches on
it, as on the hanging load) and a branch on the joint's shaft.  A muscle whose forces add up to a push
(pushed past the contraction at which it pulls nothing) leaves its tendon slack: no force, no torque,
no friction on the joint.  The slack's start and end are kinks in the torque, which the integrators'
step control resolves, not events.
"""

from __future__ import annotations

from ..modeling import LINEAR, ROTATIONAL, TRANSLATIONAL, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import cos, if_else, sin, sqrt
from .friction import equivalent_mass_kg

SIDE = Var("side", "1", "+1: the muscle turns the joint toward larger angles; -1: toward smaller", lower=-1.0, upper=1.0)
G = positive("g_m_s2", "m/s^2", "gravitational acceleration (the load-dependent friction's mass)")


def _outputs(effort: Var, *extra: Var) -> tuple[Var, ...]:
    """An attachment's outputs: the muscle's motion and tendon force, ``effort`` (what the tendon puts on
    the body), then ``extra``."""
    return (Var("x_m", "m", "the muscle's contraction"), Var("v_m_s", "m/s", "the muscle's contraction velocity"),
            Var("F_tendon_N", "N", "tendon force (zero when slack)"), effort,
            Var("taut", "1", "1 while the tendon pulls, 0 while slack"),
            Var("direction", "1", "+1 or -1 while the muscle contracts or extends under the body's slip, 0 held"),
            Var("load_mass_kg", "kg", "mass whose weight is the muscle's static force"), *extra)


class TendonAttachment(Component):
    """A muscle's tendon on a body (a joint's shaft, a slider's carriage), its kinematics given by a
    subclass: the muscle's contraction ``x(q)`` at the body's coordinate ``q`` and its derivative
    ``dx/dq`` (:meth:`kinematics`).  Then ``v = dx/dq dq/dt``, a tendon force ``T = max(F, 0)`` from the
    sum ``F`` of the muscle's forces, ``dx/dq T`` on the body (a pull moves it the way that contracts
    the muscle).  The muscle's Coulomb level reaches the body as ``|dx/dq| F_c`` while the tendon is
    taut, and the body's slip direction reaches the muscle's friction times the sign of ``dx/dq``.  The
    load-dependent friction law reads the load a muscle holds as the mass whose weight equals its static
    force, ``max(F_static, 0) / g``.

    State ``W_tendon_J``: the work the tendon does on the body, integral of ``T v``.
    """

    body = Port("shaft", ROTATIONAL, "branch")
    """The port on the body; its kind's across variables are the coordinate and its rate, its through
    variables the effort and the friction level the tendon brings."""
    ports = (body, Port("flange", TRANSLATIONAL, "node"))
    inputs = (Var("friction_level_N", "N", "Coulomb friction level of the muscle"),
              Var("joint_direction", "1", "+1 or -1 while the body's coordinate grows or falls, 0 while held"),
              Var("F_static_N", "N", "the muscle's static force"))
    states = (Var("W_tendon_J", "J", "work done by the tendon on the body", 0.1),)
    outputs = _outputs(Var("tau_Nm", "N m", "torque on the joint"),
                       Var("moment_arm_m", "m", "the tendon's lever arm about the joint, |dx/dtheta|"))

    def kinematics(self, P, q):
        """The muscle's contraction at the body's coordinate ``q`` and its derivative ``dx/dq``."""
        raise NotImplementedError

    def body_outputs(self, arm, T) -> dict:
        """The outputs past the common ones: the effort on the body, then the lever arm."""
        return {"tau_Nm": arm * T, "moment_arm_m": abs(arm)}

    def equations(self, s: Symbols) -> Equations:
        P, body = s.p, s.port[self.body.name]
        position, rate = (v.name for v in self.body.kind.across)
        effort, level = (v.name for v in self.body.kind.through)
        x, arm = self.kinematics(P, body[position])
        v = arm * body[rate]
        F = s.port["flange"]["F_N"]
        taut = F > 0.0
        T = if_else(taut, F, 0.0)
        return Equations(
            der={"W_tendon_J": T * v},
            outputs={"x_m": x, "v_m_s": v, "F_tendon_N": T, "taut": if_else(taut, 1.0, 0.0),
                     "direction": if_else(arm >= 0.0, 1.0, -1.0) * s.u["joint_direction"],
                     "load_mass_kg": equivalent_mass_kg(s.u["F_static_N"], P["g_m_s2"]), **self.body_outputs(arm, T)},
            port={"flange": {"x_m": x, "v_m_s": v},
                  self.body.name: {effort: arm * T, level: if_else(taut, abs(arm) * s.u["friction_level_N"], 0.0)}},
            initial={"W_tendon_J": 0.0})


class Pulley(TendonAttachment):
    """A tendon on a pulley of radius ``r``: ``x = x_at_zero + side r theta``, a constant lever arm ``r``."""

    parameters = (positive("radius_m", "m", "pulley radius (the tendon's lever arm)"), SIDE,
                  Var("x_at_zero_m", "m", "the muscle's contraction at joint angle zero"), G)

    def kinematics(self, P, theta):
        arm = P["side"] * P["radius_m"]
        return P["x_at_zero_m"] + arm * theta, arm


class LeverAttachment(TendonAttachment):
    """A muscle from an anchor on the base, ``base_attach_m`` from the joint, to a point on the link,
    ``link_attach_m`` from it, the two arms at ``angle_at_zero_rad`` apart at joint angle zero, and at
    ``angle_at_zero_rad - side theta`` at ``theta`` (a muscle of ``side`` +1 pulls the arms together as
    the angle grows).  The path is ``L = sqrt(a^2 + d^2 - 2 a d cos(phi))``, the muscle the path less its
    tendon, ``x = muscle_L0_m - (L - tendon_length_m)``, and the lever arm
    ``|dx/dtheta| = a d sin(phi) / L``: largest with the arms at right angles, zero when they line up.
    """

    parameters = (positive("link_attach_m", "m", "distance from the joint to the muscle's point on the link"),
                  positive("base_attach_m", "m", "distance from the joint to the muscle's anchor on the base"),
                  Var("angle_at_zero_rad", "rad", "angle between the two arms at joint angle zero", lower=0.0,
                      upper=3.141592653589793), SIDE,
                  positive("muscle_L0_m", "m", "the muscle's rest length"),
                  Var("tendon_length_m", "m", "the tendon between the muscle and the link", lower=0.0), G)

    def kinematics(self, P, theta):
        a, d = P["link_attach_m"], P["base_attach_m"]
        phi = P["angle_at_zero_rad"] - P["side"] * theta
        L = sqrt(a * a + d * d - 2.0 * a * d * cos(phi))
        # dx/dtheta = -dL/dtheta = -(a d sin(phi) / L) dphi/dtheta, dphi/dtheta = -side
        return P["muscle_L0_m"] - (L - P["tendon_length_m"]), P["side"] * a * d * sin(phi) / L


class SliderTendon(TendonAttachment):
    """A tendon from a muscle to a slider's carriage along the guide: ``x = x_at_zero + side y`` at carriage
    position ``y``, the force ``side T`` on the carriage (a muscle of ``side`` +1 pulls toward larger y)."""

    body = Port("carriage", LINEAR, "branch")
    ports = (body, Port("flange", TRANSLATIONAL, "node"))
    parameters = (SIDE, Var("x_at_zero_m", "m", "the muscle's contraction at carriage position zero"), G)
    outputs = _outputs(Var("F_N", "N", "force of the tendon on the carriage along its guide"))

    def kinematics(self, P, y):
        return P["x_at_zero_m"] + P["side"] * y, P["side"]

    def body_outputs(self, arm, T) -> dict:
        return {"F_N": arm * T}
