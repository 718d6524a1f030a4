"""The averaged model of an on/off valve under PWM: its duty in, the mean of its two paths' flows out."""

from __future__ import annotations

from ..modeling import Equations, Symbols, Var
from ..modeling.smath import if_else
from .valve import ProportionalValve


class AveragedPwmValve(ProportionalValve):
    """:class:`pamsim.elements.pwm_average.PwmAveragedValve`: an on/off valve under PWM as the mean of
    its supply and exhaust paths' flows over a period; a pneumatic branch with the proportional valve's
    ports, outputs and parameters, and the duty in place of its command.

    Each path's flow carries the temperature of where it comes from (the supply's, or the volume's gas
    for an outflow), so the flow work is the switching valve's mean too.  Output ``p_settle_abs_Pa``:
    the supply's pressure while only the supply path ever opens, the exhaust's while only the exhaust
    path does, else the port's own (a chamber fed by both settles where their flows balance, which no
    closed form gives).
    """

    inputs = (Var("duty", "1", "PWM duty cycle in [0, 1]"),
              Var("supply_gauge_Pa", "Pa", "supply gauge pressure"))

    def equations(self, s: Symbols) -> Equations:
        """The two paths' mean flows into the port, their flow work, and the pressure the port settles at."""
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
