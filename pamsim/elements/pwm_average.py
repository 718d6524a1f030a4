"""The averaged model of an on/off valve under PWM: the mean mass flow over one period.

The switching model (a ``pwm`` command on :class:`~pamsim.elements.valve.ProportionalValve33`) drives
the valve's opening ``level(t)`` in [0, 1] through a trace of straight pieces: 0 until the opening
takes effect ``delay_on_s`` after the period starts, up to 1 over ``rise_s``, held, down to 0 over
``fall_s`` from ``delay_off_s`` after the commanded close, held.  The valve's command is
``c = low + (high - low) level`` and its flow is ``|c|`` times the full orifice's flow on the side
``c`` points to (the supply for ``c > 0``, the exhaust for ``c < 0``).  With the chamber's state
frozen over one period, the mean flow is therefore exactly

    mean mdot = W_supply mdot(+1) + W_exhaust mdot(-1),
    W_supply = mean of max(c(t), 0),  W_exhaust = mean of max(-c(t), 0)

over the period: the shares of a period each path is open, weighted by its opening.  Each is a sum
over the trace's straight pieces; on a piece from command ``c1`` to ``c2`` the mean of ``max(c, 0)``
is ``(F(c2) - F(c1)) / (c2 - c1)`` with ``F(c) = max(c, 0)^2 / 2``.

With the time ``a = duty / f + delay_off_s - delay_on_s`` from the opening's to the closing's taking
effect, held within one period ``T = 1 / f``, and ``g = T - a``, the trace has one of three shapes:

* full: the valve opens and closes fully (``a >= rise_s`` and ``g >= fall_s``);
* a short pulse: the closing starts at ``lambda = a / rise_s`` open (``a < rise_s``, ``a fall_s <= g rise_s``);
* a short gap: the opening starts at ``1 - mu`` open, ``mu = g / fall_s`` (``g < fall_s``, otherwise).

For a 2/2 valve (``low = 0``, ``high = 1``) in the full shape ``W_supply`` is the mean opening, the
effective duty ``duty + f (delay_off_s - delay_on_s) + f (fall_s - rise_s) / 2``.  For a 3/2 valve
(``low = -1``) the command passes through the closed centre while it switches, and each switch
loses ``(rise_s + fall_s) / 4`` of a period from each path.  It is not the proportional valve at
command ``2 duty - 1``: the orifice's flow is not linear in the chamber pressure, so the mean of the
two paths' flows is not the flow of one path at the mean opening.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..modeling.smath import clip, fmax, if_else
from ..signals import PiecewiseConstant
from .pressure_source import ValveChamberSource
from .valve import ProportionalValve33, TwoPathValve

PWM_MODELS = ("switching", "averaged")
"""How a PWM command runs (``[pressure.command] model``): every switch as an event, or this module's
averaged valve."""
TINY_S = 1e-300
"""A duration [s] that keeps a ramp's rate finite when the ramp takes no time (that shape is not chosen then)."""


def _pos(c):
    return 0.5 * (c + abs(c))


def _mean_pos(c1, c2):
    """Mean of ``max(c, 0)`` along a straight piece from command ``c1`` to ``c2``."""
    dc = c2 - c1
    flat = abs(dc) <= 1e-12
    return if_else(flat, 0.5 * (_pos(c1) + _pos(c2)),
                   0.5 * (_pos(c2) ** 2 - _pos(c1) ** 2) / if_else(flat, 1.0, dc))


@dataclass(frozen=True)
class PwmShare:
    """The timing of a PWM command as :class:`pamsim.signals.Pwm` defines it (its frequency, its ``low`` and
    ``high`` commands, the valve's delays and opening and closing times), and each path's share of a
    period at a duty that follows from it (see the module)."""

    frequency_Hz: float
    low_command: float
    high_command: float
    delay_on_s: float = 0.0
    delay_off_s: float = 0.0
    rise_s: float = 0.0
    fall_s: float = 0.0

    @classmethod
    def of_pwm(cls, pwm) -> "PwmShare":
        """The timing of the PWM signal ``pwm`` (:class:`pamsim.signals.Pwm`)."""
        return cls(pwm.frequency_Hz, pwm.low, pwm.high, pwm.delay_on_s, pwm.delay_off_s, pwm.rise_s, pwm.fall_s)

    def share(self, duty, sign: float):
        """Mean over a period of ``max(sign c(t), 0)``: the supply path's share (+1), the exhaust's (-1)."""
        period = 1.0 / self.frequency_Hz
        r, q = self.rise_s, self.fall_s
        c0, c1 = sign * self.low_command, sign * self.high_command
        a = clip(duty * period + self.delay_off_s - self.delay_on_s, 0.0, period)
        g = period - a
        lam = clip(a / fmax(r, TINY_S), 0.0, 1.0)
        mu = clip(g / fmax(q, TINY_S), 0.0, 1.0)
        full = (r + q) * _mean_pos(c0, c1) + (a - r) * _pos(c1) + (g - q) * _pos(c0)
        c_lam = c0 + (c1 - c0) * lam
        short_pulse = (a + lam * q) * _mean_pos(c0, c_lam) + (g - lam * q) * _pos(c0)
        c_mu = c1 + (c0 - c1) * mu
        short_gap = (g + mu * r) * _mean_pos(c1, c_mu) + (a - mu * r) * _pos(c1)
        # Where the pulse's rise and the gap's fall balance (a / r = g / q) the level swings up from
        # closed, as the switching model's does from its start: a rounding must not tip it the other way.
        tie = 1e-9 * period * (r + q)
        pulse = (a < r) * (a * q <= g * r + tie)
        gap = (g < q) * (a * q > g * r + tie)
        switching = if_else(pulse, short_pulse, if_else(gap, short_gap, full)) / period
        # No switching at all at the duty's ends: the command holds low (0) or high (1) for good.
        return if_else(duty <= 0.0, _pos(c0), if_else(duty >= 1.0, _pos(c1), switching))


