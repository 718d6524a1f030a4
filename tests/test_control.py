"""Control design: the python-control model, linearisations, and the closed-loop example.

Every expected value is computed here independently (hand formulas, plain
finite differences, the nonlinear model's own response), never copied from
a previous run.
"""

from __future__ import annotations

import json
import math
import sys

import control as ct
import numpy as np
import pytest

import pamsim
from pamsim.control import (FrictionTreatment, held_equilibrium, linearize, muscle_nlsys, open_valve_equilibrium,
                            trajectory_point)
from pamsim.control.closed_loop import run_closed_loop
from pamsim.control.system import STATES, MusclePlant
from pamsim.errors import InputError

from conftest import ROOT, SCENARIOS, run_cli

FIG4 = SCENARIOS / "acra2012_fig4.toml"
CLOSED_LOOP = SCENARIOS / "closed_loop_position.toml"


@pytest.fixture(scope="module")
def fig4():
    sc = pamsim.load_scenario(FIG4)
    return sc, sc.build_model()


# ---------------------------------------------------------------- the nonlinear system
def test_nlsys_names_and_rhs_are_the_models(fig4):
    sc, model = fig4
    sys_nl = muscle_nlsys(model, FrictionTreatment("sliding", direction=1.0))
    assert list(sys_nl.state_labels) == ["x_m", "v_m_s", "p_abs_Pa", "air_mass_kg"]
    assert list(sys_nl.input_labels) == ["valve_command", "supply_gauge_Pa", "F_ext_N"]
    assert list(sys_nl.output_labels) == ["contraction_m", "p_gauge_Pa", "F_tendon_N"]
    x = np.array([0.03, 0.01, 3.0e5, 2.0e-5])
    u = np.array([0.4, 3.6e5, 1.5])
    y = np.concatenate([x, np.zeros(4)])
    expected = model.slip_rhs(y, 1.0, (0.4, 3.6e5), 1.5)[:4]
    np.testing.assert_array_equal(sys_nl.dynamics(0.0, x, u), expected)
    # Muscle force = static - damping - friction, from the elements directly.
    p = 3.0e5 - model.source.p_atm_Pa
    F = (model.static_force.force_N(0.03, p) - model.damping.force_N(0.01)
         - model.friction.level_N(0.03, p, model.load.mass_kg))
    out = sys_nl.output(0.0, x, u)
    assert out[0] == 0.03 and out[1] == pytest.approx(p)
    assert out[2] == pytest.approx(F, rel=1e-12, abs=1e-12)


def test_prescribed_pressure_source_is_refused():
    spec = dict(pamsim.load_scenario(FIG4).spec)
    spec["pressure"] = {"source": "prescribed", "prescribed": {"kind": "constant", "value_gauge_bar": 3.0}}
    sc = pamsim.Scenario.from_dict(spec, "prescribed")
    with pytest.raises(InputError, match="valve source"):
        MusclePlant(sc.build_model())


# ---------------------------------------------------------------- operating points
def test_operating_points_are_equilibria(fig4):
    sc, model = fig4
    plant = MusclePlant(model)
    dropped = FrictionTreatment("dropped")
    for op in (open_valve_equilibrium(model, sc.final_pressure_gauge_Pa),
               held_equilibrium(model, 0.030, sc.final_pressure_gauge_Pa)):
        f = plant.rhs(op.states, op.inputs, dropped)
        # Force balance to 1e-9 of the weight, chamber at rest.
        assert abs(f[1]) * model.load.mass_kg < 1e-9 * model.load.weight_N
        assert f[0] == 0.0 and abs(f[2]) < 1e-6 and abs(f[3]) < 1e-15
    held = held_equilibrium(model, 0.030, sc.final_pressure_gauge_Pa)
    assert held.inputs[0] == 0.0  # the closed valve holds the pressure


