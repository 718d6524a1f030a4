"""A linear slider: a carriage on a straight guide, inclined to the horizontal, driven by the forces of
the muscles whose tendons pull it, with the same exact stick/slip and end-stop modes as the hanging load
and the rotary joint (:mod:`pamsim.components.stick_slip`).

The paper's rig is one case of it: a vertical guide (``incline_rad`` = pi/2) with one muscle pulling
the carriage up, its contraction the carriage's position, and no guide friction of its own.
"""

from __future__ import annotations

from ..core_table import EVENT_V_TOL_M_S, EVENT_X_TOL_M
from ..modeling import LINEAR, Port, Var, non_negative, positive
from ..modeling.smath import sin
from .guided_body import BodyNames, GuidedBody
from .stick_slip import BodyMode


class LinearSlider(GuidedBody):
    """A carriage of mass ``m`` on a guide inclined at ``incline_rad`` above the horizontal, ``x`` along
    the guide (up the slope for a positive incline), between two stops.

    Sliding: ``m dv/dt = F - m g sin(incline) - b v - q F_c + F_ext``, with ``F`` the forces of the
    branches on the carriage (the muscles' friction ``-q F_c,i`` among them while sliding, ``q`` = +1 or
    -1), ``b`` and ``F_c`` the guide's viscous and Coulomb friction.  Held (stuck, or on a stop): the
    position is constant and the carriage reports zero velocity.  The Coulomb level that decides sticking
    and release is the guide's plus the branches' levels.

    States ``E_viscous_J``, ``E_coulomb_J`` and ``W_external_J``: the energy the guide dissipates, viscous
    and Coulomb, and the work of the external force.
    """

    modes = BodyMode
    parameters = (positive("mass_kg", "kg", "mass of the carriage and what it carries"),
                  positive("g_m_s2", "m/s^2", "gravitational acceleration"),
                  Var("incline_rad", "rad", "angle of the guide above the horizontal (pi/2: x straight up)"),
                  non_negative("b_N_s_per_m", "N s/m", "viscous friction of the guide"),
                  non_negative("F_coulomb_N", "N", "Coulomb friction level of the guide"),
                  Var("x_min_m", "m", "lower stop"), Var("x_max_m", "m", "upper stop"),
                  Var("restitution", "1", "coefficient of restitution at the stops", lower=0.0, upper=1.0),
                  non_negative("min_rebound_speed_m_s", "m/s",
                               "a slower rebound off a stop is none: the carriage stays on it"),
                  non_negative("stick_margin_N", "N",
                               "a stopping carriage is held unless the net force beats friction by more"),
                  positive("release_margin_N", "N", "a held carriage is released when the net force beats friction by this"),
                  Var("initial_position_m", "m", "position at the start, at rest"))
    ports = (Port("carriage", LINEAR, "node", optional=True),)
    inputs = (Var("F_external_N", "N", "external force on the carriage along x"),)
    states = (Var("x_m", "m", "position along the guide", 1e-2), Var("v_m_s", "m/s", "velocity along the guide", 1e-1),
              Var("E_viscous_J", "J", "energy dissipated by the guide's viscous friction", 0.1),
              Var("E_coulomb_J", "J", "energy dissipated by the guide's Coulomb friction", 0.1),
              Var("W_external_J", "J", "work of the external force", 0.1))
    outputs = (Var("x_m", "m", "position along the guide"),
               Var("v_m_s", "m/s", "velocity (zero when held)"),
               Var("mass_kg", "kg", "mass of the carriage (the load a muscle's friction may read)"),
               Var("F_gravity_N", "N", "weight along x"),
               Var("F_muscles_N", "N", "force of the branches on the carriage (the muscles)"),
               Var("F_applied_N", "N", "the external force, as applied to the carriage"),
               Var("F_friction_N", "N", "the guide's Coulomb friction; when held, whatever holds the carriage"),
               Var("F_stop_N", "N", "reaction of a stop"),
               Var("F_coulomb_level_N", "N", "Coulomb level: the guide's and the branches'"),
               Var("kinetic_energy_J", "J", "kinetic energy of the carriage"),
               Var("potential_energy_J", "J", "gravitational energy of the carriage above x = 0"),
               Var("F_net_N", "N", "sum of the forces on the carriage; held, of those other than friction and the stops"),
               Var("slip_direction", "1", "+1 or -1 while x grows or falls, 0 while held"))

    names = BodyNames("carriage", "x_m", "v_m_s", "mass_kg", "b_N_s_per_m", "F_coulomb_N", "x_min_m", "x_max_m",
                      "min_rebound_speed_m_s", "stick_margin_N", "release_margin_N", "initial_position_m", "F", "N")
    event_tolerances = (EVENT_V_TOL_M_S, EVENT_X_TOL_M)

    def gravity(self, P, x):
        weight = P["mass_kg"] * P["g_m_s2"] * sin(P["incline_rad"])
        return -weight, weight * x

    def extra_outputs(self, P) -> dict:
        return {"mass_kg": P["mass_kg"]}
