"""The hanging load: a mass on the muscle's flange, with its own stick/slip and end-stop modes.

The mode machine is written here: the equations of each mode, the event indicators that end it, the
jump at an event and the decision of a load at rest (docs/model.md sec. 4), which the python backend
and the native backend's C engine integrate.  Until the FMU moves onto the code generated from it,
the hand-written C core keeps its own copy, and the results' force columns come from
:meth:`pamsim.model.MuscleModel.breakdown`; the conformance suite and the tests hold them to this one.  The Coulomb level comes in as a signal; this component decides
its direction (against the motion when sliding, whatever holds the load when it is held).
"""

from __future__ import annotations

from enum import IntEnum

from ..core_table import EVENT_V_TOL_M_S, EVENT_X_TOL_M
from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, non_negative, positive
from ..modeling.smath import if_else


class LoadMode(IntEnum):
    """Friction / contact mode of the load."""

    SLIP_DOWN = -1
    STICK = 0
    SLIP_UP = 1
    STOP_LOW = 2
    STOP_HIGH = 3

    @property
    def is_slip(self) -> bool:
        """Whether the load slides in this mode (up or down)."""
        return self in (LoadMode.SLIP_UP, LoadMode.SLIP_DOWN)

    @property
    def label(self) -> str:
        """The mode's name in results and events (``slip_up``, ``stick``...)."""
        return self.name.lower()


EVENT_NAMES = {
    LoadMode.SLIP_UP: ("velocity_zero", "stop_high"),
    LoadMode.SLIP_DOWN: ("velocity_zero", "stop_low"),
    LoadMode.STICK: ("release_up", "release_down"),
    LoadMode.STOP_LOW: ("release_up", None),
    LoadMode.STOP_HIGH: (None, "release_down"),
}
"""What a crossing of each indicator means in each mode (None: that indicator never crosses there)."""


def event_name(mode: LoadMode, fired: int, to: LoadMode) -> str:
    """The name of an event that left ``mode`` for ``to`` with the indicators in the bit mask ``fired``:
    a stop reached takes precedence over a velocity reaching zero (as in the transition), and a
    release is named by the direction the load takes."""
    if mode.is_slip:
        return EVENT_NAMES[mode][1] if fired & 2 else EVENT_NAMES[mode][0]
    return "release_up" if to == LoadMode.SLIP_UP else "release_down"


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
        q, x, v = s.mode, s.x["x_m"], s.x["v_m_s"]
        M = LoadMode
        slip = q * q == 1
        up = q == M.SLIP_UP
        low, high = q == M.STOP_LOW, q == M.STOP_HIGH
        v_flange = if_else(slip, v, 0.0)
        weight = P["mass_kg"] * P["g_m_s2"]
        # The flange's forces include friction's -q F_c while sliding; at rest they hold neither
        # friction nor damping (its velocity is zero), so they add up to the static force.
        F, level = s.port["flange"]["F_N"], s.u["friction_level_N"]
        net = F - weight + s.u["F_external_N"]
        accel = if_else(slip, net / P["mass_kg"], 0.0)

        eps = P["release_margin_N"]
        z_slip = (if_else(up, v, -v), if_else(up, P["x_high_m"] - x, x - P["x_low_m"]))
        z_held = (if_else(high, 1.0, level + eps - net), if_else(low, 1.0, level + eps + net))
        indicators = tuple(if_else(slip, a, b) for a, b in zip(z_slip, z_held))
        margins = (if_else(slip, EVENT_V_TOL_M_S, 0.0), if_else(slip, EVENT_X_TOL_M, 0.0))

        margin = P["stick_margin_N"]
        rest = if_else(slip, q, if_else((1 - high) * (net - level > margin), float(M.SLIP_UP),
                                        if_else((1 - low) * (-net - level > margin), float(M.SLIP_DOWN), q)))
        at_stop = slip * s.fired[1]
        stopped = slip * (1 - at_stop) * s.fired[0]
        rebound = P["restitution"] * abs(v)
        bounces = rebound > P["min_rebound_speed_m_s"]
        transition = {
            "x_m": if_else(at_stop, if_else(up, P["x_high_m"], P["x_low_m"]), x),
            "v_m_s": if_else(at_stop, if_else(bounces, if_else(up, -rebound, rebound), 0.0),
                             if_else(stopped, 0.0, v)),
            "mode": if_else(at_stop, if_else(bounces, -q, if_else(up, float(M.STOP_HIGH), float(M.STOP_LOW))),
                            if_else(stopped, float(M.STICK), q)),
        }
        held_by_friction = (q == M.STICK) + low * (net > 0.0) + high * (net < 0.0)
        on_stop = low * (net <= 0.0) + high * (net >= 0.0)
        x0 = P["initial_contraction_m"]
        return Equations(
            der={"x_m": v_flange, "v_m_s": accel},
            outputs={"x_m": x, "v_m_s": v_flange, "mass_kg": P["mass_kg"], "F_gravity_N": -weight,
                     "F_friction_N": if_else(slip, -q * level, if_else(held_by_friction, -net, 0.0)),
                     "F_stop_N": if_else(on_stop, -net, 0.0), "F_coulomb_level_N": level,
                     "kinetic_energy_J": 0.5 * P["mass_kg"] * v * v, "F_net_N": net,
                     "slip_direction": if_else(slip, q, 0.0)},
            port={"flange": {"x_m": x, "v_m_s": v_flange}},
            indicators=indicators, indicator_margins=margins, transition=transition, rest_mode=rest,
            initial={"x_m": x0, "v_m_s": 0.0,
                     "mode": if_else(x0 <= P["x_low_m"], float(M.STOP_LOW),
                                     if_else(x0 >= P["x_high_m"], float(M.STOP_HIGH), float(M.STICK)))})
