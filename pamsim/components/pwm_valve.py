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
        outputs, port = two_path_flows(self, s, s.u["duty"])
        return Equations(outputs=outputs, port=port)


def two_path_flows(component, s: Symbols, opening) -> tuple[dict, dict]:
    """``(outputs, port)`` of a valve ``component`` whose element has a supply and an exhaust path open at
    once (``path_flows_kg_s(opening, ...)`` and ``shares(opening)``: the averaged PWM valve at its duty, a
    spool valve at its position), between its supply input and its ``port``.

    Each path's flow carries the temperature of where it comes from (the supply's, or the volume's gas
    for an outflow).  Output ``p_settle_abs_Pa``: the supply's pressure while only the supply path is
    open, the exhaust's while only the exhaust path is, else the port's own (a volume fed by both settles
    where their flows balance, which no closed form gives).
    """
    valve = component.symbolic_element(s.p)
    p, T = s.port["port"]["p_abs_Pa"], s.port["port"]["T_K"]
    T_supply, p_atm = s.p["T_supply_K"], s.p["p_atm_Pa"]
    p_supply = s.u["supply_gauge_Pa"] + p_atm
    supply, exhaust = valve.path_flows_kg_s(opening, p, T, p_supply, T_supply, p_atm)
    work = sum(if_else(mdot >= 0.0, T_supply, T) * mdot for mdot in (supply, exhaust))
    w_supply, w_exhaust = valve.shares(opening)
    settle = if_else((w_supply > 0.0) * (w_exhaust == 0.0), p_supply,
                     if_else((w_exhaust > 0.0) * (w_supply == 0.0), p_atm, p))
    return ({"mass_flow_kg_s": supply + exhaust, "p_settle_abs_Pa": settle},
            {"port": {"mdot_kg_s": supply + exhaust, "flow_work_W": s.p["R_J_per_kg_K"] * work}})