# ---------------------------------------------------------------- linear vs nonlinear
def _responses(model, op, lin, t, u, friction):
    sys_nl = muscle_nlsys(model, friction)
    nl = ct.input_output_response(sys_nl, t, u, op.states, solve_ivp_method="LSODA",
                                  solve_ivp_kwargs={"rtol": 1e-10, "atol": [1e-13, 1e-12, 1e-6, 1e-15],
                                                    "max_step": 2e-4})
    du = u - op.inputs[:, None]
    li = ct.forced_response(lin.sys, t, du)
    dx_nl = nl.outputs[0] - op.states[0]
    dp_nl = nl.outputs[1] - (op.states[2] - model.source.p_atm_Pa)
    return dx_nl, li.outputs[0], dp_nl, li.outputs[1]


def test_linear_matches_nonlinear_valve_pulse(fig4):
    """A 2 % valve pulse of 20 ms about the held point at 30 mm (Coulomb off)."""
    sc, model = fig4
    op = held_equilibrium(model, 0.030, sc.final_pressure_gauge_Pa)
    friction = FrictionTreatment("dropped")
    lin = linearize(model, op, friction, valve_slope="fill")  # the pulse fills: one-sided slope
    t = np.arange(0.0, 0.6, 2e-4)
    u = np.tile(op.inputs[:, None], (1, t.size))
    u[0] = np.where((t >= 0.01) & (t < 0.03), 0.02, 0.0)
    dx_nl, dx_li, dp_nl, dp_li = _responses(model, op, lin, t, u, friction)
    peak_x, peak_p = np.max(np.abs(dx_nl)), np.max(np.abs(dp_nl))
    assert peak_x > 1e-4  # a real deflection (0.1 mm or more), not numerical noise
    assert np.max(np.abs(dx_li - dx_nl)) <= 0.05 * peak_x
    assert np.max(np.abs(dp_li - dp_nl)) <= 0.05 * peak_p


def test_linear_matches_nonlinear_supply_step_open_valve(fig4):
    """A 2 mbar supply step about the open-valve point: the valve stays in its laminar branch."""
    sc, model = fig4
    op = open_valve_equilibrium(model, sc.final_pressure_gauge_Pa)
    friction = FrictionTreatment("dropped")
    lin = linearize(model, op, friction)
    t = np.arange(0.0, 0.6, 2e-4)
    u = np.tile(op.inputs[:, None], (1, t.size))
    u[1] = np.where(t >= 0.01, op.inputs[1] + 200.0, op.inputs[1])
    dx_nl, dx_li, dp_nl, dp_li = _responses(model, op, lin, t, u, friction)
    peak_x, peak_p = np.max(np.abs(dx_nl)), np.max(np.abs(dp_nl))
    assert peak_x > 1e-6 and peak_p > 100.0
    assert np.max(np.abs(dx_li - dx_nl)) <= 0.05 * peak_x
    assert np.max(np.abs(dp_li - dp_nl)) <= 0.05 * peak_p


# ---------------------------------------------------------------- natural frequency by hand
def _hand_stiffness_N_m(params, x_m, p_gauge_Pa):
    """k_eff = -dF_static/dx + dF_static/dp * n p |dV/dx| / V: the closed chamber's polytropic spring."""
    P = p_gauge_Pa / 1e5
    dF_dx = (2 * params["K1_N_per_bar_m2"] * x_m + params["K2_N_per_bar_m"]) * P + 2 * params["S1_N_per_m2"] * x_m \
        + params["S2_N_per_m"]
    dF_dp = (params["K1_N_per_bar_m2"] * x_m ** 2 + params["K2_N_per_bar_m"] * x_m + params["C1_N_per_bar"]) / 1e5
    theta = math.radians(params["theta0_deg"])
    b = params["L0_m"] / math.cos(theta)
    n = b * math.sin(theta) / (2.0 * math.pi * params["r0_m"])
    L = params["L0_m"] - x_m
    V = L * (b * b - L * L) / (4 * math.pi * n * n) + params["dead_volume_m3"]
    dV_dx = (3 * L * L - b * b) / (4 * math.pi * n * n)  # V grows as the muscle shortens
    p_abs = p_gauge_Pa + params["p_atm_Pa"]
    k_pneumatic = dF_dp * params["polytropic_index"] * p_abs * dV_dx / V
    return -dF_dx + k_pneumatic


