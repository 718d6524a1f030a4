"""The proportional spool valve (``[pressure.spool]``, :mod:`pamsim.elements.spool`).

Each check is against a result found without the spool's code: the spool's step against the
second-order lag's step response written here; the fast, zero-lapped, tight spool against the
proportional valve's run (a second implementation), its gap against the spool's delay ``2 zeta / wn``
times the run's fastest rate; the overlap's shut band against mass and pressure that cannot change; the
conductances against the ramp computed by hand; the linear model against the proportional valve's
linear model times the spool's own transfer function ``wn^2 / (s^2 + 2 zeta wn s + wn^2)``.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

import pamsim
from conftest import SCENARIOS, assert_refused
from pamsim.control import linearize
from pamsim.control.operating_point import held_equilibrium

FIG4 = SCENARIOS / "acra2012_fig4.toml"
BASE = pamsim.load_scenario(FIG4)
OPEN_S = 1.0
"""The fig. 4 scenario's valve opens (its command steps 0 -> 1) at 1 s."""


def _spool(spool: dict, **simulation):
    return BASE.with_changes({"pressure": {"spool": spool}, "simulation": simulation})


def _second_order_step(t_s, f_Hz: float, zeta: float):
    """Step response from rest of ``s'' + 2 zeta wn s' + wn^2 s = wn^2`` (textbook closed forms)."""
    w = 2.0 * math.pi * f_Hz
    if zeta < 1.0:
        wd = w * math.sqrt(1.0 - zeta ** 2)
        return 1.0 - np.exp(-zeta * w * t_s) * (np.cos(wd * t_s) + zeta * w / wd * np.sin(wd * t_s))
    root = w * math.sqrt(zeta ** 2 - 1.0)
    p1, p2 = -zeta * w + root, -zeta * w - root
    return 1.0 - (p2 * np.exp(p1 * t_s) - p1 * np.exp(p2 * t_s)) / (p2 - p1)


# ---------------------------------------------------------------- the spool's step response


@pytest.mark.parametrize("zeta", [0.3, 2.0], ids=["underdamped", "overdamped"])
@pytest.mark.parametrize("backend", ["python", "native"])
def test_spool_step_matches_the_second_order_step_response(zeta, backend):
    """The command steps 0 -> 1 at 1 s; the spool's position against the closed form.  Tolerance: ten local
    error tolerances of the integrator, 10 (rtol max|s| + rtol nominal) with rtol = 1e-6, max|s| the
    response's peak and nominal 0.1 the spool position's absolute scale (measured: 9e-7 python, 8e-9
    native).  Before the step the spool stays exactly in its centre."""
    scenario = _spool({"natural_frequency_Hz": 125.0, "damping_ratio": zeta}, duration_s=1.05, sample_rate_Hz=20000.0)
    result = pamsim.simulate(scenario, backend)
    t = result.t_s - OPEN_S
    after = t >= 0.0
    expected = _second_order_step(t[after], 125.0, zeta)
    tolerance = 10.0 * (1e-6 * np.max(np.abs(expected)) + 1e-6 * 0.1)
    assert np.max(np.abs(result.signals["spool_position"][after] - expected)) < tolerance
    assert np.all(result.signals["spool_position"][~after] == 0.0)
    if zeta < 1.0:  # the overshoot past the stroke is the lag's own: the position is not clipped
        peak = 1.0 + math.exp(-math.pi * zeta / math.sqrt(1 - zeta ** 2))
        assert np.max(result.signals["spool_position"]) == pytest.approx(peak, abs=tolerance)


# ---------------------------------------------------------------- a second implementation


@pytest.fixture(scope="module")
def proportional_run():
    return pamsim.simulate(BASE.with_changes({"simulation": {"duration_s": 3.0}}))


