"""The averaged model of an on/off valve under PWM (``[pressure.command] model = "averaged"``).

Each check is against a second, independent result: the shares of a period against the switching
command's own trace (:func:`pamsim.signals.pwm_levels`) integrated piece by piece; the mean flow
against the ISO 6358 formula written here; the averaged run against switching runs whose frequency
rises; the linearisation against central differences of the averaged model's Python right-hand side
and its DC gain against the slope of switching runs' mean pressure.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import pamsim
from conftest import SCENARIOS, assert_refused
from pamsim.control import FrictionTreatment, MusclePlant, linearize
from pamsim.control.exact import exact_jacobians
from pamsim.control.linear import jacobians
from pamsim.control.operating_point import averaged_pwm_equilibrium, averaged_pwm_held
from pamsim.elements.pwm_average import PwmAveragedValve, PwmShare
from pamsim.signals import Pwm

PWM_3_2 = SCENARIOS / "pwm_3_2.toml"
BASE = pamsim.load_scenario(PWM_3_2)
COMMAND = dict(BASE.spec["pressure"]["command"])
IDEAL = {**COMMAND, "delay_on_s": 0.0, "delay_off_s": 0.0, "rise_s": 0.0, "fall_s": 0.0}
"""The scenario's valve switching at once: its averaged model does not depend on the frequency."""


def _scenario(command: dict, sample_rate_Hz: float = 5000.0, **changes):
    return BASE.with_changes({"pressure": {"command": {**command, **changes}},
                              "simulation": {"sample_rate_Hz": sample_rate_Hz}})


# ---------------------------------------------------------------- the shares of a period


def _trace_shares(pwm: Pwm, periods_in: int = 20) -> tuple[float, float]:
    """Mean over one period, ``periods_in`` periods after the start, of max(c, 0) and max(-c, 0) along the
    command's knots, cut where c crosses 0: exact for a trace of straight pieces (the trapezoid rule)."""
    T = 1.0 / pwm.frequency_Hz
    lo, hi = periods_in * T, (periods_in + 1) * T
    t = np.array(pwm.knots_t_s)
    times = [lo, *t[(t > lo) & (t < hi)], hi]
    total = np.zeros(2)
    for t0, t1 in zip(times[:-1], times[1:]):
        if t1 == t0:
            continue  # a jump: two knots at one time
        c0, c1 = pwm(t0), pwm(math.nextafter(t1, -math.inf))  # just inside the piece: its ends may be jumps
        cuts = [(t0, c0), (t1, c1)]
        if c0 * c1 < 0.0:
            tz = t0 + (t1 - t0) * c0 / (c0 - c1)
            cuts.insert(1, (tz, 0.0))
        for (ta, ca), (tb, cb) in zip(cuts[:-1], cuts[1:]):
            total += (tb - ta) * np.array([max(ca, 0.0) + max(cb, 0.0), max(-ca, 0.0) + max(-cb, 0.0)]) / 2.0
    return tuple(total / T)


TIMINGS = [(0.0, 0.0, 0.0, 0.0), (2e-3, 2e-3, 2e-3, 2e-3), (1e-3, 1.5e-3, 0.5e-3, 1.2e-3), (1.5e-3, 1e-3, 1.2e-3, 0.3e-3)]
LEVELS = [(-1.0, 1.0), (0.0, 1.0), (-0.5, 0.8), (0.2, 1.0), (-1.0, -0.2)]


