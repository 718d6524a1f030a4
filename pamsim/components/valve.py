"""The proportional 3/3 valve between a supply, the exhaust and a pneumatic port."""

from __future__ import annotations

from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else
from .element import ElementParameters


PROBE_POINTS = tuple((u, p, 293.15, 5e5, 293.15, 1.01325e5) for u in (-1.0, -0.3, 0.0, 0.4, 1.0)
                     for p in (0.5e5, 1.5e5, 4.99e5, 6e5))


def _inflow_kg_s(element, u, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa):
    return element.inflow_kg_s(u, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa)


class ProportionalValve(ElementParameters, Component):
    """:class:`pamsim.elements.valve.ProportionalValve33` on an ISO 6358 orifice: a pneumatic branch.

    Inputs: the command in [-1, 1] (1 open to supply, -1 open to exhaust) and the supply gauge
    pressure.  Inflow carries the supply temperature, outflow the volume's gas temperature.  Output
    ``p_settle_abs_Pa``: the port pressure at which the flow stops, the supply's or the exhaust's
    (the port's own while the valve is closed), for a chamber that settles
    (:class:`pamsim.components.Chamber`).
    """

    ports = (Port("port", PNEUMATIC, "branch"),)
    inputs = (Var("command", "1", "valve command in [-1, 1]"),
              Var("supply_gauge_Pa", "Pa", "supply gauge pressure"))
    outputs = (Var("mass_flow_kg_s", "kg/s", "mass flow into the port"),
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
        u, p_supply = s.u["command"], s.u["supply_gauge_Pa"] + p_atm
        mdot = valve.inflow_kg_s(u, p, T, p_supply, T_supply, p_atm)
        T_in = if_else(mdot >= 0.0, T_supply, T)
        return Equations(outputs={"mass_flow_kg_s": mdot,
                                  "p_settle_abs_Pa": if_else(u > 0.0, p_supply, if_else(u < 0.0, p_atm, p))},
                         port={"port": {"mdot_kg_s": mdot, "flow_work_W": s.p["R_J_per_kg_K"] * T_in * mdot}})
