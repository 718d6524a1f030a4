"""The muscle's gas chamber: volume from the braid, and the law its gas follows (isothermal, polytropic or
thermal, :mod:`pamsim.elements.chamber`); a pneumatic node."""

from __future__ import annotations

from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, non_negative, positive
from ..modeling.smath import if_else
from .element import ElementParameters

PROBE_POINTS = tuple((x,) for x in (0.0, 0.01, 0.04))

OUTPUTS = (Var("p_gauge_Pa", "Pa", "chamber gauge pressure"), Var("p_abs_Pa", "Pa", "absolute chamber pressure"),
           Var("gas_temperature_K", "K", "chamber gas temperature p V / (m R) (the wall's, isothermal)"),
           Var("volume_m3", "m^3", "chamber volume"))
THERMAL_OUTPUTS = (Var("wall_heat_W", "W", "heat the wall gives the gas, h A(x) (T_wall - T)"),
                   Var("wall_area_m2", "m^2", "inner surface of the muscle's cylinder"))
"""The thermal law's outputs besides :data:`OUTPUTS`."""


def _volume_m3(element, x_m):
    return element.volume_m3(x_m)


class Chamber(ElementParameters, Component):
    """A chamber of :mod:`pamsim.elements.chamber` (:class:`~pamsim.elements.chamber.MuscleChamber`, the
    polytropic law; :class:`~pamsim.elements.chamber.IsothermalChamber`;
    :class:`~pamsim.elements.chamber.ThermalChamber`): states absolute pressure and air mass.

    ``dp/dt`` is the element's law, with the flow work ``R T_in mdot`` and the mass flow summed over every
    flow into the port; ``dm/dt`` is the summed mass flow.  The volume follows the contraction ``x_m``
    and its rate ``v_m_s``.  The gas temperature ``p V / (m R)`` is an output and the port's temperature
    (the temperature an outflow carries); the thermal law adds the wall's heat and area as outputs.

    Settling (:attr:`pamsim.modeling.component.Equations.settle`): where the pressure is within the
    integrator's tolerance of ``p_settle_abs_Pa``, the pressure its source holds the port at, it is set
    to that pressure, and the air mass moves by what that change of pressure takes at the present flow
    (``dm = dp mdot / (dp/dt)``, the volume held).
    """

    ports = (Port("port", PNEUMATIC, "node", optional=True),)
    inputs = (Var("x_m", "m", "contraction"), Var("v_m_s", "m/s", "contraction velocity"),
              Var("p_settle_abs_Pa", "Pa", "pressure the source holds the port at (its own pressure when none)"))
    states = (Var("p_abs_Pa", "Pa", "absolute chamber pressure", 1e5),
              Var("air_mass_kg", "kg", "air mass in the chamber", 1e-5, conserved=True))
    outputs = OUTPUTS
    extra_parameters = (positive("p_atm_Pa", "Pa", "ambient pressure"),
                        non_negative("initial_pressure_gauge_Pa", "Pa", "chamber gauge pressure at the start"),
                        positive("T_initial_K", "K", "gas temperature at the start under the polytropic law (the "
                                 "isothermal and thermal laws start at their wall's)"))

    def __init__(self, name: str, element, p_atm_Pa: float, initial_pressure_gauge_Pa: float, T_initial_K: float):
        if getattr(element, "law", "") == "thermal":
            self.outputs = OUTPUTS + THERMAL_OUTPUTS
        values = self.wrap(element, _volume_m3, PROBE_POINTS, required="chamber")
        values.update(p_atm_Pa=p_atm_Pa, initial_pressure_gauge_Pa=initial_pressure_gauge_Pa, T_initial_K=T_initial_K)
        super().__init__(name, values)

    def equations(self, s: Symbols) -> Equations:
        ch = self.symbolic_element(s.p)
        p, m = s.x["p_abs_Pa"], s.x["air_mass_kg"]
        x, v = s.u["x_m"], s.u["v_m_s"]
        flow = s.port["port"]
        V = ch.volume_m3(x)
        T_gas = ch.gas_temperature_K(p, V, m)
        dV = ch.dvolume_dx_m2(x) * v
        dp = ch.pressure_rate_of_flows_Pa_s(p, V, dV, flow["mdot_kg_s"], flow["flow_work_W"], m, x)
        p0 = s.p["p_atm_Pa"] + s.p["initial_pressure_gauge_Pa"]
        target = s.u["p_settle_abs_Pa"]
        dp_settle = target - p
        rate_held = ch.pressure_rate_of_flows_Pa_s(p, V, 0.0, flow["mdot_kg_s"], flow["flow_work_W"], m, x)
        # Without flow (a valve whose supply differs from the chamber by rounding) the approach has no
        # rate to scale the air mass by: the chamber is left as it is.
        near = ((dp_settle != 0.0) * (rate_held != 0.0)
                * (abs(dp_settle) <= s.tol * (self.states[0].nominal + abs(target))))
        outputs = {"p_gauge_Pa": p - s.p["p_atm_Pa"], "p_abs_Pa": p, "gas_temperature_K": T_gas, "volume_m3": V}
        if len(self.outputs) > len(OUTPUTS):
            outputs.update(wall_heat_W=ch.wall_heat_W(p, V, m, x), wall_area_m2=ch.wall_area_m2(x))
        return Equations(
            der={"p_abs_Pa": dp, "air_mass_kg": flow["mdot_kg_s"]},
            outputs=outputs,
            port={"port": {"p_abs_Pa": p, "T_K": T_gas}},
            # The law says where the gas starts: at the wall (isothermal, thermal: their own T_wall_K, so that an
            # FMU's changed wall temperature moves the start with it) or at T_initial_K (polytropic: the supply's).
            initial={"p_abs_Pa": p0, "air_mass_kg": ch.air_mass_kg(p0, V, ch.start_temperature_K(s.p["T_initial_K"]))},
            settle={"p_abs_Pa": if_else(near, target, p),
                    "air_mass_kg": if_else(near, m + dp_settle * flow["mdot_kg_s"] / rate_held, m)})