@pytest.mark.parametrize("frequency_Hz", [50.0, 200.0, 400.0, 1000.0])
@pytest.mark.parametrize("low, high", LEVELS)
def test_shares_are_the_switching_traces_means(frequency_Hz, low, high):
    """Every duty, valve timing and pair of levels for which the opening takes effect strictly within a
    period before the closing does (``0 < duty / f + delay_off - delay_on < 1 / f``): the full, short-pulse
    and short-gap shapes, and the balanced case (rise and fall cancel) the switching trace starts closed."""
    checked = 0
    for duty in (0.02, 0.1, 0.3, 0.5, 0.8, 0.97, 0.999):
        for timing in TIMINGS:
            a = duty / frequency_Hz + timing[1] - timing[0]
            if not 1e-9 < a < 1.0 / frequency_Hz - 1e-9:
                continue
            pwm = Pwm(0.0, 30.0 / frequency_Hz, frequency_Hz, duty, low, high, *timing)
            got = PwmAveragedValve(None, PwmShare(frequency_Hz, low, high, *timing)).shares(duty)
            assert got == pytest.approx(_trace_shares(pwm), abs=1e-12), (duty, timing)
            checked += 1
    assert checked >= 10


def test_shares_at_the_duty_ends_hold_the_levels():
    """No switching at duty 0 (the ``low`` command) or 1 (``high``), whatever the valve's timing."""
    valve = PwmAveragedValve(None, PwmShare(50.0, -0.5, 0.8, 1e-3, 2e-3, 2e-3, 1e-3))
    assert valve.shares(0.0) == (0.0, 0.5)
    assert valve.shares(1.0) == (0.8, 0.0)


def test_effective_duty_of_a_3_2_valve_by_hand():
    """3/2 valve (low -1, high 1), full shape: the supply path is fully open ``a - rise`` and half open on
    average over the half of each switch where the command is positive, so its share is
    ``d + f (delay_off - delay_on) - f rise + f (rise + fall) / 4`` and the exhaust's
    ``1 - d - f (delay_off - delay_on) - f fall + f (rise + fall) / 4``."""
    f, d, on, off, r, q = 100.0, 0.4, 1e-3, 1.5e-3, 2e-3, 1e-3
    supply, exhaust = PwmAveragedValve(None, PwmShare(f, -1.0, 1.0, on, off, r, q)).shares(d)
    assert supply == pytest.approx(d + f * (off - on) - f * r + f * (r + q) / 4, rel=1e-14)
    assert exhaust == pytest.approx(1 - d - f * (off - on) - f * q + f * (r + q) / 4, rel=1e-14)


# ---------------------------------------------------------------- the mean flow against ISO 6358


def _iso6358_kg_s(p_up, p_down, T_up, C, b, laminar, rho0, T0):
    """ISO 6358 mass flow from ``p_up`` to ``p_down`` [kg/s]: choked below b, the elliptic subsonic law
    above it, and above the laminar ratio the straight line to zero at ratio 1 (pamsim's valve)."""
    ratio = p_down / p_up
    choked = C * rho0 * p_up * math.sqrt(T0 / T_up)
    if ratio <= b:
        return choked
    if ratio <= laminar:
        return choked * math.sqrt(1.0 - ((ratio - b) / (1.0 - b)) ** 2)
    at_laminar = choked * math.sqrt(1.0 - ((laminar - b) / (1.0 - b)) ** 2)
    return at_laminar * (1.0 - ratio) / (1.0 - laminar)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_averaged_flow_is_the_duty_weighted_iso6358_flows(backend):
    """Along an averaged run of the scenario's 3/2 valve (2 ms delays and switching times, 50 Hz), the
    valve's mass flow at every sample is ``d_s mdot(supply -> chamber) - d_e mdot(chamber -> exhaust)`` with
    the hand-derived effective duties ``d_s = d_e = d - f (rise + fall) / 4 = 0.45`` at d = 0.5 (equal delays
    and times), and the full flows from the formula above at the sample's chamber pressure and gas
    temperature."""
    res = pamsim.simulate(_scenario(COMMAND, model="averaged"), backend=backend)
    par = BASE.parameters
    C, b, lam = par["valve_C_m3_per_s_Pa"], par["valve_b"], par["valve_laminar_ratio"]
    rho0, T0, Ts, p_atm = par["rho0_kg_m3"], par["T0_K"], par["T_supply_K"], par["p_atm_Pa"]
    p_supply = BASE.final_pressure_gauge_Pa + p_atm
    f, rise, fall = COMMAND["frequency_Hz"], COMMAND["rise_s"], COMMAND["fall_s"]
    d_eff = COMMAND["duty"] - f * (rise + fall) / 4.0
    assert d_eff == pytest.approx(0.45)
    during = np.flatnonzero((res.t_s > COMMAND["start_s"]) & (res.t_s < COMMAND["end_s"]))[::97]
    want = []
    for k in during:
        p, T = res.p_gauge_Pa[k] + p_atm, res.signals["gas_temperature_K"][k]
        fill = _iso6358_kg_s(p_supply, p, Ts, C, b, lam, rho0, T0) if p < p_supply else 0.0
        vent = _iso6358_kg_s(p, p_atm, T, C, b, lam, rho0, T0) if p > p_atm else 0.0
        want.append(d_eff * fill - d_eff * vent)
    got = res.signals["valve_mass_flow_kg_s"][during]
    assert len(during) > 100
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-15)