@pytest.mark.parametrize("x_mm", [10.0, 30.0, 55.0])
def test_natural_frequency_matches_hand_value(fig4, x_mm):
    sc, model = fig4
    op = held_equilibrium(model, x_mm * 1e-3, sc.final_pressure_gauge_Pa)
    mode = linearize(model, op).mechanical_mode()
    p_gauge = op.states[2] - sc.parameters["p_atm_Pa"]
    k_eff = _hand_stiffness_N_m(sc.parameters, x_mm * 1e-3, p_gauge)
    omega_hand = math.sqrt(k_eff / sc.mass_kg)
    assert mode.omega_n_rad_s == pytest.approx(omega_hand, rel=0.05)
    assert abs(mode.damping_ratio) < 0.05  # the paper's damping is weak (and slightly negative)


def test_natural_frequency_with_adiabatic_chamber_is_stiffer(fig4):
    """n = 1.4 raises the pneumatic stiffness by 1.4; the linearisation must follow the hand formula."""
    sc, _ = fig4
    sc14 = sc.with_changes({"parameters": {"polytropic_index": 1.4}})
    model = sc14.build_model()
    op = held_equilibrium(model, 0.030, sc14.final_pressure_gauge_Pa)
    k_eff = _hand_stiffness_N_m(sc14.parameters, 0.030, op.states[2] - sc14.parameters["p_atm_Pa"])
    assert linearize(model, op).mechanical_mode().omega_n_rad_s == pytest.approx(
        math.sqrt(k_eff / sc14.mass_kg), rel=0.05)


# ---------------------------------------------------------------- A vs central differences
def _central_difference_A(plant, op, friction, rel_step=1e-6):
    scales = np.array([1e-2, 1e-1, 1e5, 1e-5])
    A = np.zeros((4, 4))
    for j in range(4):
        h = rel_step * scales[j]
        xp, xm = op.states.astype(float).copy(), op.states.astype(float).copy()
        xp[j] += h
        xm[j] -= h
        A[:, j] = (plant.rhs(xp, op.inputs, friction) - plant.rhs(xm, op.inputs, friction)) / (2 * h)
    return A, scales


def _ops(sc, model):
    supply = sc.final_pressure_gauge_Pa
    return {
        "held_dropped": (held_equilibrium(model, 0.030, supply), FrictionTreatment("dropped")),
        "held_regularised": (held_equilibrium(model, 0.045, supply), FrictionTreatment("regularised", 0.01)),
        "open_valve": (open_valve_equilibrium(model, supply), FrictionTreatment("dropped")),
        "filling_sliding": (trajectory_point(sc, 1.3), FrictionTreatment("sliding")),
    }


def test_A_matches_central_difference(fig4):
    sc, model = fig4
    plant = MusclePlant(model)
    for name, (op, friction) in _ops(sc, model).items():
        lin = linearize(model, op, friction, drop_unobservable_air_mass=False)
        assert list(lin.sys.state_labels) == list(STATES)
        A_fd, s = _central_difference_A(plant, op, lin.friction)
        # Compare in scaled variables (row i divided by scale i, column j times scale j) so that
        # entries in Pa and kg are commensurable; relative to the largest entry of each row.
        S = s[None, :] / s[:, None]
        err = np.abs(lin.sys.A - A_fd) * S
        ref = np.max(np.abs(A_fd) * S, axis=1, keepdims=True)
        ref[ref == 0.0] = 1.0
        assert np.max(err / ref) < 1e-6, name


