"""Two 2/2 on/off solenoid valves on the muscle's chamber: an inlet from the supply and an exhaust to the
ambient, each with its own ISO 6358 (C, b), its own command and its own delays and switching times.

The valves are :class:`~pamsim.elements.valve.OnOffValvePair` (the flow law is
:class:`~pamsim.elements.valve.Iso6358Orifice`'s, written once); their openings are the signals of their
commands as the valves follow them (:class:`pamsim.signals.Pwm`, :class:`pamsim.signals.OnOff`), each knot
a breakpoint, so every switch of either valve is exact.  Both may be open at once; their flows add, each
carrying the temperature of where it comes from.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..signals import max_step_hint_s
from .pressure_source import ValveChamberSource
from .pwm_average import AveragedInletPair, AveragedPwmSource, PwmShare, chamber_rates_of_paths, duty_signal
from .valve import OnOffValvePair

VALVE_DEFAULTS = {
    "delay_on_s": (0.0, "assumed: a valve that opens when commanded (set it from the valve's data sheet)"),
    "delay_off_s": (0.0, "assumed: a valve that closes when commanded"),
    "rise_s": (0.0, "assumed: a valve that opens at once"),
    "fall_s": (0.0, "assumed: a valve that closes at once"),
}
"""The timing keys of a ``[pressure.inlet]`` or ``[pressure.exhaust]`` table besides its ``C_m3_per_s_Pa`` and
``b`` (whose defaults are the muscle's ``valve_C_m3_per_s_Pa`` and ``valve_b``): default and where it comes
from."""


@dataclass(frozen=True)
class ValvePairSource(ValveChamberSource):
    """:class:`ValveChamberSource` through two 2/2 valves (``valve``: an :class:`OnOffValvePair`): ``command``
    is the inlet's opening in [0, 1] as it follows its command, ``exhaust_command`` the exhaust's."""

    exhaust_command: Callable = None
    averaged_inlet: Any = None
    """The inlet's PWM command (:class:`pamsim.signals.Pwm`) when ``command`` is its mean opening (run averaged,
    :func:`~pamsim.elements.pwm_average.mean_opening_signal`); None otherwise."""

    def at_inlet_duty(self) -> AveragedPwmSource:
        """The pair averaged at the inlet's duty (its input), the exhaust open its share while the inlet's PWM
        runs (:class:`~pamsim.elements.pwm_average.AveragedInletPair`): the model ``pamsim linearize`` takes.

        Raises
        ------
        ValueError
            If the inlet does not run averaged, or the exhaust's opening changes while the inlet's PWM runs
            (a switching PWM, a step inside it): no share stands for it.
        """
        pwm = self.averaged_inlet
        if pwm is None:
            raise ValueError("the inlet's PWM does not run averaged")
        inside = [t for t in getattr(self.exhaust_command, "breakpoints", ()) if pwm.start_s < t < pwm.end_s]
        times = np.concatenate([np.linspace(pwm.start_s, pwm.end_s, 101)[1:-1], inside])
        openings = np.unique(np.asarray(self.exhaust_command(times), dtype=float))
        if openings.size != 1:
            raise ValueError(f"the exhaust's opening takes {openings.size} values while the inlet's PWM runs "
                             f"({pwm.start_s:g} to {pwm.end_s:g} s); run its PWM averaged, or hold it")
        valve = AveragedInletPair(self.valve.valve, PwmShare.of_pwm(pwm), float(openings[0]))
        return AveragedPwmSource(valve, self.chamber, self.supply_gauge_Pa, duty_signal(pwm), self.T_supply_K,
                                 self.p_atm_Pa)

    def inputs(self, t_s) -> tuple:
        """(inlet opening, exhaust opening, supply gauge pressure [Pa]) at time ``t_s``."""
        return self.command(t_s), self.exhaust_command(t_s), self.supply_gauge_Pa(t_s)

    @property
    def signals(self) -> tuple:
        """The signals of :meth:`inputs`, in its order."""
        return self.command, self.exhaust_command, self.supply_gauge_Pa

    def inflow_kg_s(self, s, V, inputs):
        """Net mass flow into the chamber [kg/s] through both valves, and the gas temperature [K]."""
        T_gas = self.chamber.gas_temperature_K(s[0], V, s[1])
        mdot = self.valve.inflow_kg_s((inputs[0], inputs[1]), s[0], T_gas, inputs[2] + self.p_atm_Pa,
                                      self.T_supply_K, self.p_atm_Pa)
        return mdot, T_gas

    def derivatives(self, s, x_m, v_m_s, inputs) -> tuple[float, float]:
        """(dp/dt [Pa/s], dm/dt [kg/s]) of the chamber, each valve's flow carrying its own temperature."""
        inlet, exhaust, supply_gauge_Pa = inputs
        return chamber_rates_of_paths(self, s, x_m, v_m_s, (inlet, exhaust), supply_gauge_Pa)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where the supply pressure or either valve's opening jumps or kinks."""
        return super().breakpoints + tuple(getattr(self.exhaust_command, "breakpoints", ()))

    @property
    def max_input_step_s(self) -> float:
        """Longest step [s] over which the supply pressure and both openings are monotonic."""
        return max_step_hint_s(self.supply_gauge_Pa, self.command, self.exhaust_command)

    def outputs(self, t_s, S, x_m) -> dict[str, np.ndarray]:
        """Extra trace columns: air mass, the valves' net mass flow, each valve's opening (``valve_command``
        the inlet's, ``exhaust_command`` the exhaust's), supply pressure, gas temperature."""
        inlet, exhaust, supply = self.inputs(t_s)
        mdot, T_gas = self.inflow_kg_s(S, self.chamber.volume_m3(x_m), (inlet, exhaust, supply))
        zero = 0.0 * t_s
        return {"air_mass_kg": S[1], "valve_mass_flow_kg_s": np.asarray(mdot, dtype=float),
                "valve_command": np.asarray(inlet, dtype=float) + zero,
                "exhaust_command": np.asarray(exhaust, dtype=float) + zero,
                "supply_gauge_Pa": np.asarray(supply, dtype=float) + zero, "gas_temperature_K": T_gas}