# ---------------------------------------------------------------- PWM mean -> averaged pressure


def _mean_gauge_Pa(scenario, frequency_Hz: float, t0: float = 3.5, t1: float = 4.5) -> float:
    """Mean chamber gauge pressure over the whole periods from ``t0`` to ``t1`` (trapezoid rule)."""
    res = pamsim.simulate(scenario, backend="native")
    n = round((t1 - t0) * frequency_Hz)
    w = (res.t_s >= t0 - 1e-12) & (res.t_s <= t0 + n / frequency_Hz + 1e-12)
    return float(np.trapezoid(res.p_gauge_Pa[w], res.t_s[w]) / (res.t_s[w][-1] - res.t_s[w][0]))


FREQUENCIES_HZ = (50.0, 200.0, 1000.0)


@pytest.mark.parametrize("duty", [0.3, 0.5, 0.7])
def test_pwm_mean_pressure_tends_to_the_averaged_pressure(duty):
    """The scenario's muscle and weight, the valve switching at once (its averaged model then does not
    depend on the frequency): the gap between the switching run's mean pressure (3.5-4.5 s, whole
    periods, sampled at 50 kHz) and the averaged run's shrinks at each step of 50, 200, 1000 Hz, by at
    least 1/f^2 from 200 to 1000 Hz (measured: 25x for duties 0.3 and 0.7, 170x at 0.5, where the
    ripple's first-order effect cancels), to below 1 Pa at 1000 Hz (measured 0.1-0.3 Pa)."""
    averaged = _mean_gauge_Pa(_scenario(IDEAL, 50000.0, duty=duty, model="averaged"), 50.0)
    gaps = [abs(_mean_gauge_Pa(_scenario(IDEAL, 50000.0, duty=duty, frequency_Hz=f), f) - averaged)
            for f in FREQUENCIES_HZ]
    assert gaps[0] > gaps[1] > gaps[2], gaps
    assert gaps[1] / gaps[2] >= 0.8 * (1000.0 / 200.0) ** 2, gaps
    assert gaps[2] < 1.0, gaps


ASYMMETRIC = {**COMMAND, "delay_on_s": 1e-3, "delay_off_s": 2e-3, "rise_s": 1e-3, "fall_s": 2e-3, "end_s": 9.5}
"""A valve that closes later and more slowly than it opens: at duty 0.5 and 100 Hz its supply path's share
is 0.575 and its exhaust path's 0.275 (the ideal valve's: 0.5 each), so it balances at another pressure."""


