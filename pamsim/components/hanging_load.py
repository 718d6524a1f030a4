"""The hanging load: a mass on the muscle's flange, with its own stick/slip and end-stop modes.

Its modes are those of any body with one degree of freedom (:mod:`pamsim.components.stick_slip`,
docs/model.md sec. 4), which the python backend, the native backend's C engine and the FMU integrate
from the code generated here.  The Coulomb level comes in as a signal; the modes decide its direction
(against the motion when sliding, whatever holds the load when it is held).
"""

from __future__ import annotations

from ..core_table import EVENT_V_TOL_M_S, EVENT_X_TOL_M
from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, non_negative, positive
from .stick_slip import EVENT_NAMES, BodyMode, Contact, event_name, stick_slip

__all__ = ["EVENT_NAMES", "HangingLoad", "LoadMode", "event_name"]


LoadMode = BodyMode
"""Friction / contact mode of the load (:class:`pamsim.components.stick_slip.BodyMode`)."""


class HangingLoad(Component):
    """A mass under gravity between two rigid stops, driven by the forces on its flange.

    Sliding (``SLIP_UP``/``SLIP_DOWN``): ``m a = F - m g + F_ext`` with ``F`` the sum of the forces
    on the flange, friction's ``-q F_c`` among them (``q`` = +1 or -1, output ``slip_direction``).  Held (``STICK`` or on a stop): x and v are constant and the
    flange reports zero velocity, so every velocity-dependent branch sees the load at rest.

    Event indicators, positive inside the mode (a crossing to zero ends it): sliding, the velocity
    and the distance to the stop ahead (with margins ``EVENT_V_TOL_M_S`` and ``EVENT_X_TOL_M`` for an
    integrator that needs a release from rest not to be an event); held, the margins
    ``F_c + release_margin -+ net`` by which friction still holds the load up and down.  At an event: a stop reached takes the load
    to it, with a rebound of ``restitution |v|`` if that exceeds ``min_rebound_speed_m_s``, else at
    rest on it (the stop takes precedence when both indicators cross at once); a velocity reaching zero
    stops the load; then :attr:`Equations.rest_mode` decides a
    held load's mode from its forces (slip if the net force beats friction by ``stick_margin_N``).
    """

    modes = LoadMode
    n_indicators = 2
    parameters = (positive("mass_kg", "kg", "hanging mass, holder included"),
                  positive("g_m_s2", "m/s^2", "gravitational acceleration"),
                  non_negative("x_low_m", "m", "lower stop"), positive("x_high_m", "m", "upper stop"),
                  Var("restitution", "1", "coefficient of restitution at the stops", lower=0.0, upper=1.0),
                  non_negative("min_rebound_speed_m_s", "m/s",
                               "a slower rebound off a stop is none: the load stays on it"),
                  non_negative("stick_margin_N", "N",
                               "a stopping load is held unless the net force beats friction by more"),
                  positive("release_margin_N", "N", "a held load is released when the net force beats friction by this"),
                  non_negative("initial_contraction_m", "m", "contraction at the start, load at rest"))
    ports = (Port("flange", TRANSLATIONAL, "node"),)
    inputs = (Var("friction_level_N", "N", "Coulomb friction level"),
              Var("F_external_N", "N", "external force on the load along x"))
    states = (Var("x_m", "m", "contraction x = L0 - L", 1e-2), Var("v_m_s", "m/s", "contraction velocity", 1e-1))
    outputs = (Var("x_m", "m", "contraction"), Var("v_m_s", "m/s", "contraction velocity (zero when held)"),
               Var("mass_kg", "kg", "hanging mass"), Var("F_gravity_N", "N", "weight along x"),
               Var("F_friction_N", "N", "friction on the load along x; when held, whatever holds it"),
               Var("F_stop_N", "N", "reaction of a stop along x"),
               Var("F_coulomb_level_N", "N", "Coulomb friction level"),
               Var("kinetic_energy_J", "J", "kinetic energy of the load"),
               Var("F_net_N", "N", "sum of the forces on the load; held, of those other than friction and the stops"),
               Var("slip_direction", "1", "+1 or -1 while sliding up or down, 0 while held"))

    def equations(self, s: Symbols) -> Equations:
        P = s.p
        x, v = s.x["x_m"], s.x["v_m_s"]
        weight = P["mass_kg"] * P["g_m_s2"]
        # The flange's forces include friction's -q F_c while sliding; at rest they hold neither
        # friction nor damping (its velocity is zero), so they add up to the static force.
        F, level = s.port["flange"]["F_N"], s.u["friction_level_N"]
        net = F - weight + s.u["F_external_N"]
        contact = Contact(P["x_low_m"], P["x_high_m"], P["restitution"], P["min_rebound_speed_m_s"],
                          P["stick_margin_N"], P["release_margin_N"], EVENT_V_TOL_M_S, EVENT_X_TOL_M)
        x0 = P["initial_contraction_m"]
        b = stick_slip(s.mode, x, v, net, level, P["mass_kg"], contact, s.fired, x0)
        return Equations(
            der={"x_m": b.v_reported, "v_m_s": b.accel},
            outputs={"x_m": x, "v_m_s": b.v_reported, "mass_kg": P["mass_kg"], "F_gravity_N": -weight,
                     "F_friction_N": b.friction, "F_stop_N": b.stop_reaction, "F_coulomb_level_N": level,
                     "kinetic_energy_J": 0.5 * P["mass_kg"] * v * v, "F_net_N": net,
                     "slip_direction": b.slip_direction},
            port={"flange": {"x_m": x, "v_m_s": b.v_reported}},
            indicators=b.indicators, indicator_margins=b.margins,
            transition={"x_m": b.jump_pos, "v_m_s": b.jump_vel, "mode": b.jump_mode}, rest_mode=b.rest_mode,
            initial={"x_m": x0, "v_m_s": 0.0, "mode": b.initial_mode})
