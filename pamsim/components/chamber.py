"""The muscle's gas chamber: volume from the braid, polytropic pressure law; a pneumatic node."""

from __future__ import annotations

from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, non_negative, positive
from ..modeling.smath import if_else
from .element import ElementParameters

PROBE_POINTS = tuple((x,) for x in (0.0, 0.01, 0.04))


def _volume_m3(element, x_m):
    return element.volume_m3(x_m)


class PolytropicChamber(ElementParameters, Component):
    """:class:`pamsim.elements.chamber.MuscleChamber`: states absolute pressure and air mass.

    ``dp/dt = n (R T_in mdot - p dV/dt) / V``, with the flow work ``R T_in mdot`` summed over every
    flow into the port.  The volume follows the contraction ``x_m`` and its rate ``v_m_s``.

    Settling (:attr:`pamsim.modeling.component.Equations.settle`): where the pressure is within the
    integrator's tolerance of ``p_settle_abs_Pa``, the pressure its source holds the port at, it is set
    to that pressure, and the air mass moves by what that change of pressure takes at the present flow
    (``dm = dp mdot / (dp/dt)``, the volume held).
    """

    ports = (Port("port", PNEUMATIC, "node", optional=True),)
    inputs = (Var("x_m", "m", "contraction"), Var("v_m_s", "m/s", "contraction velocity"),
              Var("p_settle_abs_Pa", "Pa", "pressure the source holds the port at (its own pressure when none)"))
    states = (Var("p_abs_Pa", "Pa", "absolute chamber pressure", 1e5),
              Var("air_mass_kg", "kg", "air mass in the chamber", 1e-5))
    outputs = (Var("p_gauge_Pa", "Pa", "chamber gauge pressure"), Var("p_abs_Pa", "Pa", "absolute chamber pressure"),
               Var("gas_temperature_K", "K", "chamber gas temperature p V / (m R)"),
               Var("volume_m3", "m^3", "chamber volume"))
    extra_parameters = (positive("p_atm_Pa", "Pa", "ambient pressure"),
                        non_negative("initial_pressure_gauge_Pa", "Pa", "chamber gauge pressure at the start"),
                        positive("T_initial_K", "K", "gas temperature at the start"))

    def __init__(self, name: str, element, p_atm_Pa: float, initial_pressure_gauge_Pa: float, T_initial_K: float):
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
        dp = ch.pressure_rate_from_flow_work_Pa_s(p, V, dV, flow["flow_work_W"])
        p0 = s.p["p_atm_Pa"] + s.p["initial_pressure_gauge_Pa"]
        target = s.u["p_settle_abs_Pa"]
        dp_settle = target - p
        rate_held = ch.pressure_rate_from_flow_work_Pa_s(p, V, 0.0, flow["flow_work_W"])
        # Without flow (a valve whose supply differs from the chamber by rounding) the approach has no
        # rate to scale the air mass by: the chamber is left as it is.
        near = ((dp_settle != 0.0) * (rate_held != 0.0)
                * (abs(dp_settle) <= s.tol * (self.states[0].nominal + abs(target))))
        return Equations(
            der={"p_abs_Pa": dp, "air_mass_kg": flow["mdot_kg_s"]},
            outputs={"p_gauge_Pa": p - s.p["p_atm_Pa"], "p_abs_Pa": p, "gas_temperature_K": T_gas, "volume_m3": V},
            port={"port": {"p_abs_Pa": p, "T_K": T_gas}},
            initial={"p_abs_Pa": p0, "air_mass_kg": ch.air_mass_kg(p0, V, s.p["T_initial_K"])},
            settle={"p_abs_Pa": if_else(near, target, p),
                    "air_mass_kg": if_else(near, m + dp_settle * flow["mdot_kg_s"] / rate_held, m)})