def test_timing_correction_is_what_brings_the_averaged_model_to_the_switching_run():
    """:data:`ASYMMETRIC` at 100 Hz, 10 s, mean over 8.5-9.5 s (settled): the averaged model with the
    effective duties of the valve's delays and times lies within 200 Pa of the switching run's mean
    pressure (measured 80 Pa: the ripple's gap at 100 Hz); the same model without them is off by more
    than 50 kPa (measured 78.6 kPa)."""
    def settled(command, **changes):
        return BASE.with_changes({"pressure": {"command": {**command, "frequency_Hz": 100.0, **changes}},
                                  "simulation": {"sample_rate_Hz": 50000.0, "duration_s": 10.0}})

    switching = _mean_gauge_Pa(settled(ASYMMETRIC), 100.0, 8.5, 9.5)
    timed = _mean_gauge_Pa(settled(ASYMMETRIC, model="averaged"), 100.0, 8.5, 9.5)
    untimed = _mean_gauge_Pa(settled({**IDEAL, "end_s": 9.5}, model="averaged"), 100.0, 8.5, 9.5)
    assert abs(timed - switching) < 200.0
    assert abs(untimed - switching) > 50e3


def test_averaged_run_is_the_same_on_every_backend():
    """Python, native, fmu-cs and fmu-me run the averaged valve from the same generated equations: the
    final-second mean pressure within 10 Pa and contraction within 1 um of the python run's."""
    scenario = _scenario(COMMAND, model="averaged")
    runs = {b: pamsim.simulate(scenario, backend=b) for b in ("python", "native", "fmu-cs", "fmu-me")}
    ref = runs["python"]
    window = (ref.t_s >= 3.5) & (ref.t_s <= 4.5)
    for name, res in runs.items():
        np.testing.assert_allclose(res.t_s, ref.t_s)
        assert abs(res.p_gauge_Pa[window].mean() - ref.p_gauge_Pa[window].mean()) < 10.0, name
        assert np.max(np.abs(res.x_m - ref.x_m)) < 1e-6, name


# ---------------------------------------------------------------- linearisation


AVERAGED = _scenario(COMMAND, model="averaged")
MODEL = AVERAGED.build_model()


@pytest.mark.parametrize("where", ["balanced at duty 0.5", "held at 30 mm"])
@pytest.mark.parametrize("friction", [FrictionTreatment("dropped"), FrictionTreatment("regularised", 1e-3)],
                         ids=lambda f: f.kind)
def test_linearisation_agrees_with_central_differences(where, friction):
    """CasADi's Jacobians of the generated averaged valve against Richardson-extrapolated central
    differences of the model's Python right-hand side (``AveragedPwmSource.derivatives``), each entry to
    1e-6 of itself or 1e-9 of its block's largest entry (the tolerance of the proportional valve's)."""
    op = (averaged_pwm_equilibrium(MODEL, 0.5) if where.startswith("balanced")
          else averaged_pwm_held(MODEL, 0.030))
    assert np.max(np.abs(MusclePlant(MODEL).rhs(op.states, op.inputs, friction)[2:])) < 1e-6 * 1e5
    exact = exact_jacobians(MODEL, op.states, op.inputs, friction, "fill")
    diff = jacobians(MusclePlant(MODEL), op, friction, "fill")
    for name, e, d in zip("ABCD", exact, diff):
        floor = 1e-9 * max(np.max(np.abs(d)), np.max(np.abs(e))) + np.where(e == 0.0, 1e-8, 0.0)
        assert np.all(np.abs(e - d) <= 1e-6 * np.abs(d) + floor), (name, e, d)


def _settled(**command):
    """The scenario's valve switching at once at 1000 Hz for 9 s, the mean taken over its last second
    (the gas's slow thermal mode, -2.1 1/s, has settled to 1e-7 by then), sampled at 50 kHz."""
    return BASE.with_changes({"pressure": {"command": {**IDEAL, "frequency_Hz": 1000.0, "end_s": 9.5, **command}},
                              "simulation": {"sample_rate_Hz": 50000.0, "duration_s": 10.0}})