def test_A_matches_fmu_directional_derivatives(fig4):
    """Cross-check against the FMU (C model, docs/fmu.md): its directional derivatives at a sliding
    state it reached itself, against this linearisation of the Python model there, to 1e-4."""
    fmpy = pytest.importorskip("fmpy")
    import os
    import shutil

    if not (os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")):
        pytest.skip("no C compiler to build the FMU")
    from fmpy.fmi2 import FMU2Slave

    from pamsim.control import OperatingPoint
    from pamsim.fmu.runner import ScenarioInputs, cached_fmu, start_values
    from pamsim.fmu.variables import value_reference

    sc, model = fig4
    path = cached_fmu(2)
    md = fmpy.read_model_description(path)
    unzipped = fmpy.extract(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="control_check")
    names = ["contraction_m", "velocity_m_s", "chamber_pressure_abs_Pa", "air_mass_kg"]
    inputs = ScenarioInputs(sc)

    def set_values(values):
        reals = {value_reference(k): v for k, v in values.items() if isinstance(v, float)}
        ints = {value_reference(k): v for k, v in values.items() if not isinstance(v, float)}
        fmu.setReal(list(reals), list(reals.values()))
        if ints:
            fmu.setInteger(list(ints), list(ints.values()))

    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0, stopTime=2.0)
        set_values(start_values(sc))
        set_values(inputs(0.0))
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(0.0, 1.0)  # the valve opens at 1 s
        set_values(inputs(1.0))
        fmu.doStep(1.0, 0.3)
        states = np.array(fmu.getReal([value_reference(n) for n in names]))
        mode = fmu.getInteger([value_reference("friction_mode")])[0]
        ders = [value_reference(f"der({n})") for n in names]
        A_fmu = np.column_stack([fmu.getDirectionalDerivative(ders, [value_reference(n)], [1.0]) for n in names])
        fmu.terminate()
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    assert mode in (1, -1) and states[1] != 0.0  # sliding, so the Coulomb term has a derivative
    u, supply = model.source.inputs(1.3)
    op = OperatingPoint(states, np.array([u, supply, 0.0]), "fmu", pamsim.Mode(mode), "FMU state at 1.3 s")
    lin = linearize(model, op, FrictionTreatment("sliding"), drop_unobservable_air_mass=False)
    assert lin.friction.direction == mode
    s = np.array([1e-2, 1e-1, 1e5, 1e-5])
    S = s[None, :] / s[:, None]
    ref = np.max(np.abs(A_fmu) * S, axis=1, keepdims=True)
    ref[ref == 0.0] = 1.0
    assert np.max(np.abs(lin.sys.A - A_fmu) * S / ref) < 1e-4


def test_sliding_friction_needs_motion(fig4):
    sc, model = fig4
    op = held_equilibrium(model, 0.030, sc.final_pressure_gauge_Pa)
    with pytest.raises(InputError, match="moving load"):
        linearize(model, op, FrictionTreatment("sliding"))


