"""A tube: the gas in its bore and the bore's resistance, laminar or turbulent, in ``segments`` lumped cells,
with or without the gas's inertia (:mod:`pamsim.elements.tube`).

Two layouts, chosen by ``inlet``, because a node (a volume) meets only branches (flows) and a branch only a
node:

- ``inlet = "resistance"`` (the default): each cell a T, half its resistance, its volume, the other half.
  Both ends are branches: the tube joins two volumes (a supply and a reservoir, a reservoir and the muscle).
- ``inlet = "volume"``: each cell its volume then its whole resistance.  The inlet is a node: a valve (a
  branch) discharges into the first cell, and the last cell's resistance feeds the volume at its outlet.

The bore of length ``L`` is cut into ``segments = N`` cells of length ``L / N``; between two neighbours the
resistance of ``L / N`` (of ``L / (2 N)`` at an end of the T layout).  Without ``inertia`` each such flow is
the resistance's flow of the pressures on its two sides; with it, each flow is a state, the gas in that
length accelerated by the pressure difference less the resistance's drop, so that pressure waves travel
along the tube at the gas law's speed of sound.  Its length, bore, law and layout are the scenario's
(``[[component]] type = "tube"``).
"""

from __future__ import annotations

import dataclasses

from ..elements.tube import RESISTANCES, TUBE_LAWS
from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else
from . import gas_volume
from .element import ElementParameters
from .reservoir import VOLUME_OUTPUTS, VOLUME_STATES

INLETS = ("resistance", "volume")
"""The tube's layouts by the role of its inlet; the first is the default."""

MAX_SEGMENTS = 50
"""The most cells a tube takes: each adds two or three states, and the native engine's explicit steps shrink
with the cell (its acoustic period with ``inertia``, ``2 L / (N c)``).  50 cells put the quarter-wave
resonance within 1e-4 of ``c / (4 L)`` (``docs/pneumatics.md``)."""

VISCOSITY_PA_S = 1.81e-5
"""Dynamic viscosity of air at 20 C and 1 atm [Pa s] (F. M. White, Fluid Mechanics, 7th ed., Table A.2);
it hardly depends on the pressure."""

FLOW_NOMINAL_KG_S = 1e-4
"""Nominal scale of a cell's mass flow (the integrator's absolute tolerance): a tenth of a millimetre tube's
flow at a fill (the shipped line's peaks near 1e-3 kg/s)."""

FLOW_OUTPUTS = (Var("inlet_mass_flow_kg_s", "kg/s", "mass flow into the tube at its inlet"),
                Var("outlet_mass_flow_kg_s", "kg/s", "mass flow out of the tube at its outlet"),
                Var("reynolds_number", "1", "Reynolds number of the outlet's flow (laminar below about 2300)"),
                Var("outlet_p_gauge_Pa", "Pa", "gauge pressure of the cell at the outlet (the bore's, one cell)"),
                Var("air_mass_total_kg", "kg", "air in the whole bore (every cell's)"))


def _segments_violation(value) -> str | None:
    if isinstance(value, bool) or not isinstance(value, int):
        return "must be a whole number of cells"
    if not 1 <= value <= MAX_SEGMENTS:
        return f"must be between 1 and {MAX_SEGMENTS}"
    return None


def _inertia_violation(value) -> str | None:
    return None if isinstance(value, bool) else "must be true or false"


def _probe(element, p, m, mdot, flow_work):
    return (gas_volume.pressure_rate(element, p, m, mdot, flow_work) + element.mass_flow_kg_s(p, 1.5e5, 300.0, 0.5)
            + element.turbulent_mass_flow_kg_s(p, 1.5e5, 300.0, 0.5)
            + element.flow_acceleration_kg_s2(mdot, p, 1.5e5, 300.0, 0.5, True))


def _cell_names(k: int) -> tuple[str, str]:
    """The pressure and air-mass states of cell ``k`` (0 at the inlet): the first keeps the one-cell tube's
    names."""
    return ("p_abs_Pa", "air_mass_kg") if k == 0 else (f"cell{k + 1}_p_abs_Pa", f"cell{k + 1}_air_mass_kg")


def _flow_name(j: int) -> str:
    return f"flow{j + 1}_mdot_kg_s"