def test_dc_gain_in_duty_is_the_slope_of_switching_runs_mean_pressure():
    """The DC gain duty -> pressure of the linearisation at duty 0.5 against the slope of the switching
    runs' mean pressure: secants over duty steps 0.02, 0.04 and 0.08 about 0.5, extrapolated twice
    (Romberg: the delta^2 and delta^4 errors removed, the orifice's curvature makes the second matter).

    Tolerance: each run's mean differs from the averaged model's balance pressure at its duty by ``e``
    (the PWM gap and the solver, measured here: below 2 Pa); through the Romberg weights
    (4/3, 1/3, then 16/15, 1/15) on secants over 2 delta that is at most 165 max|e| per unit duty, and the
    delta^6 remainder is below 10 per unit duty (the delta^4 term is 160 at delta 0.04)."""
    model = _settled(model="averaged").build_model()
    src = model.source
    gain, _ = linearize(model, averaged_pwm_equilibrium(model, 0.5)).gain_at_zero("pwm_duty", "p_gauge_Pa")
    duties = (0.46, 0.48, 0.49, 0.51, 0.52, 0.54)
    means = {d: _mean_gauge_Pa(_settled(duty=d), 1000.0, 8.5, 9.5) for d in duties}
    T = src.chamber.start_temperature_K(src.T_supply_K)
    e = max(abs(means[d] - (src.balance_pressure_Pa(d, T) - src.p_atm_Pa)) for d in duties)

    def secant(delta):
        return (means[round(0.5 + delta, 2)] - means[round(0.5 - delta, 2)]) / (2 * delta)

    r1 = [(4 * secant(delta) - secant(2 * delta)) / 3 for delta in (0.01, 0.02)]
    slope = (16 * r1[0] - r1[1]) / 15
    tolerance = 165 * e + 10.0
    assert e < 2.0
    assert abs(gain - slope) < tolerance, (gain, slope, tolerance)
    assert tolerance < 1e-3 * gain  # the check means something: 0.05 % of the gain


def test_cli_linearize_uses_the_averaged_model(tmp_path, cli):
    """``pamsim linearize`` on the switching PWM scenario: the duty is the input, the output says so, and the
    operating point is the averaged model's balance (a rest: the residual is nil)."""
    proc = cli("linearize", PWM_3_2, "--json")
    assert proc.returncode == 0, proc.stderr
    rep = json.loads(proc.stdout)
    assert rep["inputs"] == ["pwm_duty", "supply_gauge_Pa", "F_ext_N"]
    assert "averaged model" in rep["valve_model"] and "pwm_duty [1]" in rep["valve_model"]
    assert rep["operating_point"]["kind"] == "pwm_averaged"
    assert np.max(np.abs(rep["residual_f_x0_u0"][2:])) < 1e-3
    assert rep["dc_gain"]["pwm_duty->contraction_m"] > 0
    text = cli("linearize", PWM_3_2, "-o", tmp_path)
    assert text.returncode == 0, text.stderr
    assert "valve: the averaged model of the on/off valve under 50 Hz PWM" in text.stdout
    assert "DC gain pwm_duty -> contraction" in text.stdout