def test_closed_valve_integrates_the_command(fig4):
    """Held with the valve closed, the command integrates into air: infinite DC gain, finite rate.

    The rate must equal the filling flow's effect: mdot raises the pressure,
    and at steady rate the static force stays at the weight, so
    dx/dt = -(dF/dp)(dp/dm) mdot / (dF/dx + dF/dp dp/dx) for the mean valve slope.
    """
    sc, model = fig4
    op = held_equilibrium(model, 0.030, sc.final_pressure_gauge_Pa)
    lin = linearize(model, op)
    g0, k_int = lin.gain_at_zero("valve_command", "contraction_m")
    assert g0 is None and k_int > 0
    # Independent estimate: a quasi-static slow fill.  Air mass rate per unit command (mean of the
    # filling and venting slopes), and the contraction that keeps F_static = W as air is added at
    # fixed temperature (pV = mRT): dx/dm from the held equilibrium at two air masses.
    src = model.source
    s0 = op.states[2:4]
    V0 = src.chamber.volume_m3(0.030)
    mdot_fill = src.inflow_kg_s(s0, V0, (1.0, op.inputs[1]))[0]
    mdot_vent = -src.inflow_kg_s(s0, V0, (-1.0, op.inputs[1]))[0]
    mdot = 0.5 * (mdot_fill + mdot_vent)
    from scipy.optimize import brentq

    def x_for_mass(m_air):
        T = src.T_supply_K
        ch = src.chamber
        return brentq(lambda x: model.static_force.force_N(
            x, m_air * ch.R_J_per_kg_K * T / ch.volume_m3(x) - src.p_atm_Pa) - model.load.weight_N, 0.005, 0.06)

    dm = 1e-3 * s0[1]
    dx_dm = (x_for_mass(s0[1] + dm) - x_for_mass(s0[1] - dm)) / (2 * dm)
    assert k_int == pytest.approx(dx_dm * mdot, rel=1e-3)


# ---------------------------------------------------------------- closed loop on the hybrid model
@pytest.fixture(scope="module")
def closed_loop():
    return run_closed_loop(CLOSED_LOOP)


def test_closed_loop_meets_its_specification(closed_loop):
    run = closed_loop
    spec = run.config.spec
    m = run.metrics
    assert set(spec) >= {"rise_time_max_s", "overshoot_max_percent", "settling_time_max_s",
                         "steady_state_error_max_mm"}
    assert m["rise_time_s"] <= spec["rise_time_max_s"]
    assert m["overshoot_percent"] <= spec["overshoot_max_percent"]
    assert m["settling_time_s"] <= spec["settling_time_max_s"]
    assert m["steady_state_error_mm"] <= spec["steady_state_error_max_mm"]
    assert run.failures() == []
    # It is the hybrid model that ran: the load was stuck before the step and sticks at the end.
    res = run.result
    assert res.mode[0] == pamsim.Mode.STICK and res.final_mode == pamsim.Mode.STICK
    # The valve saturated during the move (the anti-windup was exercised) and stays within [-1, 1].
    u = res.signals["valve_command"]
    assert np.max(u) == 1.0 and np.min(u) >= -1.0
    # Held at 20 mm before the step, at the target at the end.
    assert res.x_m[res.t_s < run.config.step_time_s] == pytest.approx(0.020, abs=1e-6)
    assert abs(res.x_m[-1] - 0.040) <= spec["steady_state_error_max_mm"] * 1e-3


def test_closed_loop_has_no_friction_limit_cycle_without_deadband():
    """With the integral deadband off, the load must still come to rest (no stick-slip hunting):
    this model's breakaway and sliding friction are equal (docs/control.md)."""
    run = run_closed_loop(CLOSED_LOOP, {"integrator_deadband_mm": 0.0})
    res = run.result
    late = [e for e in res.transitions if e.t_s > run.config.step_time_s + 1.0]
    assert late == []
    tail = res.t_s > res.t_s[-1] - 1.0
    assert np.ptp(res.x_m[tail]) < 1e-6
    assert run.metrics["steady_state_error_mm"] < 0.05


def test_bad_controller_table_is_an_input_error():
    sc = pamsim.load_scenario(CLOSED_LOOP)
    spec = dict(sc.spec)
    spec["controller"] = {**spec["controller"], "max_velocity_mm_s": -1.0}
    bad = pamsim.Scenario.from_dict(spec, "bad", sc.base_dir, "bad.toml")
    with pytest.raises(InputError, match="max_velocity_mm_s"):
        run_closed_loop(bad)


# ---------------------------------------------------------------- CLI