@dataclass(frozen=True)
class PwmAveragedValve(TwoPathValve):
    """:class:`~pamsim.elements.valve.ProportionalValve33` under a PWM command with its timing (as
    :class:`pamsim.signals.Pwm` defines it), averaged over one period; its input is the duty, and its paths'
    flows (:class:`~pamsim.elements.valve.TwoPathValve`) are their mean flows over a period at the duty."""

    valve: ProportionalValve33
    timing: PwmShare

    @classmethod
    def of_pwm(cls, valve: ProportionalValve33, pwm) -> "PwmAveragedValve":
        """The averaged ``valve`` under the PWM signal ``pwm`` (:class:`pamsim.signals.Pwm`)."""
        return cls(valve, PwmShare.of_pwm(pwm))

    @property
    def frequency_Hz(self) -> float:
        """The PWM frequency [Hz]."""
        return self.timing.frequency_Hz

    def shares(self, duty) -> tuple:
        """``(W_supply, W_exhaust)``: each path's opening averaged over a period at ``duty`` (see the module)."""
        return self.timing.share(duty, 1.0), self.timing.share(duty, -1.0)


@dataclass(frozen=True)
class _PairAtInletDuty(TwoPathValve):
    """Two 2/2 on/off valves (:class:`~pamsim.elements.valve.OnOffValvePair`) averaged over a period of the
    inlet's PWM command (``inlet``, from 0 to 1) at its duty, the input; the exhaust's share is the subclass's."""

    valve: ProportionalValve33
    inlet: PwmShare

    @property
    def frequency_Hz(self) -> float:
        """The inlet's PWM frequency [Hz]."""
        return self.inlet.frequency_Hz

    def shares(self, duty) -> tuple:
        """``(W_supply, W_exhaust)``: each valve's opening averaged over a period at the inlet's ``duty``."""
        return self.inlet.share(duty, 1.0), self.exhaust_share_at(duty)


@dataclass(frozen=True)
class AveragedValvePair(_PairAtInletDuty):
    """The pair under PWM, the exhaust under the inlet's complementary command (``exhaust``, from 1 down to 0
    with its own delays and times, :func:`pamsim.signals.complementary`), both at the inlet's duty, each
    path's share derived from its own valve's trace."""

    exhaust: PwmShare

    def exhaust_share_at(self, duty):
        """The exhaust's opening averaged over a period at the inlet's ``duty``."""
        return self.exhaust.share(duty, 1.0)


@dataclass(frozen=True)
class AveragedInletPair(_PairAtInletDuty):
    """The pair at the inlet's duty, the exhaust open a fixed ``exhaust_share`` of the time (its own command's
    mean opening while the inlet's PWM runs): the model ``pamsim linearize`` takes of a pair whose exhaust
    has a command of its own."""

    exhaust_share: float

    def exhaust_share_at(self, duty):
        """The exhaust's share, whatever the inlet's duty."""
        return self.exhaust_share


def mean_opening_signal(pwm) -> PiecewiseConstant:
    """A 2/2 valve's opening under the PWM command ``pwm`` (from 0 to 1, with its timing) averaged over a
    period (its share, :meth:`PwmShare.share`) from the command's start to its end, closed before and after:
    the averaged model of one valve of a pair whose other valve has a command of its own.  Each valve's flow
    is its opening times its full orifice's, so the pair's mean flow with the chamber's state frozen over a
    period is the pair's flow at the two mean openings, whatever the two commands' frequencies and phases."""
    share = float(PwmShare.of_pwm(pwm).share(pwm.duty, 1.0))
    if pwm.start_s > 0.0:
        return PiecewiseConstant((0.0, pwm.start_s, pwm.end_s), (0.0, share, 0.0))
    return PiecewiseConstant((pwm.start_s, pwm.end_s), (share, 0.0))


