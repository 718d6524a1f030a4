"""A rotary joint: a link turning about one axis, driven by the torques on its shaft, with the same exact
stick/slip and end-stop modes as the hanging load (:mod:`pamsim.components.stick_slip`).

Muscles act on it through pulleys (:class:`pamsim.components.pulley.Pulley`), each a branch on the
shaft that brings a torque and the level of its muscle's Coulomb friction; the joint adds its own
bearing friction (viscous and Coulomb), the link's gravity torque and an external torque.
"""

from __future__ import annotations

from ..modeling import ROTATIONAL, Port, Var, non_negative, positive
from ..modeling.smath import cos, sin
from .guided_body import BodyNames, GuidedBody
from .stick_slip import BodyMode

EVENT_OMEGA_TOL_RAD_S = 1e-9
"""Event indicators on the angular velocity are shifted by this in the engine, so omega = 0 right after a
release is no event [rad/s] (assumed, as the hanging load's 1e-9 m/s: far below any speed resolved)."""
EVENT_THETA_TOL_RAD = 1e-9
"""Event indicators on the distance to a joint limit are shifted by this [rad] (assumed, likewise)."""

JointMode = BodyMode
"""Friction / contact mode of the joint (``SLIP_UP``: the angle grows; ``STOP_LOW``/``STOP_HIGH``: on
the lower or upper limit)."""


class RotaryJoint(GuidedBody):
    """A link of moment of inertia ``J`` about the joint, between two angle limits.

    Sliding: ``J domega/dt = tau - m g l sin(theta - theta_down) - b omega - q tau_c + tau_ext``, with
    ``tau`` the torques of the branches on the shaft (muscles' friction ``-q r F_c`` among them while
    sliding, ``q`` = +1 or -1), ``m g l`` the link's gravity torque (zero and stable at ``theta_down``),
    ``b`` and ``tau_c`` the bearing's viscous and Coulomb friction.  Held (stuck, or on a limit): the
    angle is constant and the shaft reports zero angular velocity.  The Coulomb level that decides
    sticking and release is ``tau_c`` plus the branches' levels.

    States ``E_viscous_J``, ``E_coulomb_J`` and ``W_external_J``: the energy the bearing dissipates,
    viscous and Coulomb, and the work of the external torque.
    """

    modes = JointMode
    parameters = (positive("inertia_kg_m2", "kg m^2", "moment of inertia of the link about the joint"),
                  non_negative("link_mass_kg", "kg", "mass of the link (its gravity torque)"),
                  non_negative("com_distance_m", "m", "distance from the joint to the link's centre of mass"),
                  positive("g_m_s2", "m/s^2", "gravitational acceleration"),
                  Var("theta_down_rad", "rad", "angle at which the link hangs straight down"),
                  non_negative("b_Nm_s_per_rad", "N m s/rad", "viscous friction of the bearing"),
                  non_negative("tau_coulomb_Nm", "N m", "Coulomb friction level of the bearing"),
                  Var("theta_min_rad", "rad", "lower joint limit"), Var("theta_max_rad", "rad", "upper joint limit"),
                  Var("restitution", "1", "coefficient of restitution at the limits", lower=0.0, upper=1.0),
                  non_negative("min_rebound_speed_rad_s", "rad/s",
                               "a slower rebound off a limit is none: the link stays on it"),
                  non_negative("stick_margin_Nm", "N m",
                               "a stopping link is held unless the net torque beats friction by more"),
                  positive("release_margin_Nm", "N m", "a held link is released when the net torque beats friction by this"),
                  Var("initial_angle_rad", "rad", "angle at the start, at rest"))
    ports = (Port("shaft", ROTATIONAL, "node", optional=True),)
    inputs = (Var("tau_external_Nm", "N m", "external torque on the link"),)
    states = (Var("theta_rad", "rad", "joint angle", 0.1), Var("omega_rad_s", "rad/s", "angular velocity", 1.0),
              Var("E_viscous_J", "J", "energy dissipated by the bearing's viscous friction", 0.1),
              Var("E_coulomb_J", "J", "energy dissipated by the bearing's Coulomb friction", 0.1),
              Var("W_external_J", "J", "work of the external torque", 0.1))
    outputs = (Var("theta_rad", "rad", "joint angle"),
               Var("omega_rad_s", "rad/s", "angular velocity (zero when held)"),
               Var("tau_gravity_Nm", "N m", "gravity torque of the link"),
               Var("tau_muscles_Nm", "N m", "torque of the branches on the shaft (the muscles)"),
               Var("tau_applied_Nm", "N m", "the external torque, as applied to the link"),
               Var("tau_friction_Nm", "N m", "the bearing's Coulomb friction; when held, whatever holds the link"),
               Var("tau_stop_Nm", "N m", "reaction of a joint limit"),
               Var("tau_coulomb_level_Nm", "N m", "Coulomb level: the bearing's and the branches'"),
               Var("kinetic_energy_J", "J", "kinetic energy of the link"),
               Var("potential_energy_J", "J", "gravitational energy of the link above its lowest position"),
               Var("tau_net_Nm", "N m", "sum of the torques on the link; held, of those other than friction and the limits"),
               Var("slip_direction", "1", "+1 or -1 while the angle grows or falls, 0 while held"))

    names = BodyNames("shaft", "theta_rad", "omega_rad_s", "inertia_kg_m2", "b_Nm_s_per_rad", "tau_coulomb_Nm",
                      "theta_min_rad", "theta_max_rad", "min_rebound_speed_rad_s", "stick_margin_Nm",
                      "release_margin_Nm", "initial_angle_rad", "tau", "Nm")
    event_tolerances = (EVENT_OMEGA_TOL_RAD_S, EVENT_THETA_TOL_RAD)

    def gravity(self, P, theta):
        mgl = P["link_mass_kg"] * P["g_m_s2"] * P["com_distance_m"]
        return -mgl * sin(theta - P["theta_down_rad"]), mgl * (1.0 - cos(theta - P["theta_down_rad"]))