def test_cli_linearize_json(tmp_path, cli):
    proc = cli("linearize", FIG4, "--contraction-mm", "30", "--json", "-o", tmp_path)
    assert proc.returncode == 0, proc.stderr
    rep = json.loads(proc.stdout)
    for key in ("A", "B", "C", "D", "poles", "natural_frequency_Hz", "damping_ratio", "states", "inputs", "outputs"):
        assert key in rep
    assert rep["states"] == ["x_m", "v_m_s", "p_abs_Pa"]
    assert np.array(rep["A"]).shape == (3, 3) and np.array(rep["B"]).shape == (3, 3)
    assert all(len(p) == 2 for p in rep["poles"])
    assert rep["dc_gain"]["valve_command->contraction_m"] is None  # integrator
    assert rep["natural_frequency_Hz"] > 0
    assert (tmp_path / "acra2012_fig4_linear_bode.png").stat().st_size > 0
    assert (tmp_path / "acra2012_fig4_linear_pzmap.png").stat().st_size > 0


def test_cli_linearize_json_without_output_folder_writes_nothing_and_keeps_stderr_empty(tmp_path):
    proc = run_cli("linearize", FIG4, "--json", cwd=tmp_path)  # a real process: warnings show as a user sees them
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["natural_frequency_Hz"] > 0
    assert proc.stderr == ""
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, words", [
    (("--contraction-mm", "90"), "outside the model's range"),
    (("--contraction-mm", "-3"), "outside the model's range"),
    (("--at-time", "100"), "must lie in"),
])
def test_cli_bad_operating_points_exit_2(tmp_path, cli, args, words):
    proc = cli("linearize", FIG4, *args, "-o", tmp_path / "out")
    assert proc.returncode == 2
    assert words in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()  # found after the folder was made: it goes again


def test_cli_load_beyond_capability_exits_2(tmp_path, cli):
    heavy = tmp_path / "heavy.toml"
    heavy.write_text(FIG4.read_text().replace("weight_N = 22.74", "weight_N = 80.0"))
    for extra in ((), ("--contraction-mm", "30")):
        proc = cli("linearize", heavy, *extra, "-o", tmp_path)
        assert proc.returncode == 2, proc.stderr
        assert ("force capability" in proc.stderr) and "Traceback" not in proc.stderr


@pytest.mark.parametrize("method", ["LSODA", "RK45"])
def test_closed_loop_release_that_turns_back_at_once_does_not_crash(method):
    """The reviewer's reproduction: 32.74 N from 10 mm to 30 mm.  A slip starts at v = 0 and turns back
    within the integrator's resolution while the controller vents; the run must finish and settle.
    (LSODA crashed in the root finder; RK45 stopped with "event switching made no progress".)"""
    sc = pamsim.load_scenario(CLOSED_LOOP)
    heavy = sc.with_changes({"load": {"weight_N": 32.74}, "simulation": {"initial_contraction_m": 0.010},
                             "solver": {"method": method}})
    run = run_closed_loop(heavy, {"target_contraction_mm": 30.0})
    res = run.result
    assert res.t_s[-1] == pytest.approx(sc.duration_s)
    assert res.at_rest_at_end
    assert abs(res.x_m[-1] - 0.030) <= run.config.spec["steady_state_error_max_mm"] * 1e-3


