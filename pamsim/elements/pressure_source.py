"""Where the muscle's pressure comes from: a valve feeding the chamber, or a
prescribed pressure.

A source owns its own states (none for a prescribed pressure; chamber
pressure and air mass for the valve) and reports the gauge pressure the
mechanics see.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..signals import max_step_hint_s
from .chamber import BraidCylinder
from .valve import ProportionalValve33


@dataclass(frozen=True)
class ValveChamberSource:
    """A proportional 3/3 valve between a supply and the muscle chamber.

    States: absolute chamber pressure [Pa] and air mass [kg].
    ``supply_gauge_Pa(t)`` and ``command(t)`` (in [-1, 1]) are signals.
    """

    valve: ProportionalValve33
    chamber: BraidCylinder
    supply_gauge_Pa: Callable
    command: Callable
    T_supply_K: float
    p_atm_Pa: float
    name: str = "valve"
    state_names: tuple[str, ...] = ("p_abs_Pa", "air_mass_kg")

    def initial_state(self, x_m: float, p_gauge_Pa: float = 0.0) -> list[float]:
        """``[absolute pressure, air mass]`` of the chamber at rest at ``x_m`` and gauge pressure ``p_gauge_Pa``,
        at the chamber's starting temperature (the supply's, or the wall's for a law with a wall temperature).
        """
        p = self.p_atm_Pa + p_gauge_Pa
        T = self.chamber.start_temperature_K(self.T_supply_K)
        return [p, self.chamber.air_mass_kg(p, self.chamber.volume_m3(x_m), T)]

    def inputs(self, t_s) -> tuple:
        """The source's inputs at time t: (valve command [-], supply gauge pressure [Pa])."""
        return self.command(t_s), self.supply_gauge_Pa(t_s)

    @property
    def signals(self) -> tuple:
        """The signals of :meth:`inputs`, in its order: valve command, supply gauge pressure [Pa]."""
        return self.command, self.supply_gauge_Pa

    def pressure_gauge_Pa(self, s, inputs):
        """Gauge pressure [Pa] of the chamber: its absolute pressure state less the ambient pressure."""
        return s[0] - self.p_atm_Pa

    def pressure_trace_Pa(self, t_s, S):
        """Gauge pressure [Pa] along a trace, from the pressure state."""
        return np.asarray(S[0], dtype=float) - self.p_atm_Pa  # a state: the inputs are not needed

    def inflow_kg_s(self, s, V, inputs):
        """Valve mass flow into the chamber [kg/s] and the chamber gas temperature [K] at volume V [m^3]."""
        p, m = s[0], s[1]
        u, supply_gauge_Pa = inputs
        T_gas = self.chamber.gas_temperature_K(p, V, m)
        mdot = self.valve.inflow_kg_s(u, p, T_gas, supply_gauge_Pa + self.p_atm_Pa, self.T_supply_K, self.p_atm_Pa)
        return mdot, T_gas

    def derivatives(self, s, x_m, v_m_s, inputs) -> tuple[float, float]:
        """(dp/dt [Pa/s], dm/dt [kg/s]) of the chamber."""
        p = s[0]
        V = self.chamber.volume_m3(x_m)
        mdot, T_gas = self.inflow_kg_s(s, V, inputs)
        mdot = float(mdot)
        T_in = self.T_supply_K if mdot >= 0.0 else T_gas
        dV = self.chamber.dvolume_dx_m2(x_m) * v_m_s
        return self.chamber.pressure_rate_Pa_s(p, V, dV, mdot, T_in, s[1], x_m), mdot

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where the supply pressure or the valve command jumps."""
        return tuple(getattr(self.supply_gauge_Pa, "breakpoints", ())) + tuple(getattr(self.command, "breakpoints", ()))

    @property
    def max_input_step_s(self) -> float:
        """Longest step [s] over which the supply pressure and the command are monotonic."""
        return max_step_hint_s(self.supply_gauge_Pa, self.command)

    def outputs(self, t_s, S, x_m) -> dict[str, np.ndarray]:
        """Extra trace columns: air mass, valve mass flow, valve command, supply pressure, gas temperature."""
        inputs = self.inputs(t_s)
        mdot, T_gas = self.inflow_kg_s(S, self.chamber.volume_m3(x_m), inputs)
        return {"air_mass_kg": S[1], "valve_mass_flow_kg_s": np.asarray(mdot, dtype=float),
                "valve_command": np.asarray(inputs[0], dtype=float) + 0.0 * t_s,
                "supply_gauge_Pa": np.asarray(inputs[1], dtype=float) + 0.0 * t_s,
                "gas_temperature_K": T_gas}


@dataclass(frozen=True)
class LineValveSource(ValveChamberSource):
    """:class:`ValveChamberSource` in a line of components: the valve's supply side connected to the port
    ``supply_port`` of a component added to the rig (a supply's, a reservoir's node), in place of its
    supply input, and its outlet to ``outlet_port`` (a tube's inlet) in place of the chamber.  An empty
    string keeps that side as :class:`ValveChamberSource` has it.  The physics is the same; only the
    wiring differs (:func:`pamsim.assemblies.one_muscle.source_parts`)."""

    supply_port: str = ""
    outlet_port: str = ""


@dataclass(frozen=True)
class PrescribedPressure:
    """Gauge pressure imposed as a signal ``p_gauge_Pa(t)``: step, ramp, lag or measured trace."""

    p_gauge_Pa: Callable
    name: str = "prescribed"
    state_names: tuple[str, ...] = ()

    def initial_state(self, x_m: float, p_gauge_Pa: float = 0.0) -> list[float]:
        """No states: an empty list."""
        return []

    def inputs(self, t_s) -> tuple:
        """The source's input at time t: (gauge pressure [Pa],)."""
        return (self.p_gauge_Pa(t_s),)

    @property
    def signals(self) -> tuple:
        """The signal of :meth:`inputs`: the gauge pressure [Pa]."""
        return (self.p_gauge_Pa,)

    def pressure_gauge_Pa(self, s, inputs):
        """The prescribed gauge pressure [Pa], the source's only input."""
        return inputs[0]

    def pressure_trace_Pa(self, t_s, S):
        """The prescribed gauge pressure [Pa] at the times ``t_s`` [s]."""
        return np.asarray(self.p_gauge_Pa(t_s), dtype=float) + 0.0 * t_s

    def derivatives(self, s, x_m, v_m_s, inputs) -> tuple[()]:
        """No states, no derivatives."""
        return ()

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where the prescribed pressure jumps."""
        return tuple(getattr(self.p_gauge_Pa, "breakpoints", ()))

    @property
    def max_input_step_s(self) -> float:
        """Longest step [s] over which the prescribed pressure is monotonic."""
        return max_step_hint_s(self.p_gauge_Pa)

    def outputs(self, t_s, S, x_m) -> dict[str, np.ndarray]:
        """No extra columns."""
        return {}
