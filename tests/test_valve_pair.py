"""On/off solenoid valves with their own ISO 6358 (C, b) per path: the 3/2 valve's per-path keys
(``[pressure] supply_C_m3_per_s_Pa`` ...) and two 2/2 valves (``[pressure.inlet]``, ``[pressure.exhaust]``).

Each check is against a result found without the valves' code: the ISO 6358 formula written here, the
sum of two such formulas while both valves are open, the air mass held exactly while both are shut (the
switches' lateness), the switching traces integrated piece by piece, a balance pressure solved here from
the formula, switching runs whose frequency rises, and the backends against each other.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import pamsim
from conftest import SCENARIOS, assert_refused
from pamsim.signals import OnOff, Pwm, complementary

PWM_ONOFF = SCENARIOS / "pwm_onoff.toml"
BASE = pamsim.load_scenario(PWM_ONOFF)
PAR = BASE.parameters
P_ATM, TS = PAR["p_atm_Pa"], PAR["T_supply_K"]
P_SUPPLY = BASE.final_pressure_gauge_Pa + P_ATM
NO_TIMING = {"delay_on_s": 0.0, "delay_off_s": 0.0, "rise_s": 0.0, "fall_s": 0.0}


def _iso6358_kg_s(p_up, p_down, T_up, C, b, lam=None, rho0=None, T0=None):
    """ISO 6358 mass flow from ``p_up`` to ``p_down`` (p_up >= p_down), with the linear laminar branch above the
    ratio ``lam`` (Simscape's), written from the standard: ``C rho0 p_up sqrt(T0/T_up)`` choked below ``b``,
    times ``sqrt(1 - ((r - b)/(1 - b))^2)`` above it."""
    lam = PAR["valve_laminar_ratio"] if lam is None else lam
    rho0 = PAR["rho0_kg_m3"] if rho0 is None else rho0
    T0 = PAR["T0_K"] if T0 is None else T0
    r = p_down / p_up
    s = max(min(r, lam) - b, 0.0) / (1.0 - b)
    return C * rho0 * p_up * math.sqrt(T0 / T_up) * math.sqrt(1.0 - s * s) * min(1.0, (1.0 - r) / (1.0 - lam))


def _signed(p_chamber, T_gas, p_port, C, b):
    """Mass flow into the chamber through an open path to ``p_port`` (air from the port at the supply's
    temperature, from the chamber at the gas's)."""
    if p_port >= p_chamber:
        return _iso6358_kg_s(p_port, p_chamber, TS, C, b) if p_port > p_chamber else 0.0
    return -_iso6358_kg_s(p_chamber, p_port, T_gas, C, b)


def _pair(inlet: dict, exhaust: dict, inlet_command: dict, exhaust_command: dict, **sim) -> pamsim.Scenario:
    """:data:`BASE` with the inlet's and exhaust's tables (C, b, timing) and commands replaced."""
    return BASE.with_changes({"pressure": {"inlet": {**inlet, "command": inlet_command},
                                           "exhaust": {**exhaust, "command": exhaust_command}},
                              "simulation": {"duration_s": 1.6, "sample_rate_Hz": 10000.0, **sim}})


# ---------------------------------------------------------------- per-path (C, b) against the formula


DIFFERENT = ({"C_m3_per_s_Pa": 8e-10, "b": 0.25, **NO_TIMING}, {"C_m3_per_s_Pa": 3e-10, "b": 0.45, **NO_TIMING})
"""An inlet and an exhaust valve of different (C, b)."""


@pytest.mark.parametrize("backend", ["python", "native"])
def test_both_valves_open_at_once_flow_the_sum_of_their_formulas(backend):
    """Both valves open from 0.1 s (the inlet at 0.1 s, the exhaust at 0.3 s: first the inlet alone): at
    every sample the valves' net flow is the inlet's ISO 6358 flow with its own (C, b) plus the exhaust's with
    its own, each from the formula above at the sample's chamber pressure and gas temperature; the chamber
    settles between supply and ambient where the two cancel (no single valve would rest there)."""
    inlet, exhaust = DIFFERENT
    sc = _pair(inlet, exhaust, {"kind": "step", "time_s": 0.1, "final": 1.0},
               {"kind": "step", "time_s": 0.3, "final": 1.0})
    res = pamsim.simulate(sc, backend=backend)
    got, want = [], []
    for k in range(0, len(res.t_s), 37):
        p, T = res.p_gauge_Pa[k] + P_ATM, res.signals["gas_temperature_K"][k]
        on_in, on_ex = res.signals["valve_command"][k], res.signals["exhaust_command"][k]
        want.append(on_in * _signed(p, T, P_SUPPLY, inlet["C_m3_per_s_Pa"], inlet["b"])
                    + on_ex * _signed(p, T, P_ATM, exhaust["C_m3_per_s_Pa"], exhaust["b"]))
        got.append(res.signals["valve_mass_flow_kg_s"][k])
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-15)
    both = res.t_s > 0.3
    assert np.all(res.signals["exhaust_command"][both] == 1.0) and np.all(res.signals["valve_command"][both] == 1.0)
    p_end = res.p_gauge_Pa[-1] + P_ATM
    balance = brentq(lambda p: _signed(p, TS, P_SUPPLY, 8e-10, 0.25) + _signed(p, TS, P_ATM, 3e-10, 0.45),
                     P_ATM + 1.0, P_SUPPLY - 1.0, xtol=1e-6)
    assert P_ATM + 1e5 < p_end < P_SUPPLY - 1e4
    assert p_end == pytest.approx(balance, abs=50.0)  # the gas near the supply's temperature: within 50 Pa


@pytest.mark.parametrize("backend", ["python", "native"])
def test_a_3_2_valve_uses_each_paths_own_c_and_b(backend):
    """The 3/2 valve with ``[pressure]`` per-path keys, open to the supply at 0.2 s and to the exhaust from 0.8 s:
    each sample's flow is the formula with the supply path's (C, b) while it fills and the exhaust path's
    while it vents."""
    sc = pamsim.load_scenario(SCENARIOS / "pwm_3_2.toml").with_changes({
        "pressure": {"command": {"kind": "steps", "times_s": [0.2, 0.8], "values": [1.0, -1.0]},
                     "supply_C_m3_per_s_Pa": 7e-10, "supply_b": 0.2, "exhaust_C_m3_per_s_Pa": 4e-10, "exhaust_b": 0.5},
        "simulation": {"duration_s": 1.5}})
    res = pamsim.simulate(sc, backend=backend)
    fills = vents = 0
    for k in range(0, len(res.t_s), 23):
        p, T, u = res.p_gauge_Pa[k] + P_ATM, res.signals["gas_temperature_K"][k], res.signals["valve_command"][k]
        want = 0.0 if u == 0 else (_signed(p, T, P_SUPPLY, 7e-10, 0.2) if u > 0 else _signed(p, T, P_ATM, 4e-10, 0.5))
        fills, vents = fills + (u > 0), vents + (u < 0)
        assert res.signals["valve_mass_flow_kg_s"][k] == pytest.approx(want, rel=1e-9, abs=1e-15), res.t_s[k]
    assert fills > 50 and vents > 50


def test_per_path_keys_equal_to_the_muscles_valve_give_its_run():
    """Per-path (C, b) set to the muscle's own valve's: the same run as without them (the other code path
    evaluates both orifices and takes one), to 1e-9 m and 1e-3 Pa."""
    base = pamsim.load_scenario(SCENARIOS / "pwm_3_2.toml").with_changes({"simulation": {"duration_s": 1.5}})
    same = base.with_changes({"pressure": {"supply_C_m3_per_s_Pa": PAR["valve_C_m3_per_s_Pa"], "supply_b": PAR["valve_b"],
                                           "exhaust_C_m3_per_s_Pa": PAR["valve_C_m3_per_s_Pa"]}})
    a, b = pamsim.simulate(base), pamsim.simulate(same)
    assert np.max(np.abs(a.x_m - b.x_m)) < 1e-9 and np.max(np.abs(a.p_gauge_Pa - b.p_gauge_Pa)) < 1e-3


def test_a_spools_leakage_is_a_share_of_each_paths_own_c():
    """A spool valve whose exhaust path has its own C: at position 0.6 with overlap 0.2 the supply path opens
    (0.6 - 0.2) / 0.8 = 0.5 of its stroke, and the leakage of 1e-11 m^3/(s Pa) is 1e-11 / 1e-9 = 0.01 of the
    supply path's C and 1e-11 / 4e-10 = 0.025 of the exhaust path's."""
    from pamsim.elements.spool import SpoolValve33
    from pamsim.elements.valve import Iso6358Orifice, ProportionalValve33

    supply = Iso6358Orifice(1e-9, 0.3, 0.999, 1.185, 293.15)
    exhaust = Iso6358Orifice(4e-10, 0.4, 0.999, 1.185, 293.15)
    spool = SpoolValve33(ProportionalValve33(supply, exhaust), 125.0, 0.7, 0.2, 1e-11)
    assert spool.shares(0.6) == pytest.approx((0.51, 0.025), abs=1e-15)


# ---------------------------------------------------------------- the switches: exact on both valves


def _phased_pair() -> pamsim.Scenario:
    """The inlet under 50 Hz PWM at 40 % from 0.5 s (open 0.5 + 0.02 k to + 0.008), the exhaust under its own
    50 Hz PWM at 20 % from 0.51 s (open 0.51 + 0.02 k to + 0.004): between them both valves are shut, twice a
    period.  Valves of different (C, b), switching at once; sampled at 10 kHz, on every switch."""
    inlet, exhaust = DIFFERENT
    pwm = {"kind": "pwm", "frequency_Hz": 50.0}
    return _pair(inlet, exhaust, {**pwm, "start_s": 0.5, "end_s": 1.5, "duty": 0.4},
                 {**pwm, "start_s": 0.51, "end_s": 1.51, "duty": 0.2}, duration_s=1.6)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_both_valves_switch_exactly(backend):
    """While both valves are shut the air mass must stay what it was at the last close: a step past a
    close by dt would go on filling (or venting) by the flow times dt, and a step into an opening early
    would change it before the opening.  The change over each shut interval, divided by the flow just
    before it began, bounds each valve's lateness below 1e-9 s at all 50 closes of each valve; and each
    interval ends with the mass unchanged up to the opening's sample."""
    res = pamsim.simulate(_phased_pair(), backend=backend)
    m, mdot = res.signals["air_mass_kg"], res.signals["valve_mass_flow_kg_s"]
    rate = 10000
    for k in range(50):
        t0 = 0.5 + 0.02 * k
        for close, reopen, sign in ((t0 + 0.008, t0 + 0.010, 1.0), (t0 + 0.014, t0 + 0.020, -1.0)):
            i, j = round(close * rate), round(reopen * rate)
            assert sign * mdot[i - 1] > 0.0, (k, close)
            late_s = np.max(np.abs(m[i:j + 1] - m[i])) / abs(mdot[i - 1])
            assert late_s < 1e-9, (k, close, late_s)
            assert np.all(mdot[i + 1:j] == 0.0)


def test_the_pairs_openings_follow_their_commands_and_timing():
    """The inlet's opening under a PWM with 2 ms dead times and 1 ms / 3 ms opening and closing times, and
    the complementary exhaust's under its own 1 ms dead times and 2 ms times, written out by hand over one
    10 ms pulse at 1.0 s (50 Hz, 50 %)."""
    inlet = Pwm(1.0, 1.02, 50.0, 0.5, delay_on_s=0.002, delay_off_s=0.002, rise_s=0.001, fall_s=0.003)
    exhaust = complementary(inlet, delay_on_s=0.001, delay_off_s=0.001, rise_s=0.002, fall_s=0.002)
    # inlet: shut until 1.002, open at 1.003, closing from 1.012, shut at 1.015
    want_in = {0.5: 0.0, 1.002: 0.0, 1.0025: 0.5, 1.003: 1.0, 1.012: 1.0, 1.0135: 0.5, 1.015: 0.0}
    # exhaust: open until 1.001, shut at 1.003; opening from 1.011, open at 1.013
    want_ex = {0.5: 1.0, 1.001: 1.0, 1.002: 0.5, 1.003: 0.0, 1.011: 0.0, 1.012: 0.5, 1.013: 1.0, 1.05: 1.0}
    assert [inlet(t) for t in want_in] == pytest.approx(list(want_in.values()), abs=1e-9)
    assert [exhaust(t) for t in want_ex] == pytest.approx(list(want_ex.values()), abs=1e-9)
    boolean = OnOff(((0.3, 1), (0.7, 0)), 0.0, delay_on_s=0.01, rise_s=0.02)
    inverse = complementary(boolean, fall_s=0.004)
    assert [boolean(t) for t in (0.3, 0.31, 0.32, 0.33, 0.7, 0.71)] == pytest.approx([0, 0, 0.5, 1, 0, 0])
    assert [inverse(t) for t in (0.0, 0.3, 0.302, 0.304, 0.7)] == pytest.approx([1, 1, 0.5, 0, 1])


# ---------------------------------------------------------------- the averaged pair


def _trace_mean(signal, frequency_Hz: float, periods_in: int = 10) -> float:
    """Mean of an opening (0 to 1) over one period ``periods_in`` periods after 1.0 s, by the trapezoid rule
    on its knots: exact for a trace of straight pieces."""
    T = 1.0 / frequency_Hz
    lo, hi = 1.0 + periods_in * T, 1.0 + (periods_in + 1) * T
    t = np.array(signal.knots_t_s)
    times = [lo, *t[(t > lo) & (t < hi)], hi]
    total = 0.0
    for t0, t1 in zip(times[:-1], times[1:]):
        if t1 > t0:
            total += (t1 - t0) * (signal(t0) + signal(math.nextafter(t1, -math.inf))) / 2.0
    return total / T


@pytest.mark.parametrize("duty", [0.05, 0.3, 0.5, 0.8, 0.85])
@pytest.mark.parametrize("timing_in, timing_ex", [
    ((0.002, 0.002, 0.002, 0.002), (0.002, 0.002, 0.002, 0.002)),
    ((0.001, 0.003, 0.0005, 0.002), (0.002, 0.0005, 0.003, 0.001)),
    ((0.0, 0.0, 0.0, 0.0), (0.003, 0.001, 0.0, 0.004)),
])
def test_averaged_pair_shares_are_the_switching_traces_means(duty, timing_in, timing_ex):
    """Each path's share of the averaged pair at a duty (the exhaust's from its own complementary trace, with
    its own timing) against the switching openings' traces integrated over a period, to 1e-12; over every
    shape (full pulses, a short gap), the delays differing by less than the commanded open and closed times
    (the averaged model's range, docs/pneumatics.md)."""
    from pamsim.elements.pwm_average import AveragedValvePair, PwmShare

    keys = ("delay_on_s", "delay_off_s", "rise_s", "fall_s")
    inlet = Pwm(1.0, 2.0, 50.0, duty, **dict(zip(keys, timing_in)))
    exhaust = complementary(inlet, **dict(zip(keys, timing_ex)))
    pair = AveragedValvePair(None, PwmShare.of_pwm(inlet), PwmShare.of_pwm(exhaust))
    w_in, w_ex = pair.shares(duty)
    assert float(w_in) == pytest.approx(_trace_mean(inlet, 50.0), abs=1e-12)
    assert float(w_ex) == pytest.approx(_trace_mean(exhaust, 50.0), abs=1e-12)


def _mean_gauge_Pa(scenario, frequency_Hz: float, t0: float = 4.5, t1: float = 5.0) -> float:
    """Mean chamber gauge pressure over the whole periods from ``t0`` to ``t1`` (trapezoid rule)."""
    res = pamsim.simulate(scenario, backend="native")
    n = round((t1 - t0) * frequency_Hz)
    w = (res.t_s >= t0 - 1e-12) & (res.t_s <= t0 + n / frequency_Hz + 1e-12)
    return float(np.trapezoid(res.p_gauge_Pa[w], res.t_s[w]) / (res.t_s[w][-1] - res.t_s[w][0]))


def _balanced_pair(frequency_Hz: float, model: str, duty: float = 0.5,
                   weight_N: float | None = None) -> pamsim.Scenario:
    """The pair of different valves (switching at once), the inlet under PWM, the exhaust complementary;
    ``weight_N`` in place of the scenario's load, if given."""
    inlet, exhaust = DIFFERENT
    sc = _pair(inlet, exhaust, {"kind": "pwm", "start_s": 0.5, "end_s": 5.5, "frequency_Hz": frequency_Hz,
                                "duty": duty, "model": model}, {"kind": "complementary"},
               duration_s=5.0, sample_rate_Hz=50000.0)
    return sc if weight_N is None else sc.with_changes({"load": {"weight_N": weight_N}})


HELD_N = 200.0
"""A weight the muscle cannot lift at the pair's pressures (it rests on its lower stop): the chamber's volume
stays fixed.  Under the scenario's own load the ripple ratchets the load up a little every period, by
amounts that follow the integrator's stick/slip path (a few micrometres apart between the backends), and
the volume's share of the mean pressure hid the switching's own."""


def test_switching_pairs_mean_pressure_tends_to_the_averaged_pairs():
    """The pair of different valves at duty 0.5, the load held (:data:`HELD_N`): the averaged run settles (the
    gas at the supply's temperature) at the pressure where ``0.5 q_in(p) = 0.5 q_ex(p)``, solved here from the
    formula, within 1 Pa (the small exhaust valve takes seconds to settle it).  The switching runs' mean
    pressure over 4.5-5 s comes closer to it at each step of 50, 200 and 1000 Hz, by at least 1/f^2 from
    200 to 1000 Hz (measured 327, 20.4 and 0.82 Pa: 25.0 times from 200 to 1000 Hz), to below 1 Pa at
    1000 Hz."""
    assert pamsim.simulate(_balanced_pair(1000.0, "switching", weight_N=HELD_N), backend="native").x_m.max() == 0.0
    averaged = _mean_gauge_Pa(_balanced_pair(50.0, "averaged", weight_N=HELD_N), 50.0)
    balance = brentq(lambda p: _signed(p, TS, P_SUPPLY, 8e-10, 0.25) + _signed(p, TS, P_ATM, 3e-10, 0.45),
                     P_ATM + 1.0, P_SUPPLY - 1.0, xtol=1e-6) - P_ATM
    assert averaged == pytest.approx(balance, abs=1.0)
    gaps = [abs(_mean_gauge_Pa(_balanced_pair(f, "switching", weight_N=HELD_N), f) - averaged)
            for f in (50.0, 200.0, 1000.0)]
    print(f"different valves: |switching - averaged| mean pressure {gaps[0]:.0f}, {gaps[1]:.1f}, {gaps[2]:.2f} Pa at "
          f"50, 200, 1000 Hz ({gaps[1] / gaps[2]:.1f} times from 200 to 1000 Hz)")
    assert gaps[0] > gaps[1] > gaps[2], gaps
    assert gaps[1] / gaps[2] >= 0.8 * 5.0 ** 2, gaps
    assert gaps[2] < 1.0, gaps


def _own_exhaust_pair(frequency_Hz: float, model: str, exhaust_command: dict | None = None) -> pamsim.Scenario:
    """The pair of different valves (switching at once) on the held load (:data:`HELD_N`), the inlet under PWM at
    0.6, the exhaust under a PWM of its own at 0.3 of the same frequency (both open at each period's start),
    or under ``exhaust_command``; both commands run by ``model``."""
    inlet, exhaust = DIFFERENT
    pwm = {"kind": "pwm", "start_s": 0.5, "end_s": 5.5, "frequency_Hz": frequency_Hz, "model": model}
    sc = _pair(inlet, exhaust, {**pwm, "duty": 0.6}, exhaust_command or {**pwm, "duty": 0.3},
               duration_s=5.0, sample_rate_Hz=50000.0)
    return sc.with_changes({"load": {"weight_N": HELD_N}})


def _balance_gauge_Pa(w_in: float, w_ex: float) -> float:
    """The gauge pressure where ``w_in q_in(p) + w_ex q_ex(p) = 0`` for the valves :data:`DIFFERENT` (gas at the
    supply's temperature), from the formula written here."""
    return brentq(lambda p: w_in * _signed(p, TS, P_SUPPLY, 8e-10, 0.25) + w_ex * _signed(p, TS, P_ATM, 3e-10, 0.45),
                  P_ATM + 1.0, P_SUPPLY - 1.0, xtol=1e-6) - P_ATM


def test_an_exhaust_with_a_pwm_of_its_own_averages_by_its_mean_opening():
    """Inlet at duty 0.6 and exhaust at 0.3, each under its own PWM with ``model = "averaged"``: the averaged run
    opens each valve by its duty (no switching times) and settles where ``0.6 q_in(p) + 0.3 q_ex(p) = 0``,
    solved here from the formula, within 1 Pa.  The switching runs' mean pressure over 4.5-5 s comes closer
    to it at each of 50, 200 and 1000 Hz, at least as 1/f from 200 to 1000 Hz (measured 792, 212 and 43 Pa:
    4.9 times; the complementary pair's came as 1/f^2), to below 50 Pa at 1000 Hz."""
    averaged = pamsim.simulate(_own_exhaust_pair(50.0, "averaged"), backend="native")
    assert set(np.unique(averaged.signals["valve_command"])) == {0.0, 0.6}
    assert set(np.unique(averaged.signals["exhaust_command"])) == {0.0, 0.3}
    mean = _mean_gauge_Pa(_own_exhaust_pair(50.0, "averaged"), 50.0)
    assert mean == pytest.approx(_balance_gauge_Pa(0.6, 0.3), abs=1.0)
    gaps = [abs(_mean_gauge_Pa(_own_exhaust_pair(f, "switching"), f) - mean) for f in (50.0, 200.0, 1000.0)]
    print(f"own exhaust: |switching - averaged| mean pressure {gaps[0]:.0f}, {gaps[1]:.0f}, {gaps[2]:.0f} Pa at "
          f"50, 200, 1000 Hz ({gaps[1] / gaps[2]:.1f} times from 200 to 1000 Hz)")
    assert gaps[0] > gaps[1] > gaps[2], gaps
    assert gaps[1] / gaps[2] >= 0.8 * 5.0, gaps
    assert gaps[2] < 50.0, gaps


def test_an_averaged_inlet_with_an_exhaust_held_open_settles_at_the_balance():
    """The inlet under PWM at 0.6 run averaged, the exhaust open throughout (a constant command): the chamber
    settles where ``0.6 q_in(p) + q_ex(p) = 0``, within 1 Pa, on python and native."""
    sc = _own_exhaust_pair(50.0, "averaged", {"kind": "constant", "value": 1.0})
    for backend in ("python", "native"):
        res = pamsim.simulate(sc, backend=backend)
        assert res.p_gauge_Pa[-1] == pytest.approx(_balance_gauge_Pa(0.6, 1.0), abs=1.0), backend


def test_linearize_on_the_pair_rests_at_the_formulas_balance(tmp_path, cli):
    """``pamsim linearize`` of the pair linearises its averaged model: the operating point's pressure is the
    balance of the two valves' formulas at the effective duties (equal 2 ms timing: 0.5 each), to 0.1 mbar."""
    text = cli("linearize", PWM_ONOFF, "--json", "-o", tmp_path)
    assert text.returncode == 0, text.stderr
    rep, _ = json.JSONDecoder().raw_decode(text.stdout)
    assert rep["inputs"][0] == "pwm_duty" and "inlet and exhaust 2/2 valves" in rep["valve_model"]
    assert rep["operating_point"]["kind"] == "pwm_averaged"
    C, b = 5.5e-10, 0.3
    balance = brentq(lambda p: _signed(p, TS, P_SUPPLY, C, b) + _signed(p, TS, P_ATM, C, b), P_ATM + 1.0,
                     P_SUPPLY - 1.0, xtol=1e-6) - P_ATM
    assert rep["operating_point"]["states"][2] - P_ATM == pytest.approx(balance, abs=10.0)


# ---------------------------------------------------------------- every backend


@pytest.mark.parametrize("model", ["switching", "averaged", "averaged, own exhaust"])
def test_every_backend_runs_the_pair_alike(model):
    """python, native, fmu-cs and fmu-me run ``pwm_onoff.toml`` (1.5 s) alike: contraction within 1e-5 m and
    pressure within 100 Pa of the python run at every sample, and the same switches seen in the exhaust's
    opening; also with the exhaust under a 30 Hz PWM of its own at 0.4, both run averaged."""
    inlet = BASE.spec["pressure"]["inlet"]
    exhaust = BASE.spec["pressure"]["exhaust"]
    own = model == "averaged, own exhaust"
    changes = {"inlet": {**inlet, "command": {**inlet["command"], "model": model.split(",")[0]}}}
    if own:
        changes["exhaust"] = {**exhaust, "command": {"kind": "pwm", "start_s": 0.2, "end_s": 1.2, "frequency_Hz": 30.0,
                                                     "duty": 0.4, "model": "averaged"}}
    sc = BASE.with_changes({"pressure": changes, "simulation": {"duration_s": 1.5}})
    runs = {b: pamsim.simulate(sc, backend=b) for b in ("python", "native", "fmu-cs", "fmu-me")}
    py = runs["python"]
    assert py.x_m.max() > 0.005
    for b, r in runs.items():
        assert np.max(np.abs(r.x_m - py.x_m)) < 1e-5, b
        assert np.max(np.abs(r.p_gauge_Pa - py.p_gauge_Pa)) < 100.0, b
        if model == "switching":
            np.testing.assert_array_equal(r.signals["exhaust_command"], py.signals["exhaust_command"])


# ---------------------------------------------------------------- bad input


def _bad(tmp_path, *changes: tuple[str, str]):
    """``pwm_onoff.toml`` with each ``(old, new)`` of ``changes`` made once, written to ``tmp_path``."""
    text = PWM_ONOFF.read_text()
    for old, new in changes:
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return path


AVERAGED = ("duty = 0.5\n", 'duty = 0.5\nmodel = "averaged"\n')


@pytest.mark.parametrize("old, new, key", [
    ("C_m3_per_s_Pa = 5.5e-10\n", "C_m3_per_s_Pa = 0.0\n", "pressure.inlet.C_m3_per_s_Pa"),
    ("C_m3_per_s_Pa = 5.5e-10\nb = 0.3\ndelay_on_s = 0.002\ndelay_off_s = 0.002\nrise_s = 0.002\nfall_s = 0.002\n\n"
     "[pressure.exhaust.command]", "C_m3_per_s_Pa = -1e-9\nb = 0.3\n\n[pressure.exhaust.command]",
     "pressure.exhaust.C_m3_per_s_Pa"),
    ("b = 0.3\n", "b = 1.0\n", "pressure.inlet.b"),
    ("b = 0.3\n", "b = -0.1\n", "pressure.inlet.b"),
    ("duty = 0.5\n", "duty = 1.5\n", "pressure.inlet.command.duty"),
    ("duty = 0.5\n", "duty = -0.2\n", "pressure.inlet.command.duty"),
    ("frequency_Hz = 50.0", "frequency_Hz = 0.0", "pressure.inlet.command.frequency_Hz"),
    ("frequency_Hz = 50.0", "frequency_Hz = 2000.0", "pressure.inlet.command.frequency_Hz"),
    ("delay_on_s = 0.002\n", "delay_on_s = -0.002\n", "pressure.inlet.delay_on_s"),
    ("fall_s = 0.002\n", "fall_s = 0.002\nopen_s = 1.0\n", "pressure.inlet.open_s"),
    ('kind = "pwm"', 'kind = "sine"', "pressure.inlet.command.kind"),
    ('kind = "complementary"', 'kind = "inverse"', "pressure.exhaust.command.kind"),
    ('kind = "pwm"', 'kind = "complementary"', "pressure.inlet.command.kind"),
    ('kind = "complementary"', 'kind = "complementary"\nduty = 0.5', "pressure.exhaust.command.duty"),
    ("duty = 0.5\n", "duty = 0.5\nrise_s = 0.001\n", "pressure.inlet.command.rise_s"),
    ("duty = 0.5\n", "duty = 0.5\nlow = -1.0\n", "pressure.inlet.command.low"),
    ('kind = "complementary"', 'kind = "step"\ntime_s = 1.0\nfinal = 0.5', "pressure.exhaust.command.final = 0.5"),
    ('kind = "complementary"', 'kind = "steps"\ntimes_s = [1.0, 2.0]\nvalues = [1, 0.5]',
     "pressure.exhaust.command.values[1] = 0.5"),
    ("duty = 0.5\n", 'duty = 0.5\nmodel = "mean"\n', "pressure.inlet.command.model"),
    ('[pressure.inlet]\n', '[pressure.inlet]\nfoo = 1\n', "pressure.inlet.foo"),
    ('supply_gauge_bar = 3.6\n', 'supply_gauge_bar = 3.6\nvalve_open_time_s = 1.0\n', "pressure.valve_open_time_s"),
])
@pytest.mark.parametrize("command", ["run", "linearize"])
def test_bad_valve_input_exits_2_naming_the_key(tmp_path, cli, old, new, key, command):
    """Each refusal: exit 2, one line naming the key, nothing written."""
    assert_refused(cli(command, _bad(tmp_path, (old, new)), "-o", tmp_path / "out"), key, tmp_path / "out")


@pytest.mark.parametrize("exhaust, share", [
    ('kind = "pwm"\nstart_s = 0.5\nend_s = 4.5\nfrequency_Hz = 30.0\nduty = 0.3\nmodel = "averaged"', 0.3),
    ('kind = "constant"\nvalue = 1.0', 1.0)], ids=["own averaged PWM", "held open"])
def test_linearize_takes_an_exhaust_of_its_own_at_its_share(tmp_path, cli, exhaust, share):
    """``pamsim linearize`` of the pair whose exhaust has a command of its own (the inlet at duty 0.6): the pair
    averaged at the inlet's duty, the exhaust open its share (equal 2 ms timing: the duty); the operating
    point's pressure is where ``0.6 q_in(p) + share q_ex(p) = 0``, solved here from the formula, to 10 Pa."""
    path = _bad(tmp_path, ('kind = "complementary"', exhaust), ("duty = 0.5\n", "duty = 0.6\n"))
    text = cli("linearize", path, "--json", "-o", tmp_path)
    assert text.returncode == 0, text.stderr
    rep, _ = json.JSONDecoder().raw_decode(text.stdout)
    assert rep["inputs"][0] == "pwm_duty" and f"exhaust open {share:g} of the time" in rep["valve_model"]
    C, b = 5.5e-10, 0.3
    balance = brentq(lambda p: 0.6 * _signed(p, TS, P_SUPPLY, C, b) + share * _signed(p, TS, P_ATM, C, b),
                     P_ATM + 1.0, P_SUPPLY - 1.0, xtol=1e-6) - P_ATM
    assert rep["operating_point"]["states"][2] - P_ATM == pytest.approx(balance, abs=10.0)


def test_linearize_refuses_an_exhaust_whose_opening_changes_under_the_inlets_pwm(tmp_path, cli):
    """An exhaust under a switching PWM of its own, or stepping while the inlet's PWM runs, has no share to
    stand for it: ``pamsim linearize`` exits 2 naming its kind."""
    for exhaust in ('kind = "pwm"\nstart_s = 0.5\nend_s = 4.5\nfrequency_Hz = 30.0\nduty = 0.3',
                    'kind = "step"\ntime_s = 2.0\ninitial = 0\nfinal = 1'):
        path = _bad(tmp_path, ('kind = "complementary"', exhaust))
        assert_refused(cli("linearize", path, "-o", tmp_path / "out"), "pressure.exhaust.command.kind",
                       tmp_path / "out")


@pytest.mark.parametrize("key, value, message", [
    ("supply_C_m3_per_s_Pa", 0.0, "pressure.supply_C_m3_per_s_Pa"),
    ("exhaust_C_m3_per_s_Pa", -1e-9, "pressure.exhaust_C_m3_per_s_Pa"),
    ("supply_b", 1.0, "pressure.supply_b"),
    ("exhaust_b", -0.5, "pressure.exhaust_b"),
    ("exhaust_b", 0.9995, "pressure.exhaust_b"),
])
def test_bad_3_2_path_keys_exit_2_naming_the_key(tmp_path, cli, key, value, message):
    text = (SCENARIOS / "pwm_3_2.toml").read_text().replace("supply_gauge_bar = 3.6\n",
                                                            f"supply_gauge_bar = 3.6\n{key} = {value}\n")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert_refused(cli("run", path, "-o", tmp_path / "out"), message, tmp_path / "out")


@pytest.mark.parametrize("at_time, side", [(None, -1.0), (0.3, 1.0)], ids=["inlet open (the end)", "inlet shut (0.3 s)"])
def test_linearize_takes_a_boolean_pair_in_the_inlets_opening(tmp_path, cli, at_time, side):
    """Two valves under boolean commands (the inlet a step open at 0.5 s, the exhaust complementary) are
    linearised in the inlet's opening: its B column and the pressure's own A entry are the switching pair's
    flow law differentiated by hand (one-sided into the openings' range: from below where the inlet is open,
    from above where it is shut), at the operating point the command prints."""
    import json

    path = _bad(tmp_path, ('kind = "pwm"\nstart_s = 0.5\nend_s = 4.5\n', 'kind = "step"\ntime_s = 0.5\nfinal = 1.0\n'),
                ("frequency_Hz = 50.0", "#"), ("duty = 0.5\n", "\n"))
    assert cli("run", path, "-o", tmp_path / "ok").returncode == 0
    extra = () if at_time is None else ("--at-time", str(at_time))
    done = cli("linearize", path, *extra, "--json")
    assert done.returncode == 0, done.stderr
    rep = json.loads(done.stdout)
    assert "under boolean commands" in rep["valve_model"] and rep["inputs"][0] == "pwm_duty"
    x, v, p, m = rep["operating_point"]["states"]
    supply = rep["operating_point"]["inputs"][1]
    src = pamsim.load_scenario(path).build_model().source  # the switching pair's own flow law

    def dp_dt(inlet: float, p_abs: float = p) -> float:
        return src.derivatives(np.array([p_abs, m]), x, v, (inlet, 1.0 - inlet, supply))[0]
    u0 = 1.0 if side < 0 else 0.0
    assert rep["operating_point"]["inputs"][0] == u0
    h = 1e-7
    row = rep["states"].index("p_abs_Pa")
    assert rep["B"][row][0] == pytest.approx((dp_dt(u0 + side * h) - dp_dt(u0)) / (side * h), rel=1e-6)
    dp = 0.05  # Pa: the flow law curves near the ambient, and a central difference of 1 Pa is off by 2.5e-6
    assert rep["A"][row][row] == pytest.approx((dp_dt(u0, p + dp) - dp_dt(u0, p - dp)) / (2.0 * dp), rel=1e-6)


def test_a_closed_loop_on_two_valves_is_refused(tmp_path, cli):
    """A ``[controller]`` drives the rig's single valve: with two 2/2 valves it is refused naming
    ``pressure.inlet``."""
    loop = (SCENARIOS / "closed_loop_position.toml").read_text()
    start = loop.index("[pressure]")
    end = loop.index("\n[", start + 1)
    pair = PWM_ONOFF.read_text()
    block = pair[pair.index("[pressure]"):pair.index("[simulation]")]
    path = tmp_path / "loop.toml"
    path.write_text(loop[:start] + block + loop[end + 1:])
    assert_refused(cli("run", path, "-o", tmp_path / "out"), "pressure.inlet", tmp_path / "out")
