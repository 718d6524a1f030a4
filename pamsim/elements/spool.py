"""A proportional 3/3 spool valve (the Festo MPYE class): the spool's position as a second-order state, and
two ISO 6358 paths whose conductances follow it.

Spool (normalised position ``s`` in [-1, 1] of the stroke, command ``u`` in [-1, 1])::

    s'' = wn^2 (clip(u, -1, 1) - s) - 2 zeta wn s',     wn = 2 pi natural_frequency_Hz

the step response of a second-order lag: a valve whose spool position is closed-loop controlled, as the
MPYE's is, behaves so up to its critical frequency.  The end stops: the command is clipped to the stroke,
so the spool settles within it, and the metering edges see the position clipped to [-1, 1]: an
underdamped spool's overshoot past the stroke (4.6 % at ``zeta = 0.7``) opens the port no further than
fully.  No event, no impact: nothing chatters.

Paths (``o`` the overlap as a fraction of the stroke, ``C`` the full conductance, ``C_leak`` the leakage)::

    C_supply(s)  = C ramp(s) + C_leak,    C_exhaust(s) = C ramp(-s) + C_leak
    ramp(z)      = max(clip(z, -1, 1) - o, 0) / (1 - o)

zero inside the overlap band ``|s| <= o``, rising linearly to ``C`` at the end of the stroke; the leakage
(an underlapped or worn spool's centre flow) connects the port to the supply and to the exhaust at every
position.  Each path's flow is the existing ISO 6358 law
(:meth:`pamsim.elements.valve.Iso6358Orifice.mass_flow_kg_s`) scaled by its conductance's share of ``C``:
the law is linear in ``C``.  With ``o = 0`` and ``C_leak = 0`` the flow is that of
:class:`~pamsim.elements.valve.ProportionalValve33` at command ``s``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .pressure_source import ValveChamberSource
from .pwm_average import chamber_rates_of_paths
from .valve import ProportionalValve33, TwoPathValve, _max, _min

SPOOL_DEFAULTS = {
    "natural_frequency_Hz": (125.0, "assumed: about 125 Hz, the critical frequency given for the Festo MPYE-M5; "
                                    "not checked against its data sheet, which was not found in the sources "
                                    "searched"),
    "damping_ratio": (0.7, "assumed: a position-controlled spool tuned for little overshoot (4.6 % at 0.7); "
                           "no data sheet gives it"),
    "overlap": (0.0, "assumed: a zero-lapped spool, the MPYE's metering as a control valve"),
    "leakage_C_m3_per_s_Pa": (0.0, "assumed: no leakage, so that a closed valve holds the chamber as the "
                                   "proportional valve does"),
}
"""``[pressure.spool]`` keys: default and where it comes from (docs/pneumatics.md, "The proportional
spool valve")."""


def _ramp(z, overlap):
    """The share of the full conductance a metering edge opens at position ``z`` (see the module)."""
    z = _min(_max(z, -1.0), 1.0)
    return _max(z - overlap, 0.0) / (1.0 - overlap)


@dataclass(frozen=True)
class SpoolValve33(TwoPathValve):
    """A 3/3 spool valve: the spool's dynamics and its two paths' conductances (see the module).

    ``valve`` is the full opening's valve (its orifice's ``C`` is the conductance at the end of the
    stroke); ``leakage_C_m3_per_s_Pa`` is each path's conductance at every position besides it.  Its paths'
    flows (:class:`~pamsim.elements.valve.TwoPathValve`) take the spool's position.
    """

    valve: ProportionalValve33
    natural_frequency_Hz: float
    damping_ratio: float
    overlap: float
    leakage_C_m3_per_s_Pa: float

    @property
    def omega_rad_s(self):
        """The spool's natural angular frequency ``2 pi f`` [rad/s]."""
        return 2.0 * math.pi * self.natural_frequency_Hz

    def spool_acceleration(self, position, velocity, command):
        """``s''`` [1/s^2] at spool ``position`` [1], ``velocity`` [1/s] and ``command`` [1] (clipped to [-1, 1])."""
        w = self.omega_rad_s
        u = _min(_max(command, -1.0), 1.0)
        return w * w * (u - position) - 2.0 * self.damping_ratio * w * velocity

    def shares(self, position) -> tuple:
        """``(W_supply, W_exhaust)``: each path's conductance as a share of the full ``C`` at ``position``."""
        leak = self.leakage_C_m3_per_s_Pa
        if self.valve.exhaust_orifice is None:
            leak = leak / self.valve.orifice.C_m3_per_s_Pa
            return _ramp(position, self.overlap) + leak, _ramp(-position, self.overlap) + leak
        # Paths of their own: the leakage is a conductance, so each path's share is of its own C.
        return (_ramp(position, self.overlap) + leak / self.valve.orifice.C_m3_per_s_Pa,
                _ramp(-position, self.overlap) + leak / self.valve.exhaust_orifice.C_m3_per_s_Pa)


@dataclass(frozen=True)
class SpoolValveSource(ValveChamberSource):
    """:class:`ValveChamberSource` through a :class:`SpoolValve33`: the spool's position and velocity are states
    after the chamber's, the command drives the spool, and the chamber sees the two paths' flows.
    ``outlet_port``: where the valve discharges (a tube's inlet), empty for the chamber."""

    outlet_port: str = ""
    state_names: tuple[str, ...] = ("p_abs_Pa", "air_mass_kg", "spool_position", "spool_velocity_per_s")

    def initial_state(self, x_m: float, p_gauge_Pa: float = 0.0) -> list[float]:
        """The chamber's start (:meth:`ValveChamberSource.initial_state`), the spool at rest in its centre."""
        return super().initial_state(x_m, p_gauge_Pa) + [0.0, 0.0]

    def held_spool(self, command: float) -> dict[str, float]:
        """The spool at rest under a held ``command``: at the command (clipped to the stroke), not moving."""
        return {"spool_position": float(np.clip(command, -1.0, 1.0)), "spool_velocity_per_s": 0.0}

    def inflow_kg_s(self, s, V, inputs):
        """Net mass flow into the chamber [kg/s] at the spool's position ``s[2]``, and the gas temperature [K]."""
        T_gas = self.chamber.gas_temperature_K(s[0], V, s[1])
        mdot = self.valve.inflow_kg_s(s[2], s[0], T_gas, inputs[1] + self.p_atm_Pa, self.T_supply_K, self.p_atm_Pa)
        return mdot, T_gas

    def derivatives(self, s, x_m, v_m_s, inputs) -> tuple[float, ...]:
        """(dp/dt, dm/dt) of the chamber through the spool's two paths, then the spool's (ds/dt, dv/dt)."""
        command, supply_gauge_Pa = inputs
        dp, dm = chamber_rates_of_paths(self, s, x_m, v_m_s, s[2], supply_gauge_Pa)
        return dp, dm, s[3], float(self.valve.spool_acceleration(s[2], s[3], command))

    def outputs(self, t_s, S, x_m) -> dict[str, np.ndarray]:
        """:meth:`ValveChamberSource.outputs` (the flow at the spool's position) and the spool's position and
        velocity."""
        out = super().outputs(t_s, S, x_m)
        out.update(spool_position=np.asarray(S[2], dtype=float), spool_velocity_per_s=np.asarray(S[3], dtype=float))
        return out


SPOOL_LIMITS = {"natural_frequency_Hz": (lambda x: x > 0.0, "must be > 0"),
                "damping_ratio": (lambda x: x > 0.0, "must be > 0"),
                "overlap": (lambda x: 0.0 <= x < 1.0, "must lie in [0, 1): a fraction of the stroke"),
                "leakage_C_m3_per_s_Pa": (lambda x: x >= 0.0, "must be >= 0")}
"""What each ``[pressure.spool]`` key must satisfy, and the message when it does not."""


def spool_source(v, pressure: dict, parts: tuple, ports: dict) -> SpoolValveSource:
    """The :class:`SpoolValveSource` of a ``[pressure]`` table with a ``[pressure.spool]`` table, from the
    ``parts`` of its :class:`ValveChamberSource` (the proportional valve whose orifice is the full opening's)
    and its ``ports``.  ``v`` (a :class:`pamsim.table_checks.TableChecker`) refuses, naming the key, an
    unknown key or a value out of :data:`SPOOL_LIMITS`, a supply port (the spool takes its supply input),
    and a PWM command's averaged model (that is a valve of its own)."""
    table = pressure["spool"]
    if not isinstance(table, dict):
        v.fail("pressure.spool", table, "must be a table of the spool's parameters")
    for key in table:
        if key not in SPOOL_DEFAULTS:
            v.fail(f"pressure.spool.{key}", table[key], "unknown key of the spool valve", choices=tuple(SPOOL_DEFAULTS))
    values = {}
    for key, (default, _) in SPOOL_DEFAULTS.items():
        value = v.number(f"pressure.spool.{key}", table.get(key, default))
        test, why = SPOOL_LIMITS[key]
        if not test(value):
            v.fail(f"pressure.spool.{key}", value, why)
        values[key] = value
    if "supply_port" in ports:
        v.fail("pressure.supply_port", pressure["supply_port"], "the spool valve takes its supply input: it "
               "discharges into a line (outlet_port), it does not draw from one")
    command = pressure.get("command")
    if isinstance(command, dict) and "model" in command:
        v.fail("pressure.command.model", command["model"], "the spool valve is driven by its command itself: "
               "a PWM command's model does not apply to it")
    return SpoolValveSource(SpoolValve33(parts[0], **values), *parts[1:], outlet_port=ports.get("outlet_port", ""))
