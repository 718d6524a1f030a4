"""Two 2/2 on/off valves (:class:`pamsim.elements.valve.OnOffValvePair`) as one pneumatic branch: the inlet's
and the exhaust's openings in, their two paths' flows into the port."""

from __future__ import annotations

from ..modeling import Equations, Symbols, Var
from .pwm_valve import two_path_flows
from .valve import ProportionalValve


def _inflow_kg_s(element, u, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa):
    # Probed with the inlet open by u and the exhaust by the rest: both paths' flows, at once too.
    return element.inflow_kg_s((u, 1.0 - u), p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa)


class ValvePair(ProportionalValve):
    """An inlet and an exhaust 2/2 valve on one port, each with its own ISO 6358 orifice and opening in
    [0, 1]; a pneumatic branch with the proportional valve's ports, outputs and parameters.

    Output ``p_settle_abs_Pa``: the supply's pressure while the inlet alone is open, the ambient's while
    the exhaust alone is, else the port's own (:func:`pamsim.components.pwm_valve.two_path_flows`).
    """

    probe = staticmethod(_inflow_kg_s)
    inputs = (Var("inlet_command", "1", "inlet valve's opening in [0, 1]"),
              Var("exhaust_command", "1", "exhaust valve's opening in [0, 1]"),
              Var("supply_gauge_Pa", "Pa", "supply gauge pressure"))

    def equations(self, s: Symbols) -> Equations:
        """The two valves' flows into the port, their flow work, and the pressure the port settles at."""
        outputs, port = two_path_flows(self, s, (s.u["inlet_command"], s.u["exhaust_command"]))
        return Equations(outputs=outputs, port=port)