@pytest.mark.parametrize("f_Hz", [2000.0, 20000.0])
def test_a_fast_tight_spool_is_the_proportional_valve_delayed(proportional_run, f_Hz):
    """Overlap 0, leakage 0, critically damped: the flow is the proportional valve's at the spool's position,
    a lag of delay 2 zeta / wn = 1 / (pi f) behind the command at low frequency.  The gap from the
    proportional valve's run is then that delay times the run's fastest rate, to first order: within
    10 % for the contraction and the pressure (measured 0.7 % and 0.4 %), so it falls as 1 / f."""
    run = pamsim.simulate(BASE.with_changes({"simulation": {"duration_s": 3.0},
                                             "pressure": {"spool": {"natural_frequency_Hz": f_Hz, "damping_ratio": 1.0}}}))
    base = proportional_run
    delay_s = 1.0 / (math.pi * f_Hz)
    x_shift = delay_s * np.max(np.abs(base.v_m_s))
    p_shift = delay_s * np.max(np.abs(np.gradient(base.p_gauge_Pa, base.t_s)))
    assert np.max(np.abs(run.x_m - base.x_m)) == pytest.approx(x_shift, rel=0.1)
    assert np.max(np.abs(run.p_gauge_Pa - base.p_gauge_Pa)) == pytest.approx(p_shift, rel=0.1)
    assert run.x_m[-1] == pytest.approx(base.x_m[-1], abs=1e-6)  # the same rest, 2 s after the move


# ---------------------------------------------------------------- overlap and leakage


def test_the_conductances_by_hand():
    """``C ramp(s) + C_leak`` on each path, the ramp zero inside the overlap and 1 at the end of the stroke."""
    source = _spool({"overlap": 0.2, "leakage_C_m3_per_s_Pa": 1e-11}).build_model().source
    C = source.valve.valve.orifice.C_m3_per_s_Pa
    leak = 1e-11 / C
    for s, (supply, exhaust) in {0.0: (0.0, 0.0), 0.2: (0.0, 0.0), -0.15: (0.0, 0.0), 0.6: (0.5, 0.0),
                                 -1.0: (0.0, 1.0), 1.3: (1.0, 0.0)}.items():
        assert source.valve.shares(s) == pytest.approx((supply + leak, exhaust + leak), abs=1e-15)


def _held_at_30_mm(spool: dict):
    """Fig. 4's load at rest at 30 mm with the chamber at its holding pressure, the command held at 0.3."""
    model = BASE.build_model()
    op = held_equilibrium(model, 0.030, 3.6e5)
    p0_bar = (op.states[2] - model.source.p_atm_Pa) / 1e5
    spec = copy.deepcopy(dict(BASE.spec))
    spec["pressure"] = {"source": "valve", "supply_gauge_bar": 3.6, "spool": spool, "initial_gauge_bar": p0_bar,
                        "command": {"kind": "constant", "value": 0.3}}
    spec["simulation"].update(duration_s=1.0, initial_contraction_m=0.030)
    return pamsim.Scenario.from_dict(spec, name="held"), p0_bar * 1e5


def test_no_flow_inside_the_overlap():
    """Command 0.3 inside an overlap of 0.5, no leakage: neither path opens, so the air mass cannot change and
    the held load's pressure stays where it started (exactly: no flow, no motion).  With an overlap of 0.2
    the same command fills the chamber, and a leaking spool inside the overlap moves the pressure too."""
    shut, p0 = _held_at_30_mm({"overlap": 0.5})
    run = pamsim.simulate(shut)
    assert np.all(run.signals["valve_mass_flow_kg_s"] == 0.0)
    assert np.all(run.signals["air_mass_kg"] == run.signals["air_mass_kg"][0])
    assert np.max(np.abs(run.p_gauge_Pa - p0)) < 1e-9 * p0
    assert np.all(run.x_m == 0.030)
    opened = pamsim.simulate(_held_at_30_mm({"overlap": 0.2})[0])
    assert opened.p_gauge_Pa[-1] > p0 + 1e4
    leaking = pamsim.simulate(_held_at_30_mm({"overlap": 0.5, "leakage_C_m3_per_s_Pa": 1e-11})[0])
    assert abs(leaking.p_gauge_Pa[-1] - p0) > 1e2


# ---------------------------------------------------------------- linearisation


