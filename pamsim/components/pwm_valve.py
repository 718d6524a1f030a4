"""The averaged model of an on/off valve under PWM: its duty in, the mean of its two paths' flows out."""

from __future__ import annotations

from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else
from .element import ElementParameters

PROBE_POINTS = tuple((d, p, 293.15, 5e5, 293.15, 1.01325e5) for d in (0.0, 0.03, 0.4, 0.97, 1.0)
                     for p in (0.5e5, 1.5e5, 4.99e5, 6e5))


def _inflow_kg_s(element, duty, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa):
    return element.inflow_kg_s(duty, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa)


class AveragedPwmValve(ElementParameters, Component):
    """:class:`pamsim.elements.pwm_average.PwmAveragedValve`: an on/off valve under PWM as the mean of
    its supply and exhaust paths' flows over a period; a pneumatic branch.

    Inputs: the duty in [0, 1] and the supply gauge pressure.  Each path's flow carries the temperature
    of where it comes from (the supply's, or the volume's gas for an outflow), so the flow work is the
    mean of the switching valve's too.  Output ``p_settle_abs_Pa``: the supply's pressure while only
    the supply path is ever open, the exhaust's while only the exhaust path is, else the port's own (a
    chamber fed by both settles where their flows balance, which no closed form gives).
    """

    ports = (Port("port", PNEUMATIC, "branch"),)
    inputs = (Var("duty", "1", "PWM duty cycle in [0, 1]"),
              Var("supply_gauge_Pa", "Pa", "supply gauge pressure"))
    outputs = (Var("mass_flow_kg_s", "kg/s", "mean mass flow into the port over a PWM period"),
               Var("p_settle_abs_Pa", "Pa", "port pressure at which the flow stops"))
    extra_parameters = (positive("T_supply_K", "K", "supply air temperature"),
                        positive("p_atm_Pa", "Pa", "ambient (exhaust) pressure"),
                        positive("R_J_per_kg_K", "J/(kg K)", "specific gas constant of air"))

    def __init__(self, name: str, element, T_supply_K: float, p_atm_Pa: float, R_J_per_kg_K: float):
        values = self.wrap(element, _inflow_kg_s, PROBE_POINTS, required="valve")
        values.update(T_supply_K=T_supply_K, p_atm_Pa=p_atm_Pa, R_J_per_kg_K=R_J_per_kg_K)
        super().__init__(name, values)

    def equations(self, s: Symbols) -> Equations:
        valve = self.symbolic_element(s.p)
        p, T = s.port["port"]["p_abs_Pa"], s.port["port"]["T_K"]
        T_supply, p_atm = s.p["T_supply_K"], s.p["p_atm_Pa"]
        duty, p_supply = s.u["duty"], s.u["supply_gauge_Pa"] + p_atm
        supply, exhaust = valve.path_flows_kg_s(duty, p, T, p_supply, T_supply, p_atm)
        work = sum(if_else(mdot >= 0.0, T_supply, T) * mdot for mdot in (supply, exhaust))
        w_supply, w_exhaust = valve.shares(duty)
        settle = if_else((w_supply > 0.0) * (w_exhaust == 0.0), p_supply,
                         if_else((w_exhaust > 0.0) * (w_supply == 0.0), p_atm, p))
        return Equations(outputs={"mass_flow_kg_s": supply + exhaust, "p_settle_abs_Pa": settle},
                         port={"port": {"mdot_kg_s": supply + exhaust, "flow_work_W": s.p["R_J_per_kg_K"] * work}})