class Tube(ElementParameters, Component):
    """A tube of ``length_m`` and inner ``diameter_m`` between its ``inlet`` and ``outlet`` ports.

    States the absolute pressure and air mass of the gas in each of its ``segments`` cells (the law ``law``,
    :data:`pamsim.components.gas_volume.LAWS`), and with ``inertia`` the mass flow through each resistance;
    the outlet is a branch into the volume it feeds, the inlet a branch from the volume before it (``inlet =
    "resistance"``) or the first cell, a node (``inlet = "volume"``).  ``resistance``: the bore's law,
    ``"laminar"`` or ``"turbulent"`` (:data:`pamsim.elements.tube.RESISTANCES`).  Outputs the first cell's
    pressure and gas temperature, the last cell's pressure, the flows at both ends, the outlet's Reynolds
    number and the air in the bore.
    """

    outputs = VOLUME_OUTPUTS + FLOW_OUTPUTS
    choices = {"law": gas_volume.LAWS, "inlet": INLETS, "resistance": RESISTANCES}
    settings = {"segments": _segments_violation, "inertia": _inertia_violation}
    """Options that are not names (a number of cells, a switch): each with what is wrong with a value, or None."""
    defaults = {**gas_volume.DEFAULTS, "viscosity_Pa_s": VISCOSITY_PA_S}

    def __init__(self, name: str, values, law: str = gas_volume.LAWS[0], inlet: str = INLETS[0],
                 resistance: str = RESISTANCES[0], segments: int = 1, inertia: bool = False):
        if inlet not in INLETS:
            raise ValueError(f"unknown inlet {inlet!r} (one of {', '.join(INLETS)})")
        if resistance not in RESISTANCES:
            raise ValueError(f"unknown resistance {resistance!r} (one of {', '.join(RESISTANCES)})")
        for key, value in (("segments", segments), ("inertia", inertia)):
            why = self.settings[key](value)
            if why:
                raise ValueError(f"{key} = {value!r}: {why}")
        self.law, self.inlet, self.resistance = gas_volume.checked_law(law), inlet, resistance
        self.segments, self.inertia = int(segments), bool(inertia)
        self.ports = (Port("inlet", PNEUMATIC, "node" if inlet == "volume" else "branch"),
                      Port("outlet", PNEUMATIC, "branch"))
        self.states = self._states()
        values = {**self.defaults, **values}
        self.extra_parameters = gas_volume.COMMON_PARAMETERS
        cls = TUBE_LAWS[self.law]
        own = self.wrap(cls(**{f: float(values[f]) for f in cls.__dataclass_fields__}), _probe, gas_volume.PROBE,
                        required="tube")
        own.update({v.name: float(values[v.name]) for v in gas_volume.COMMON_PARAMETERS})
        super().__init__(name, own)

    def _n_flows(self) -> int:
        return self.segments + (1 if self.inlet == "resistance" else 0)

    def _fractions(self) -> list[float]:
        """Each resistance's share of the bore's length, inlet to outlet."""
        n = self.segments
        if self.inlet == "volume":
            return [1.0 / n] * n
        return [0.5 / n] + [1.0 / n] * (n - 1) + [0.5 / n]

    def _states(self) -> tuple[Var, ...]:
        pressure, mass = VOLUME_STATES
        cells = []
        for k in range(self.segments):
            p_name, m_name = _cell_names(k)
            where = f" of cell {k + 1}" if self.segments > 1 else ""
            cells += [dataclasses.replace(pressure, name=p_name, description=pressure.description + where),
                      dataclasses.replace(mass, name=m_name, description=mass.description + where)]
        flows = [Var(_flow_name(j), "kg/s", f"mass flow through resistance {j + 1} (inlet to outlet)",
                     FLOW_NOMINAL_KG_S) for j in range(self._n_flows())] if self.inertia else []
        return tuple(cells + flows)

    @classmethod
    def scenario_parameters(cls, options) -> tuple[Var, ...]:
        """The keys a ``[[component]]`` table of this type takes, for its ``options`` (law, inlet)."""
        return (positive("length_m", "m", "the tube's length"), positive("diameter_m", "m", "the tube's inner diameter"),
                positive("viscosity_Pa_s", "Pa s", "dynamic viscosity of the gas")
                ) + gas_volume.law_parameters(options.get("law", gas_volume.LAWS[0]))

    def structure_key(self) -> tuple:
        """The class, the element's form (its law), the layout, the resistance law, the cells and the inertia."""
        key = super().structure_key() + (self.inlet,)
        if (self.resistance, self.segments, self.inertia) != (RESISTANCES[0], 1, False):
            key += (self.resistance, self.segments, self.inertia)
        return key

    def _cell(self, bore):
        """The element of one cell: the bore, ``1 / segments`` of its length."""
        return bore if self.segments == 1 else dataclasses.replace(bore, length_m=bore.length_m / self.segments)

    def held_state(self, p_abs_Pa: float) -> dict[str, float]:
        """Its states at rest at the absolute pressure ``p_abs_Pa`` (an operating point of a line): every cell
        there, no flow."""
        cell = gas_volume.held_state(self, p_abs_Pa, self._cell(self.element))
        out = {}
        for k in range(self.segments):
            p_name, m_name = _cell_names(k)
            out[p_name], out[m_name] = cell["p_abs_Pa"], cell["air_mass_kg"]
        out.update({_flow_name(j): 0.0 for j in range(self._n_flows())} if self.inertia else {})
        return out

    def _flow(self, bore, j, fraction, side_a, side_b, x):
        """The mass flow of resistance ``j`` from ``side_a`` to ``side_b`` (each ``(p, T)``), the temperature
        it carries (its upstream side's) and, with inertia, its rate of change."""
        (p_a, T_a), (p_b, T_b) = side_a, side_b
        turbulent = self.resistance == "turbulent"
        if self.inertia:
            mdot = x[_flow_name(j)]
            T_up = if_else(mdot >= 0.0, T_a, T_b)
            return mdot, T_up, bore.flow_acceleration_kg_s2(mdot, p_a, p_b, T_up, fraction, turbulent)
        T_up = if_else(p_a >= p_b, T_a, T_b)
        law = bore.turbulent_mass_flow_kg_s if turbulent else bore.mass_flow_kg_s
        return law(p_a, p_b, T_up, fraction), T_up, None

    def equations(self, s: Symbols) -> Equations:
        bore = self.symbolic_element(s.p)
        cell = self._cell(bore)
        R, V = bore.R_J_per_kg_K, cell.volume_m3(0.0)
        names = [_cell_names(k) for k in range(self.segments)]
        gas = [(s.x[p], cell.gas_temperature_K(s.x[p], V, s.x[m])) for p, m in names]
        out, inl = s.port["outlet"], s.port["inlet"]
        node_inlet = self.inlet == "volume"
        sides = ([] if node_inlet else [(inl["p_abs_Pa"], inl["T_K"])]) + gas + [(out["p_abs_Pa"], out["T_K"])]
        flows, der = [], {}
        for j, fraction in enumerate(self._fractions()):
            mdot, T_up, rate = self._flow(bore, j, fraction, sides[j], sides[j + 1], s.x)
            flows.append((mdot, R * T_up * mdot))
            if rate is not None:
                der[_flow_name(j)] = rate
        # Cell k sits between flows k - 1 and k (T layout: flows k and k + 1); the inlet node's is the port's.
        ahead = [(inl["mdot_kg_s"], inl["flow_work_W"])] + flows if node_inlet else flows
        port = {"outlet": {"mdot_kg_s": flows[-1][0], "flow_work_W": flows[-1][1]},
                "inlet": ({"p_abs_Pa": gas[0][0], "T_K": gas[0][1]} if node_inlet
                          else {"mdot_kg_s": -flows[0][0], "flow_work_W": -flows[0][1]})}
        initial, masses = {}, 0.0
        p0, m0 = gas_volume.start(cell, s)
        for k, (p_name, m_name) in enumerate(names):
            (m_in, w_in), (m_out, w_out) = ahead[k], ahead[k + 1]
            p, m = s.x[p_name], s.x[m_name]
            der[p_name] = gas_volume.pressure_rate(cell, p, m, m_in - m_out, w_in - w_out)
            der[m_name] = m_in - m_out
            initial[p_name], initial[m_name] = p0, m0
            masses = masses + m
        initial.update({_flow_name(j): 0.0 for j in range(len(flows))} if self.inertia else {})
        p_atm = s.p["p_atm_Pa"]
        return Equations(
            der={k: der[k] for k in (v.name for v in self.states)},
            outputs={"p_gauge_Pa": gas[0][0] - p_atm, "p_abs_Pa": gas[0][0], "gas_temperature_K": gas[0][1],
                     "inlet_mass_flow_kg_s": ahead[0][0], "outlet_mass_flow_kg_s": flows[-1][0],
                     "reynolds_number": bore.reynolds_number(flows[-1][0]),
                     "outlet_p_gauge_Pa": gas[-1][0] - p_atm, "air_mass_total_kg": masses},
            port=port, initial=initial)
