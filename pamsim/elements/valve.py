"""ISO 6358 valve with a laminar branch near a pressure ratio of 1, and the
proportional 3/3 valve built on it.

Not in the paper (MODEL_NOTES sec. 6).  The subsonic ISO 6358 law has an
infinite slope at p_down/p_up -> 1; above ``laminar_ratio`` it is replaced by a
straight line to zero flow at ratio 1, as Simscape's ISO 6358 block does.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping


@dataclass(frozen=True)
class Iso6358Orifice:
    """Sonic conductance C [m^3/(s Pa)], critical ratio b [-], laminar ratio [-], reference state."""

    C_m3_per_s_Pa: float
    b: float
    laminar_ratio: float
    rho0_kg_m3: float
    T0_K: float

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "Iso6358Orifice":
        """The valve of a muscle's parameters: sonic conductance, critical pressure ratio, laminar ratio and
        reference conditions.
        """
        return cls(p["valve_C_m3_per_s_Pa"], p["valve_b"], p["valve_laminar_ratio"],
                   p["rho0_kg_m3"], p["T0_K"])

    def mass_flow_kg_s(self, p_a_Pa, p_b_Pa, T_a_K, T_b_K):
        """Signed mass flow [kg/s] from side a to side b (absolute pressures, temperatures).

        Written without branches so that one code path serves floats (in the
        right-hand side, where numpy calls on scalars would dominate the cost)
        and arrays (when a trace is post-processed).
        """
        forward = p_a_Pa >= p_b_Pa
        p_up = _max(p_a_Pa, p_b_Pa)
        p_down = _min(p_a_Pa, p_b_Pa)
        T_up = T_b_K + (T_a_K - T_b_K) * forward
        ratio = p_down / p_up
        # Below b the flow is choked (s = 0); above laminar_ratio the subsonic law is frozen
        # and scaled linearly to zero at ratio 1.
        s = _max(_min(ratio, self.laminar_ratio) - self.b, 0.0) / (1.0 - self.b)
        laminar_scale = _min(1.0, (1.0 - ratio) / (1.0 - self.laminar_ratio))
        flow = (self.C_m3_per_s_Pa * self.rho0_kg_m3 * p_up * (self.T0_K / T_up) ** 0.5
                * (1.0 - s * s) ** 0.5 * laminar_scale)
        return flow * (2 * forward - 1)


def _min(a, b):
    return 0.5 * (a + b - abs(a - b))


def _max(a, b):
    return 0.5 * (a + b + abs(a - b))


@dataclass(frozen=True)
class ProportionalValve33:
    """3/3 proportional valve: command u in [-1, 1] scales the conductance
    to supply (u > 0) or to exhaust (u < 0); u = 0 closes it.

    ``orifice`` is the supply path's (and the exhaust path's too while ``exhaust_orifice`` is None);
    ``exhaust_orifice``, if given, is the exhaust path's own ISO 6358 (C, b): a valve whose two paths
    differ, as a solenoid valve's seats do."""

    orifice: Iso6358Orifice
    exhaust_orifice: Iso6358Orifice | None = None

    @property
    def exhaust_path(self) -> Iso6358Orifice:
        """The exhaust path's orifice: its own, else the supply path's."""
        return self.orifice if self.exhaust_orifice is None else self.exhaust_orifice

    def inflow_kg_s(self, u, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa):
        """Mass flow into the chamber [kg/s] (absolute pressures).

        Only one path is open at a time, so with one orifice for both it is evaluated once,
        against the supply for u >= 0 and against the exhaust for u < 0; with a path of its own the
        exhaust's orifice is evaluated against the exhaust and the one the command points to is taken.
        """
        to_supply = u >= 0.0
        opening = _min(abs(u), 1.0)
        if self.exhaust_orifice is None:
            p_port = p_exhaust_Pa + (p_supply_Pa - p_exhaust_Pa) * to_supply
            return opening * self.orifice.mass_flow_kg_s(p_port, p_chamber_Pa, T_supply_K, T_chamber_K)
        fill = self.orifice.mass_flow_kg_s(p_supply_Pa, p_chamber_Pa, T_supply_K, T_chamber_K)
        vent = self.exhaust_orifice.mass_flow_kg_s(p_exhaust_Pa, p_chamber_Pa, T_supply_K, T_chamber_K)
        return opening * (vent + (fill - vent) * to_supply)


class TwoPathValve:
    """A valve whose supply and exhaust paths may be open at once, each a share of the full opening of its
    ``valve`` (a :class:`ProportionalValve33`): a mixin for a dataclass with a ``valve`` field and a method
    ``shares(opening) -> (W_supply, W_exhaust)`` (the averaged PWM valve at its duty, a spool valve at its
    position)."""

    def path_flows_kg_s(self, opening, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa) -> tuple:
        """Mass flows into the chamber [kg/s] through the supply path and through the exhaust path: each the
        full opening's flow on its side, times that path's share."""
        w_supply, w_exhaust = self.shares(opening)
        full = self.valve.inflow_kg_s
        return (w_supply * full(1.0, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa),
                w_exhaust * full(-1.0, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa))

    def inflow_kg_s(self, opening, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K, p_exhaust_Pa):
        """Net mass flow into the chamber [kg/s] (absolute pressures): the two paths' sum."""
        supply, exhaust = self.path_flows_kg_s(opening, p_chamber_Pa, T_chamber_K, p_supply_Pa, T_supply_K,
                                               p_exhaust_Pa)
        return supply + exhaust


@dataclass(frozen=True)
class OnOffValvePair(TwoPathValve):
    """Two 2/2 on/off valves on one port: an inlet from the supply and an exhaust to the ambient, each
    with its own ISO 6358 orifice (``valve.orifice`` the inlet's, ``valve.exhaust_path`` the exhaust's).
    Their openings are the pair ``(inlet, exhaust)``, each in [0, 1]; both may be open at once, and then
    their flows add (:class:`TwoPathValve`)."""

    valve: ProportionalValve33

    def shares(self, opening) -> tuple:
        """``(W_supply, W_exhaust)``: each valve's opening, held to [0, 1]."""
        inlet, exhaust = opening
        return _min(_max(inlet, 0.0), 1.0), _min(_max(exhaust, 0.0), 1.0)
