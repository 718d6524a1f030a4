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

    probe = staticmethod(_inflow_kg_s)
    """How the element is called on floats and on symbols to check that it takes symbols."""

    def __init__(self, name: str, element, T_supply_K: float, p_atm_Pa: float, R_J_per_kg_K: float):
        values = self.wrap(element, self.probe, PROBE_POINTS, required="valve")
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


class SuppliedValve(ProportionalValve):
    """:class:`ProportionalValve` whose supply side is a pneumatic port (a branch on a supply's, a
    reservoir's or a tube's node) instead of an input: what it lets into its ``port`` it takes from its
    ``supply`` port, at that node's pressure and temperature.

    The exhaust path (``command < 0``) vents to the ambient and draws nothing from the supply.  Output
    ``p_settle_abs_Pa`` is the port's own pressure: the volume it feeds is not settled onto the supply's
    pressure, which moves (a reservoir empties, a regulator lags), and settling it would make air.
    """

    ports = (Port("port", PNEUMATIC, "branch"), Port("supply", PNEUMATIC, "branch"))
    inputs = (Var("command", "1", "valve command in [-1, 1]"),)

    def equations(self, s: Symbols) -> Equations:
        """The valve's flow into ``port``, drawn from ``supply`` while it is open to it."""
        valve = self.symbolic_element(s.p)
        p, T = s.port["port"]["p_abs_Pa"], s.port["port"]["T_K"]
        p_up, T_up = s.port["supply"]["p_abs_Pa"], s.port["supply"]["T_K"]
        u, p_atm = s.u["command"], s.p["p_atm_Pa"]
        # The exhaust's air, drawn in below ambient, is at the supply's temperature parameter, as for the
        # valve with a supply input.
        T_source = if_else(u >= 0.0, T_up, s.p["T_supply_K"])
        mdot = valve.inflow_kg_s(u, p, T, p_up, T_source, p_atm)
        work = s.p["R_J_per_kg_K"] * if_else(mdot >= 0.0, T_source, T) * mdot
        drawn = if_else(u >= 0.0, 1.0, 0.0)
        return Equations(outputs={"mass_flow_kg_s": mdot, "p_settle_abs_Pa": p},
                         port={"port": {"mdot_kg_s": mdot, "flow_work_W": work},
                               "supply": {"mdot_kg_s": -drawn * mdot, "flow_work_W": -drawn * work}})