def test_loop_margins_agree_with_a_direct_frequency_scan_and_the_closed_loop_poles():
    """Margins of the design loop against L(jw) evaluated from its matrices, and against the
    closed-loop poles when the loop gain is scaled just past the gain margin."""
    import control as ct
    from scipy.optimize import brentq

    from pamsim.control.margins import loop_margins, loop_transfer

    sc = pamsim.load_scenario(ROOT / "scenarios" / "closed_loop_position.toml")
    m = loop_margins(sc)
    L = loop_transfer(sc)
    A, B, C, D = (np.asarray(M) for M in (L.A, L.B, L.C, L.D))

    def Ljw(f_Hz):
        s = 2j * np.pi * f_Hz
        return (C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B) + D)[0, 0]

    def crossings(g, grid):
        vals = [g(f) for f in grid]
        return [brentq(g, a, b) for a, b, ga, gb in zip(grid, grid[1:], vals, vals[1:]) if ga * gb < 0]

    grid = np.geomspace(0.1, 1000.0, 2001)
    gain_x = crossings(lambda f: abs(Ljw(f)) - 1.0, grid)
    # Phase -180 deg: L real and negative (the integrators' crossing at f -> 0 lies below the grid).
    phase_x = [f for f in crossings(lambda f: np.imag(Ljw(f)), grid) if np.real(Ljw(f)) < 0]
    assert len(gain_x) == 1 and len(phase_x) == 1, (gain_x, phase_x)
    f_gc, f_pc = gain_x[0], phase_x[0]
    pm = 180.0 + np.degrees(np.angle(Ljw(f_gc)))
    assert m.gain_crossover_Hz == pytest.approx(f_gc, rel=1e-4)
    assert m.phase_margin_deg == pytest.approx(pm, abs=0.05)
    assert m.phase_crossover_Hz == pytest.approx(f_pc, rel=1e-4)
    assert m.gain_margin == pytest.approx(1.0 / abs(Ljw(f_pc)), rel=1e-4)
    # The crossovers the docs state (gain crossover above the phase crossover) ...
    assert m.gain_crossover_Hz > m.phase_crossover_Hz
    # ... and the meaning of a lower gain margin: the loop is stable as designed and just above
    # the margin, and unstable just below it.
    for factor, stable in ((1.0, True), (1.05 * m.gain_margin, True), (0.95 * m.gain_margin, False)):
        poles = ct.feedback(factor * L, 1).poles()  # u = C P u = -L u: negative feedback around L
        assert (np.max(np.real(poles)) < 0) == stable, factor


def test_bode_phase_is_unwrapped():
    sc = pamsim.load_scenario(FIG4)
    model = sc.build_model()
    lin = linearize(model, open_valve_equilibrium(model, sc.final_pressure_gauge_Pa))
    for inp, out in (("F_ext_N", "contraction_m"), ("supply_gauge_Pa", "contraction_m")):
        phase = np.asarray(lin.bode(inp, out, lin.frequency_grid_rad_s())["phase_deg"])
        assert np.max(np.abs(np.diff(phase))) < 180.0, (inp, out)
        # Both channels are a lightly damped mass-spring seen from its input: 0 deg at DC,
        # -180 deg just past the resonance, with no jump of 360 deg on the way.
        assert phase[0] == pytest.approx(0.0, abs=5.0)
        assert phase[np.searchsorted(lin.frequency_grid_rad_s(), 1.5 * lin.mechanical_mode().omega_n_rad_s)] \
            == pytest.approx(-180.0, abs=20.0)


@pytest.mark.parametrize("name, chamber", [("proportional_valve", None), ("closed_loop_position", "thermal")])
def test_loop_margins_are_those_of_the_loop_around_the_full_linearisation(name, chamber):
    """Where the controller is designed on a reduced model (a spool and a line; a thermal gas taken adiabatic),
    the margins' loop is broken around the full linearisation: closed with unity feedback its poles are the
    design's full-loop poles.  (Before, a scenario with a line raised a traceback and a thermal one gave the
    reduced model's margins.)"""
    import control as ct

    from pamsim.control.closed_loop import design_closed_loop
    from pamsim.control.margins import loop_margins, loop_transfer

    sc = pamsim.load_scenario(ROOT / "scenarios" / f"{name}.toml")
    if chamber:
        sc = sc.with_changes({"chamber": {"law": chamber}})
    closed = np.sort_complex(np.linalg.eigvals(ct.feedback(loop_transfer(sc), 1).A))
    full = np.sort_complex(design_closed_loop(sc).design.full_loop_poles)
    np.testing.assert_allclose(closed, full, rtol=1e-9)
    assert loop_margins(sc).phase_margin_deg > 30.0