def duty_signal(pwm) -> PiecewiseConstant:
    """The duty the averaged valve takes in place of the PWM command ``pwm``: ``pwm.duty`` from its start
    to its end, 0 (the valve held at its ``low`` command) before and after."""
    if pwm.start_s > 0.0:
        return PiecewiseConstant((0.0, pwm.start_s, pwm.end_s), (0.0, pwm.duty, 0.0))
    return PiecewiseConstant((pwm.start_s, pwm.end_s), (pwm.duty, 0.0))


@dataclass(frozen=True)
class AveragedPwmSource(ValveChamberSource):
    """A :class:`ValveChamberSource` whose valve is a :class:`PwmAveragedValve` and whose command is the
    duty (:func:`duty_signal`): the averaged model of the switching source it was made from."""

    @property
    def duty(self) -> float:
        """The duty the command holds while the PWM runs (0 before and after)."""
        return max(self.command.values)

    def balance_pressure_Pa(self, duty: float, T_chamber_K: float) -> float:
        """The absolute chamber pressure [Pa] at which the two paths' mean flows cancel at ``duty`` (gas at
        ``T_chamber_K``): the supply's while only the supply path opens, the exhaust's while only the
        exhaust path does.

        Raises
        ------
        ValueError
            If neither path ever opens at ``duty`` (a 2/2 valve at duty 0): any pressure is held.
        """
        from scipy.optimize import brentq

        p_supply = float(self.supply_gauge_Pa.final_value) + self.p_atm_Pa
        w_supply, w_exhaust = self.valve.shares(duty)
        if w_supply == 0.0 and w_exhaust == 0.0:
            raise ValueError(f"at duty {duty:g} the valve never opens: every pressure is held")
        if w_exhaust == 0.0 or w_supply == 0.0:
            return p_supply if w_exhaust == 0.0 else self.p_atm_Pa

        def flow(p):
            return self.valve.inflow_kg_s(duty, p, T_chamber_K, p_supply, self.T_supply_K, self.p_atm_Pa)

        return float(brentq(flow, self.p_atm_Pa, p_supply, xtol=1e-9, rtol=1e-14))

    def derivatives(self, s, x_m, v_m_s, inputs) -> tuple[float, float]:
        """(dp/dt [Pa/s], dm/dt [kg/s]) of the chamber, each path's flow carrying its own temperature."""
        duty, supply_gauge_Pa = inputs
        return chamber_rates_of_paths(self, s, x_m, v_m_s, duty, supply_gauge_Pa)


def chamber_rates_of_paths(source, s, x_m, v_m_s, opening, supply_gauge_Pa) -> tuple[float, float]:
    """(dp/dt [Pa/s], dm/dt [kg/s]) of ``source``'s chamber (states ``s[0]``, ``s[1]``) fed by a valve with a
    supply and an exhaust path open at once (``source.valve.path_flows_kg_s(opening, ...)``: the averaged
    PWM valve at its duty, a spool valve at its position), each path's flow carrying its own temperature."""
    p, m = s[0], s[1]
    chamber = source.chamber
    V = chamber.volume_m3(x_m)
    T_gas = chamber.gas_temperature_K(p, V, m)
    flows = source.valve.path_flows_kg_s(opening, p, T_gas, supply_gauge_Pa + source.p_atm_Pa, source.T_supply_K,
                                         source.p_atm_Pa)
    work = sum(chamber.flow_work_W(float(mdot), source.T_supply_K if mdot >= 0.0 else T_gas) for mdot in flows)
    mdot = float(sum(flows))
    dV = chamber.dvolume_dx_m2(x_m) * v_m_s
    return chamber.pressure_rate_of_flows_Pa_s(p, V, dV, mdot, work, m, x_m), mdot


def averaged_source(source: ValveChamberSource, pwm, exhaust_pwm=None) -> AveragedPwmSource:
    """The averaged model of ``source`` driven by the PWM command ``pwm`` (:class:`pamsim.signals.Pwm`); with
    ``exhaust_pwm`` (the complementary command of a pair of 2/2 valves), of the pair (:class:`AveragedValvePair`:
    ``source.valve`` holds the inlet's and the exhaust's orifices)."""
    valve = (PwmAveragedValve.of_pwm(source.valve, pwm) if exhaust_pwm is None
             else AveragedValvePair(source.valve, PwmShare.of_pwm(pwm), PwmShare.of_pwm(exhaust_pwm)))
    return AveragedPwmSource(valve, source.chamber, source.supply_gauge_Pa, duty_signal(pwm), source.T_supply_K,
                             source.p_atm_Pa)