def test_the_linear_model_is_the_valves_times_the_spools_lag():
    """Held at 30 mm (valve closed): the spool's linear model from the command to the contraction is the
    proportional valve's times ``wn^2 / (s^2 + 2 zeta wn s + wn^2)``, over four decades around the
    mechanical mode (to 1e-6 relative); the spool's two states are in it."""
    spool = pamsim.load_scenario(FIG4).with_changes({"pressure": {"spool": {"natural_frequency_Hz": 40.0,
                                                                             "damping_ratio": 0.5}}})
    plain_model, spool_model = BASE.build_model(), spool.build_model()
    plain = linearize(plain_model, held_equilibrium(plain_model, 0.030, 3.6e5))
    lin = linearize(spool_model, held_equilibrium(spool_model, 0.030, 3.6e5))
    assert list(lin.sys.state_labels)[-2:] == ["valve.spool_position", "valve.spool_velocity_per_s"]
    w = np.logspace(0, 4, 41)
    g_plain = plain.sys["contraction_m", "valve_command"](1j * w)
    g_spool = lin.sys["contraction_m", "valve_command"](1j * w)
    wn = 2 * math.pi * 40.0
    lag = wn ** 2 / ((1j * w) ** 2 + 2 * 0.5 * wn * 1j * w + wn ** 2)
    np.testing.assert_allclose(g_spool, g_plain * lag, rtol=1e-6)


# ---------------------------------------------------------------- backends


def test_every_backend_agrees():
    """The default spool (125 Hz, 0.7) on fig. 4 for 3 s: the same contraction and pressure on python, native,
    fmu-cs and fmu-me, within 1e-5 m and 100 Pa: a thousand times rtol 1e-6 of the states' scales (10 mm,
    1 bar), since the integrators differ (LSODA, Dormand-Prince in C, the FMU's own) and each bounds only its
    local error (measured: fmu-me 3e-7 m and 5.8 Pa, the others below)."""
    scenario = _spool({}, duration_s=3.0)
    assert scenario.beyond_one_muscle_fmu  # the one-muscle FMU has the proportional valve
    runs = {b: pamsim.simulate(scenario, b) for b in ("python", "native", "fmu-cs", "fmu-me")}
    for backend in ("native", "fmu-cs", "fmu-me"):
        t = runs["python"].t_s
        np.testing.assert_allclose(np.interp(t, runs[backend].t_s, runs[backend].x_m), runs["python"].x_m, atol=1e-5)
        np.testing.assert_allclose(np.interp(t, runs[backend].t_s, runs[backend].p_gauge_Pa), runs["python"].p_gauge_Pa,
                                   atol=100.0)


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("line, key", [
    ("natural_frequency_Hz = 0.0", "pressure.spool.natural_frequency_Hz"),
    ("natural_frequency_Hz = -125.0", "pressure.spool.natural_frequency_Hz"),
    ("damping_ratio = 0.0", "pressure.spool.damping_ratio"),
    ("overlap = 1.0", "pressure.spool.overlap"),
    ("overlap = -0.1", "pressure.spool.overlap"),
    ("leakage_C_m3_per_s_Pa = -1e-10", "pressure.spool.leakage_C_m3_per_s_Pa"),
    ("stroke_m = 0.001", "pressure.spool.stroke_m"),
    ('natural_frequency_Hz = "fast"', "pressure.spool.natural_frequency_Hz"),
])
@pytest.mark.parametrize("command", ["run", "linearize"])
def test_bad_spool_input_exits_2_naming_the_key(tmp_path, cli, line, key, command):
    bad = tmp_path / "bad.toml"
    text = FIG4.read_text().replace("[simulation]", f"[pressure.spool]\n{line}\n\n[simulation]")
    bad.write_text(text)
    assert_refused(cli(command, bad, "-o", tmp_path / "out"), key, tmp_path / "out")


def test_the_spool_is_refused_on_a_supply_port(tmp_path, cli):
    """The spool valve takes its supply input: drawing from a line's node it is refused naming the key."""
    chain = (SCENARIOS / "supply_chain.toml").read_text()
    bad = tmp_path / "chain.toml"
    bad.write_text(chain.replace("[simulation]", "[pressure.spool]\n\n[simulation]"))
    proc = cli("run", bad, "-o", tmp_path / "out")
    assert_refused(proc, "pressure.supply_port", tmp_path / "out")
    assert "spool" in proc.stderr


# ---------------------------------------------------------------- the closed loop through the spool and a tube

PROPORTIONAL = SCENARIOS / "proportional_valve.toml"


@pytest.fixture(scope="module")
def loops():
    from pamsim.control.closed_loop import run_closed_loop

    return {b: run_closed_loop(PROPORTIONAL, backend=b) for b in ("python", "native", "fmu-cs")}