@pytest.mark.parametrize("law", ["isothermal", "polytropic", "thermal"])
def test_every_chamber_law_linearises_under_averaged_pwm_without_a_pole_at_zero(law):
    """At the averaged model's balance both paths flow.  Under the isothermal law ``p V = m R T_wall`` fixes
    the air mass by the pressure: its outflow once carried ``p V / (m R)``, so the pressure's rate read the
    air mass and the linearisation kept it, with a pole at -2e-16 (a mode no input moves).  Now the
    isothermal air mass is dropped as decoupled and every pole is a physical one; the polytropic and thermal
    gases keep theirs (their temperature is a state of its own)."""
    model = AVERAGED.with_changes({"chamber": {"law": law}}).build_model()
    lin = linearize(model, averaged_pwm_equilibrium(model, 0.5))
    poles = np.linalg.eigvals(lin.sys.A)
    assert np.min(np.abs(poles)) > 0.1, poles
    assert ("air_mass_kg" in lin.dropped_states) == (law == "isothermal"), lin.dropped_states


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("change, key", [
    ({"duty": 1.5}, "pressure.command.duty"),
    ({"duty": -0.1}, "pressure.command.duty"),
    ({"frequency_Hz": 0.0}, "pressure.command.frequency_Hz"),
    ({"frequency_Hz": 2000.0}, "pressure.command.frequency_Hz"),
    ({"model": "mean"}, "pressure.command.model"),
])
@pytest.mark.parametrize("model", ["switching", "averaged"])
@pytest.mark.parametrize("command", ["run", "linearize"])
def test_bad_pwm_input_exits_2_naming_the_key(tmp_path, cli, change, key, model, command):
    bad = tmp_path / "bad.toml"
    text = PWM_3_2.read_text().replace('duty = 0.5\n', f'duty = 0.5\nmodel = "{model}"\n')
    for name, value in change.items():
        line = next(ln for ln in text.splitlines() if ln.startswith(f"{name} ="))
        text = text.replace(line, f"{name} = {json.dumps(value)}") if name != "model" else \
            text.replace(f'model = "{model}"', f'model = "{value}"')
    bad.write_text(text)
    assert_refused(cli(command, bad, "-o", tmp_path / "out"), key, tmp_path / "out")


def test_model_is_refused_on_a_command_that_is_not_pwm(tmp_path, cli):
    bad = tmp_path / "step.toml"
    bad.write_text(PWM_3_2.read_text().split("[pressure.command]")[0]
                   + '[pressure.command]\nkind = "step"\ntime_s = 0.5\nfinal = 1.0\nmodel = "averaged"\n'
                   + "[simulation]" + PWM_3_2.read_text().split("[simulation]")[1])
    proc = cli("run", bad, "-o", tmp_path / "out")
    assert proc.returncode == 2
    assert "pressure.command.model" in proc.stderr and "only a pwm command" in proc.stderr


def test_valve_slope_is_refused_for_a_pwm_valve(tmp_path, cli):
    proc = cli("linearize", PWM_3_2, "--valve-slope", "fill", "-o", tmp_path / "out")
    assert proc.returncode == 2
    assert "--valve-slope" in proc.stderr and "duty" in proc.stderr
    assert not (tmp_path / "out").exists()


def test_the_fmu_backends_run_the_averaged_valve_through_the_assemblys_fmu():
    """The one-muscle FMU has the proportional valve: a scenario with the averaged valve goes to its
    assembly's FMU (pamsim run --backend fmu-*, pamsim fmu build --scenario), a switching one does not."""
    assert _scenario(COMMAND, model="averaged").beyond_one_muscle_fmu
    assert not _scenario(COMMAND).beyond_one_muscle_fmu
    assert not _scenario(COMMAND, model="switching").beyond_one_muscle_fmu


def test_the_averaged_valve_is_refused_in_a_supply_line(tmp_path, cli):
    """The averaged valve takes its supply input and feeds the chamber: wired into a line of components
    (``supply_port``, ``outlet_port``) it is refused naming the key, not run without the line."""
    chain = SCENARIOS / "supply_chain.toml"
    bad = tmp_path / "chain.toml"
    bad.write_text(chain.read_text().replace(
        "valve_open_time_s = 0.5\n", 'command = {kind = "pwm", start_s = 0.5, end_s = 2.5, frequency_Hz = 50.0, '
        'duty = 0.5, high = 1.0, low = -1.0, model = "averaged"}\n'))
    proc = cli("run", bad, "-o", tmp_path / "out")
    assert proc.returncode == 2, proc.stderr
    assert "pressure.supply_port" in proc.stderr and "averaged PWM valve" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
