"""A tube: the gas in its bore and the bore's laminar resistance, one lumped cell
(:mod:`pamsim.elements.tube`).

Two cells, chosen by ``inlet``, because a node (a volume) meets only branches (flows) and a branch only a
node:

- ``inlet = "resistance"`` (the default): half the bore's resistance, its volume, the other half
  (a T cell).  Both ends are branches: the tube joins two volumes (a supply and a reservoir, a reservoir
  and the muscle).
- ``inlet = "volume"``: its volume at the inlet, the whole resistance after it.  The inlet is a node: a
  valve (a branch) discharges into the bore, and the bore feeds the volume at its outlet.

Its length, bore and law are the scenario's (``[[component]] type = "tube"``).
"""

from __future__ import annotations

from ..elements.tube import TUBE_LAWS
from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else
from . import gas_volume
from .element import ElementParameters
from .reservoir import VOLUME_OUTPUTS, VOLUME_STATES

INLETS = ("resistance", "volume")
"""The tube's cells by the role of its inlet; the first is the default."""

VISCOSITY_PA_S = 1.81e-5
"""Dynamic viscosity of air at 20 C and 1 atm [Pa s] (F. M. White, Fluid Mechanics, 7th ed., Table A.2);
it hardly depends on the pressure."""

FLOW_OUTPUTS = (Var("inlet_mass_flow_kg_s", "kg/s", "mass flow into the tube at its inlet"),
                Var("outlet_mass_flow_kg_s", "kg/s", "mass flow out of the tube at its outlet"),
                Var("reynolds_number", "1", "Reynolds number of the outlet's flow (laminar below about 2300)"))


def _probe(element, p, m, mdot, flow_work):
    return gas_volume.pressure_rate(element, p, m, mdot, flow_work) + element.mass_flow_kg_s(p, 1.5e5, 300.0, 0.5)


def _segment(bore, p_from, T_from, p_to, T_to, fraction):
    """Mass flow [kg/s] from one side to the other through ``fraction`` of the bore, and the temperature
    it carries (its upstream side's, which the law takes as the gas's)."""
    T_up = if_else(p_from >= p_to, T_from, T_to)
    mdot = bore.mass_flow_kg_s(p_from, p_to, T_up, fraction)
    return mdot, T_up


class Tube(ElementParameters, Component):
    """A tube of ``length_m`` and inner ``diameter_m`` between its ``inlet`` and ``outlet`` ports.

    States the absolute pressure and air mass of the gas in its bore (the law ``law``,
    :data:`pamsim.components.gas_volume.LAWS`); the outlet is a branch into the volume it feeds, the inlet
    a branch from the volume before it (``inlet = "resistance"``, half the resistance at each end) or
    the bore's own volume, a node (``inlet = "volume"``).  Outputs its pressure, its gas temperature,
    the flows at both ends and the outlet's Reynolds number.
    """

    states = VOLUME_STATES
    outputs = VOLUME_OUTPUTS + FLOW_OUTPUTS
    choices = {"law": gas_volume.LAWS, "inlet": INLETS}
    defaults = {**gas_volume.DEFAULTS, "viscosity_Pa_s": VISCOSITY_PA_S}

    def __init__(self, name: str, values, law: str = gas_volume.LAWS[0], inlet: str = INLETS[0]):
        if inlet not in INLETS:
            raise ValueError(f"unknown inlet {inlet!r} (one of {', '.join(INLETS)})")
        self.law, self.inlet = gas_volume.checked_law(law), inlet
        self.ports = (Port("inlet", PNEUMATIC, "node" if inlet == "volume" else "branch"),
                      Port("outlet", PNEUMATIC, "branch"))
        values = {**self.defaults, **values}
        self.extra_parameters = gas_volume.COMMON_PARAMETERS
        cls = TUBE_LAWS[self.law]
        own = self.wrap(cls(**{f: float(values[f]) for f in cls.__dataclass_fields__}), _probe, gas_volume.PROBE,
                        required="tube")
        own.update({v.name: float(values[v.name]) for v in gas_volume.COMMON_PARAMETERS})
        super().__init__(name, own)

    @classmethod
    def scenario_parameters(cls, options) -> tuple[Var, ...]:
        """The keys a ``[[component]]`` table of this type takes, for its ``options`` (law, inlet)."""
        return (positive("length_m", "m", "the tube's length"), positive("diameter_m", "m", "the tube's inner diameter"),
                positive("viscosity_Pa_s", "Pa s", "dynamic viscosity of the gas")
                ) + gas_volume.law_parameters(options.get("law", gas_volume.LAWS[0]))

    def structure_key(self) -> tuple:
        """The class, the element's form (its law) and the inlet's role."""
        return super().structure_key() + (self.inlet,)

    def held_state(self, p_abs_Pa: float) -> dict[str, float]:
        """Its states at rest at the absolute pressure ``p_abs_Pa`` (an operating point of a line)."""
        return gas_volume.held_state(self, p_abs_Pa)

    def equations(self, s: Symbols) -> Equations:
        bore = self.symbolic_element(s.p)
        p, m = s.x["p_abs_Pa"], s.x["air_mass_kg"]
        T = bore.gas_temperature_K(p, bore.volume_m3(0.0), m)
        out = s.port["outlet"]
        node_inlet = self.inlet == "volume"
        m_out, T_out = _segment(bore, p, T, out["p_abs_Pa"], out["T_K"], 1.0 if node_inlet else 0.5)
        R = bore.R_J_per_kg_K
        port = {"outlet": {"mdot_kg_s": m_out, "flow_work_W": R * T_out * m_out}}
        if node_inlet:
            m_in, work_in = s.port["inlet"]["mdot_kg_s"], s.port["inlet"]["flow_work_W"]
            port["inlet"] = {"p_abs_Pa": p, "T_K": T}
        else:
            inl = s.port["inlet"]
            m_in, T_in = _segment(bore, inl["p_abs_Pa"], inl["T_K"], p, T, 0.5)
            work_in = R * T_in * m_in
            port["inlet"] = {"mdot_kg_s": -m_in, "flow_work_W": -work_in}
        mdot, work = m_in - m_out, work_in - R * T_out * m_out
        p0, m0 = gas_volume.start(bore, s)
        return Equations(
            der={"p_abs_Pa": gas_volume.pressure_rate(bore, p, m, mdot, work), "air_mass_kg": mdot},
            outputs={"p_gauge_Pa": p - s.p["p_atm_Pa"], "p_abs_Pa": p, "gas_temperature_K": T,
                     "inlet_mass_flow_kg_s": m_in, "outlet_mass_flow_kg_s": m_out,
                     "reynolds_number": bore.reynolds_number(m_out)},
            port=port, initial={"p_abs_Pa": p0, "air_mass_kg": m0})
