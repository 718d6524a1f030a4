"""A reservoir: a rigid volume of gas, a pneumatic node, whose gas follows one of the muscle chamber's laws.

Its law and parameters are the scenario's (``[[component]] type = "reservoir"``): a reservoir is something a
user adds to a rig, so its volume comes from its data sheet.  The defaults of the law's parameters are the
muscle chamber's (:mod:`pamsim.components.gas_volume`).
"""

from __future__ import annotations

from ..elements.chamber import VESSEL_LAWS
from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, positive
from . import gas_volume
from .element import ElementParameters

VOLUME_OUTPUTS = (Var("p_gauge_Pa", "Pa", "gauge pressure"), Var("p_abs_Pa", "Pa", "absolute pressure"),
                  Var("gas_temperature_K", "K", "gas temperature p V / (m R) (the wall's, isothermal)"))
"""The outputs of every rigid volume."""

VOLUME_STATES = (Var("p_abs_Pa", "Pa", "absolute pressure", 1e5),
                 Var("air_mass_kg", "kg", "air mass", 1e-5, conserved=True))
"""The states of every rigid volume: the chamber's."""


def _probe(element, p, m, mdot, flow_work):
    return gas_volume.pressure_rate(element, p, m, mdot, flow_work)


class Reservoir(ElementParameters, Component):
    """A rigid volume ``volume_m3`` (a reservoir, a manifold) under the law ``law``
    (:data:`pamsim.components.gas_volume.LAWS`; the thermal law's heat goes through ``wall_area_m2``).

    States absolute pressure and air mass; ``dm/dt`` is the summed inflow of the branches connected to its
    port, ``dp/dt`` the law's with the volume held.  Its port carries its pressure and gas temperature
    (what an outflow takes with it).
    """

    ports = (Port("port", PNEUMATIC, "node", optional=True),)
    states = VOLUME_STATES
    outputs = VOLUME_OUTPUTS
    choices = {"law": gas_volume.LAWS}
    defaults = gas_volume.DEFAULTS

    def __init__(self, name: str, values, law: str = gas_volume.LAWS[0]):
        self.law = gas_volume.checked_law(law)
        values = {**gas_volume.DEFAULTS, **values}
        self.extra_parameters = gas_volume.COMMON_PARAMETERS
        fields = dict(values, vessel_volume_m3=values["volume_m3"], vessel_area_m2=values.get("wall_area_m2"))
        element = VESSEL_LAWS[law](**{f: float(fields[f]) for f in VESSEL_LAWS[law].__dataclass_fields__})
        own = self.wrap(element, _probe, gas_volume.PROBE, required="reservoir")
        own.update({v.name: float(values[v.name]) for v in gas_volume.COMMON_PARAMETERS})
        super().__init__(name, own)

    @classmethod
    def scenario_parameters(cls, options) -> tuple[Var, ...]:
        """The keys a ``[[component]]`` table of this type takes, for its ``options`` (its law)."""
        law = options.get("law", gas_volume.LAWS[0])
        area = (positive("wall_area_m2", "m^2", "inner surface of the wall"),) if law == "thermal" else ()
        return (positive("volume_m3", "m^3", "the reservoir's volume"), *area) + gas_volume.law_parameters(law)

    def held_state(self, p_abs_Pa: float) -> dict[str, float]:
        """Its states at rest at the absolute pressure ``p_abs_Pa`` (an operating point of a line)."""
        return gas_volume.held_state(self, p_abs_Pa)

    def equations(self, s: Symbols) -> Equations:
        gas = self.symbolic_element(s.p)
        p, m = s.x["p_abs_Pa"], s.x["air_mass_kg"]
        flow = s.port["port"]
        p0, m0 = gas_volume.start(gas, s)
        T = gas.gas_temperature_K(p, gas.volume_m3(0.0), m)
        return Equations(
            der={"p_abs_Pa": gas_volume.pressure_rate(gas, p, m, flow["mdot_kg_s"], flow["flow_work_W"]),
                 "air_mass_kg": flow["mdot_kg_s"]},
            outputs={"p_gauge_Pa": p - s.p["p_atm_Pa"], "p_abs_Pa": p, "gas_temperature_K": T},
            port={"port": {"p_abs_Pa": p, "T_K": T}},
            initial={"p_abs_Pa": p0, "air_mass_kg": m0})