def test_the_loop_meets_its_spec_on_every_backend(loops):
    """The scenario's [controller.spec] (closed_loop_position.toml's, not changed for the spool) on python,
    native and fmu-cs, and the same run on each: within 1e-6 m and 10 Pa of python at every sample, a hundred
    times the integrators' local tolerance on the states' scales (rtol 1e-6 of 10 mm and of 1 bar; measured
    1.7e-8 m and 0.6 Pa)."""
    spec = loops["python"].config.spec
    assert set(spec) >= {"rise_time_max_s", "overshoot_max_percent", "settling_time_max_s", "steady_state_error_max_mm"}
    ref = loops["python"].result
    for backend, run in loops.items():
        assert run.failures() == [], backend
        np.testing.assert_allclose(np.interp(ref.t_s, run.result.t_s, run.result.x_m), ref.x_m, atol=1e-6)
        np.testing.assert_allclose(np.interp(ref.t_s, run.result.t_s, run.result.p_gauge_Pa), ref.p_gauge_Pa, atol=10.0)
    # the spool moved and the tube carried the air: the loop ran through both
    assert np.max(np.abs(ref.signals["spool_position"])) > 0.5
    assert np.max(ref.signals["tube.outlet_mass_flow_kg_s"]) > 1e-5


@pytest.mark.parametrize("name", ["proportional_valve", "closed_loop_position"])
def test_every_column_of_a_closed_loop_has_one_value_per_sample(name, loops, tmp_path, cli):
    """The valve command's column was a square (samples x samples) array, and the CSV's rows as long: the
    controller's clip on arrays went through CasADi.  Each column now has one value per sample, in the
    result and in the CSV that ``pamsim run`` writes."""
    from pamsim.control.closed_loop import run_closed_loop

    run = loops["python"] if name == "proportional_valve" else run_closed_loop(SCENARIOS / f"{name}.toml")
    for key, values in run.result.signals.items():
        assert np.shape(values) == np.shape(run.result.t_s), key
    command = run.result.signals["valve_command"]
    assert np.all(np.abs(command) <= 1.0) and np.max(np.abs(command)) == 1.0  # saturated during the step
    proc = cli("run", SCENARIOS / f"{name}.toml", "-o", tmp_path)
    assert proc.returncode == 0, proc.stderr
    lines = (tmp_path / f"{name}.csv").read_text().splitlines()
    assert {len(line.split(",")) for line in lines} == {len(lines[0].split(","))}


def test_the_design_is_checked_on_the_full_linearisation(loops):
    """The LQR is designed on contraction, velocity and chamber pressure; its loop around the full
    linearisation (spool and tube states) is stable, and its poles include the spool's pair, moved by the
    loop but of the spool's order (|p| near 2 pi 125 Hz).  A spool of 20 Hz is slower than the loop: the design
    is refused, naming the key to change."""
    from pamsim.control.closed_loop import design_closed_loop
    from pamsim.errors import InputError

    design = loops["python"].design
    assert list(design.linear.sys.state_labels) == ["x_m", "v_m_s", "p_abs_Pa"]
    assert {"valve.spool_position", "valve.spool_velocity_per_s", "tube.p_abs_Pa"} \
        <= set(design.full_linear.sys.state_labels)
    assert np.max(design.full_loop_poles.real) < 0.0
    assert np.any(np.abs(np.abs(design.full_loop_poles) - 2 * math.pi * 125.0) < 0.5 * 2 * math.pi * 125.0)
    slow = pamsim.load_scenario(PROPORTIONAL).with_changes({"pressure": {"spool": {"natural_frequency_Hz": 20.0}}})
    with pytest.raises(InputError, match="does not stabilise.*pressure.spool.natural_frequency_Hz"):
        design_closed_loop(slow)


def test_a_closed_loop_drawing_from_a_line_is_refused(tmp_path, cli):
    """The design holds the line at the chamber's pressure: a valve on a supply port is refused naming it."""
    chain = (SCENARIOS / "supply_chain.toml").read_text()
    controller = PROPORTIONAL.read_text().split("\n[controller]\n")[1]
    bad = tmp_path / "chain.toml"
    bad.write_text(chain.replace("valve_open_time_s = 0.5\n", 'command = { kind = "constant", value = 0.0 }\n')
                   .replace("sample_rate_Hz = 1000.0\n", "sample_rate_Hz = 1000.0\ninitial_contraction_m = 0.020\n")
                   + "\n[controller]\n" + controller)
    assert_refused(cli("run", bad, "-o", tmp_path / "out"), "pressure.supply_port", tmp_path / "out")
