"""Muscles on elastic tendons (:class:`pamsim.components.series_tendon.SeriesTendon`): the rigid tendon as
the limit of a stiff one, the muscle's end at rest against hand calculations, the statics and its series
stiffness, the energy balance with the tendon's stored energy, slack, the backends, and bad input."""

from __future__ import annotations

import copy
import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from pamsim.elements.damping import LinearDamping, PaperDamping, increasing
from pamsim.joints.run import simulate_joint
from pamsim.joints.scenario import JointScenario, load_joint_scenario
from pamsim.joints.static import JointStatics
from pamsim.scenario import ScenarioError

ROOT = Path(__file__).resolve().parents[1]
ELASTIC = ROOT / "scenarios" / "antagonistic_elastic.toml"
SPEC = tomllib.loads(ELASTIC.read_text())


def _scenario(k_N_per_m=2000.0, duration_s=None, pressures_bar=None) -> JointScenario:
    """The shipped elastic pair with tendon stiffness ``k_N_per_m`` (None: rigid tendons)."""
    spec = copy.deepcopy(SPEC)
    for m, p in zip(spec["muscle"], pressures_bar or (None, None)):
        if k_N_per_m is None:
            m.pop("tendon_stiffness_N_per_m")
        else:
            m["tendon_stiffness_N_per_m"] = k_N_per_m
        if p is not None:
            m["pressure"]["supply_gauge_bar"] = p
    if duration_s is not None:
        spec["simulation"]["duration_s"] = duration_s
    return JointScenario.from_dict(spec, origin="elastic.toml", base_dir=ELASTIC.parent)


@pytest.fixture(scope="module")
def elastic():
    return simulate_joint(load_joint_scenario(ELASTIC), "python")


def test_the_inverse_damping_laws_give_back_the_force():
    """``velocity_m_s`` inverts ``force_N`` for the increasing laws; the paper's D1 < 0 is not increasing."""
    for law in (PaperDamping(1.01, 0.8), PaperDamping(0.3, 0.0), LinearDamping(1.01)):
        assert increasing(law)
        for F in (-25.0, -1e-3, 0.0, 2e-6, 0.7, 40.0):
            v = law.velocity_m_s(F)
            assert law.force_N(v) == pytest.approx(F, rel=1e-13, abs=1e-18)
    assert not increasing(PaperDamping(-1.01, 0.8))


def test_a_stiff_tendon_tends_to_the_rigid_one():
    """The link's angle on tendons of 1e4 and 1e5 N/m against the rigid pair's: the largest gap falls by
    about the ratio of the stiffnesses (the tendon's stretch, T / k, is what separates them)."""
    rigid = simulate_joint(_scenario(None), "python")
    gaps = []
    for k in (1e4, 1e5):
        res = simulate_joint(_scenario(k), "python")
        gaps.append(np.max(np.abs(np.interp(rigid.t_s, res.t_s, res.theta_rad) - rigid.theta_rad)))
    assert gaps[1] < 0.02 and 0.05 < gaps[1] / gaps[0] < 0.25, gaps


def test_each_muscle_end_rests_where_its_forces_balance_by_hand(elastic):
    """At the end of the run, with the link held: each tendon's pull is k times its stretch from the pulley's
    geometry (x_at_zero + side r theta, by hand), the muscle's static force (its element, called directly)
    differs from that pull by no more than its friction holds, and the tendons' torques and gravity balance
    within the bearing's Coulomb torque."""
    sc = load_joint_scenario(ELASTIC)
    theta = elastic.theta_rad[-1]
    torque = -SPEC["joint"]["link_mass_kg"] * 9.81 * SPEC["joint"]["com_distance_m"] * math.sin(theta)
    for table, (_, one) in zip(SPEC["muscle"], sc.muscles):
        name, k = table["name"], table["tendon_stiffness_N_per_m"]
        x = elastic.muscle(name, "x_m")[-1]
        path = table["x_at_zero_m"] + table["side"] * table["radius_m"] * theta
        T = k * max(x - path, 0.0)
        assert elastic.muscle(name, "F_tendon_N")[-1] == pytest.approx(T, rel=1e-12)
        F_static = one.build_model().static_force.force_N(x, elastic.muscle(name, "p_gauge_Pa")[-1])
        level = elastic.signals[f"{name}_friction.level_N"][-1]
        # The paper's level is zero where the load (F_static / g) outweighs the pressure (the extensor's at
        # 2 bar): that end creeps toward F_static = T and has reached it by the end.
        assert abs(F_static - T) <= level + 1e-9 * T and T > 10.0, (name, F_static, T, level)
        torque += table["side"] * table["radius_m"] * T
    assert elastic.final_mode.label == "stick"
    assert abs(torque) <= SPEC["joint"]["tau_coulomb_Nm"] * (1 + 1e-9)


def test_a_held_muscle_end_does_not_move_at_all(elastic):
    """Inside its friction band the muscle's end is held exactly (velocity zero, contraction constant bit
    for bit): no creep, as a regularised friction would give.  (The flexor's: the extensor's friction level
    is zero at its load, the paper's law clipped, so it has no band to be held in.)"""
    for name in ("flexor",):
        held = elastic.signals[f"{name}_series_spring.direction"] == 0.0
        x = elastic.muscle(name, "x_m")
        late = held & (elastic.t_s > 2.0)
        assert late.sum() > 100 and np.all(elastic.signals[f"{name}_series_spring.v_m_s"][held] == 0.0)
        runs = np.nonzero(late[:-1] & late[1:])[0]
        assert np.all(x[runs + 1] == x[runs])


def test_the_energy_balance_counts_what_the_tendons_store(elastic):
    """Work of the muscles' static forces = damping + friction + work on the link + the springs' energy
    (``slack_J`` is the remainder, zero while no tendon goes slack), and the link's own balance holds."""
    balance = elastic.energy_balance()
    assert balance["relative"] < 2e-5
    for name in ("flexor", "extensor"):
        stored = elastic.signals[f"{name}_series_spring.E_elastic_J"][-1]
        T = elastic.muscle(name, "F_tendon_N")[-1]
        assert stored == pytest.approx(T * T / (2 * 2000.0), rel=1e-12) and stored > 0.05
        assert abs(balance[f"{name}.slack_J"]) < 1e-6 * stored


def test_statics_find_the_series_equilibrium_and_its_stiffness_by_hand():
    """JointStatics on elastic tendons against a hand solution at three pressure pairs: each muscle's
    contraction from F_static(x) = k (x - x_path) (brentq on the element), the torque balance, and the
    stiffness of muscle and tendon in series, sum r^2 k_m k / (k_m + k) + m g d cos(theta), k_m = -dF/dx
    by central differences; and the exact stiffness against finite differences of the net torque."""
    sc = load_joint_scenario(ELASTIC)
    statics = JointStatics(sc)
    J = SPEC["joint"]
    mgd = J["link_mass_kg"] * 9.81 * J["com_distance_m"]
    for pressures in ((2.2e5, 2.0e5), (3.0e5, 3.0e5), (2.4e5, 2.7e5)):
        eq = statics.equilibrium(pressures)
        theta, tau, k_hand = eq.theta_rad, -mgd * math.sin(eq.theta_rad), mgd * math.cos(eq.theta_rad)
        for table, (_, one), p in zip(SPEC["muscle"], sc.muscles, pressures):
            force, k = one.build_model().static_force.force_N, table["tendon_stiffness_N_per_m"]
            path = table["x_at_zero_m"] + table["side"] * table["radius_m"] * theta
            x = brentq(lambda x: force(x, p) - k * max(x - path, 0.0), path, path + 0.05, xtol=1e-15)
            h = 1e-7
            k_m = -(force(x + h, p) - force(x - h, p)) / (2 * h)
            tau += table["side"] * table["radius_m"] * force(x, p)
            k_hand += table["radius_m"] ** 2 * k_m * k / (k_m + k)
        assert eq.on_limit is None and abs(tau) < 1e-9
        assert eq.k_Nm_per_rad == pytest.approx(k_hand, rel=1e-6)
        h = 1e-6
        fd = -(statics.net_torque_Nm(theta + h, pressures) - statics.net_torque_Nm(theta - h, pressures)) / (2 * h)
        assert eq.k_Nm_per_rad == pytest.approx(fd, rel=1e-6)


def test_a_slack_tendon_pulls_nothing_and_nothing_is_nan():
    """The extensor at no pressure, the flexor at 4 bar: the link swings to the flexor's side, the extensor's
    path lengthens past its muscle and its tendon goes slack, pulling exactly nothing."""
    res = simulate_joint(_scenario(2000.0, duration_s=1.5, pressures_bar=(4.0, 0.0)), "python")
    stretch = res.muscle("extensor", "stretch_m")
    T = res.muscle("extensor", "F_tendon_N")
    assert all(np.all(np.isfinite(v)) for v in res.signals.values())
    assert np.any(stretch < 0.0) and np.all(T[stretch <= 0.0] == 0.0) and np.all(T >= 0.0)


@pytest.mark.parametrize("backend", ["native", "fmu-cs"])
def test_the_backends_agree_on_elastic_tendons(elastic, backend):
    """The generated C (native engine, and the co-simulation FMU) follows the python run of the shipped file."""
    other = simulate_joint(load_joint_scenario(ELASTIC), backend)
    assert abs(other.theta_rad[-1] - elastic.theta_rad[-1]) < 1e-5
    for name in ("flexor", "extensor"):
        assert abs(other.muscle(name, "x_m")[-1] - elastic.muscle(name, "x_m")[-1]) < 1e-6


@pytest.mark.parametrize("change, key", [
    (lambda m: m.update(tendon_stiffness_N_per_m=0.0), "tendon_stiffness_N_per_m"),
    (lambda m: m.update(tendon_stiffness_N_per_m="stiff"), "tendon_stiffness_N_per_m"),
    (lambda m: m["model"].update(damping="paper"), "model.damping"),
    (lambda m: m["model"].update(damping="none"), "model.damping"),
])
def test_bad_tendons_are_refused_by_key(tmp_path, change, key):
    """A stiffness that is not a positive number, and a damping law a massless muscle end cannot move under,
    are refused naming the muscle and the key; the command line exits 2 without a traceback."""
    spec = copy.deepcopy(SPEC)
    change(spec["muscle"][1])
    with pytest.raises(ScenarioError, match=f"muscle 'extensor'.{key}"):
        JointScenario.from_dict(spec, origin="elastic.toml", base_dir=ELASTIC.parent)
    if key == "model.damping" and spec["muscle"][1]["model"]["damping"] == "paper":
        path = tmp_path / "bad.toml"
        path.write_text(ELASTIC.read_text().replace('damping = "linear"', 'damping = "paper"'))
        done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(path), "-o", str(tmp_path / "out")],
                              capture_output=True, text=True)
        assert done.returncode == 2 and "model.damping" in done.stderr and "Traceback" not in done.stderr
        assert not (tmp_path / "out").exists()


def _prescribed_spec(pressures_bar=(2.0, 2.0)) -> dict:
    spec = copy.deepcopy(SPEC)
    for m, p in zip(spec["muscle"], pressures_bar):
        m["pressure"] = {"source": "prescribed", "prescribed": {"kind": "constant", "value_gauge_bar": p}}
    return spec


@pytest.mark.parametrize("p_bar", [(2.2, 2.0), (2.5, 2.0), (4.0, 4.2)])
def test_the_linear_model_on_elastic_tendons_has_the_series_stiffness_and_the_statics_gains(p_bar):
    """Each muscle's end is a state, at its own rest; the stiffness output is the statics' series one (the
    chain rule there against CasADi's here, and a central difference of the net torque at rest), and the
    model's gain from each pressure to the angle, ``D - C A^-1 B``, is the slope of the statics'
    equilibrium angle against that pressure (central differences of 100 Pa)."""
    from pamsim.joints.linear import linearize_joint

    scenario = JointScenario.from_dict(_prescribed_spec())
    p = [v * 1e5 for v in p_bar]
    lm = linearize_joint(scenario, p)
    assert lm.states == ("joint.theta_rad", "joint.omega_rad_s", "flexor_series_spring.x_m",
                         "extensor_series_spring.x_m")
    statics = JointStatics(scenario)
    eq = statics.equilibrium(p)
    assert lm.theta0_rad == eq.theta_rad
    assert lm.k0_Nm_per_rad == pytest.approx(eq.k_Nm_per_rad, rel=1e-12)
    h = 1e-6
    k_fd = -(statics.net_torque_Nm(eq.theta_rad + h, p) - statics.net_torque_Nm(eq.theta_rad - h, p)) / (2 * h)
    assert lm.k0_Nm_per_rad == pytest.approx(k_fd, rel=1e-7)
    rigid_spec = _prescribed_spec()
    for m in rigid_spec["muscle"]:
        del m["tendon_stiffness_N_per_m"]
    rigid = linearize_joint(JointScenario.from_dict(rigid_spec), p)
    assert lm.k0_Nm_per_rad < 0.8 * rigid.k0_Nm_per_rad  # the tendons in series soften the joint
    gain = lm.D - lm.C @ np.linalg.solve(lm.A, lm.B)
    for j in range(2):
        dp = np.zeros(2)
        dp[j] = 100.0
        slope = (statics.equilibrium(list(p + dp)).theta_rad - statics.equilibrium(list(p - dp)).theta_rad) / 200.0
        assert gain[0, j] == pytest.approx(slope, rel=1e-6)
    assert np.all(lm.poles().real < 0.0)  # the ends' own poles fast and real, the link's ringing slow


def _step_gap(dp_bar: float) -> tuple[float, float]:
    """The frictionless elastic pair at rest at 2.2 and 2 bar, the flexor's pressure stepped by ``dp_bar``
    at 2 s: the largest angle change after the step on the python backend, and its largest gap to the
    linear model's step response over 1.5 s (scipy's ``lsim``)."""
    from scipy.signal import StateSpace, lsim

    from pamsim.joints.linear import linearize_joint

    spec = _prescribed_spec((2.2, 2.0))
    for m in spec["muscle"]:
        m["model"]["friction"] = "none"
    spec["joint"]["tau_coulomb_Nm"] = 0.0
    lm = linearize_joint(JointScenario.from_dict(copy.deepcopy(spec)), [2.2e5, 2.0e5])
    spec["joint"]["initial_angle_rad"] = lm.theta0_rad
    spec["muscle"][0]["pressure"]["prescribed"] = {"kind": "steps", "times_s": [0.0, 2.0],
                                                   "values_gauge_bar": [2.2, 2.2 + dp_bar]}
    spec["simulation"]["duration_s"] = 3.5
    spec["solver"]["rtol"] = 1e-8
    run = simulate_joint(JointScenario.from_dict(spec), "python")
    after = run.t_s >= 2.0
    u = np.zeros((int(after.sum()), 3))
    u[:, 0] = dp_bar * 1e5
    _, y, _ = lsim(StateSpace(lm.A, lm.B, lm.C, lm.D), u, run.t_s[after] - 2.0)
    moved = run.theta_rad[after] - lm.theta0_rad
    return float(np.abs(moved).max()), float(np.abs(moved - y[:, 0]).max())


def test_the_linear_model_on_elastic_tendons_follows_a_small_pressure_step():
    """The nonlinear joint, friction dropped as the linearisation drops it, after a pressure step of 2 mbar
    and of 4 mbar from its equilibrium: its angle follows the linear model's step response (ringing at the
    series stiffness) within 1e-3 of the response, and the gap is the nonlinearity's, growing as the step
    squared (4.0 times for twice the step, within 10 %)."""
    peak, gap = _step_gap(0.002)
    peak2, gap2 = _step_gap(0.004)
    assert peak > 4e-3 and gap < 1e-3 * peak
    assert gap2 / gap == pytest.approx(4.0, rel=0.1)


def test_pamsim_linearize_prints_an_elastic_joints_model(tmp_path):
    """The command linearises a joint on elastic tendons whose pressures are prescribed, its ends' states
    among the model's, as JSON."""
    import json

    path = tmp_path / "elastic_prescribed.toml"
    text = ELASTIC.read_text()
    for p in ("2.2", "2.0"):
        text = text.replace(f'source = "valve"\nsupply_gauge_bar = {p}\nvalve_open_time_s = 0.5',
                            f'source = "prescribed"\nprescribed = {{ kind = "constant", value_gauge_bar = {p} }}')
    path.write_text(text)
    done = subprocess.run([sys.executable, "-m", "pamsim", "linearize", str(path), "--json"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    rep = json.loads(done.stdout)
    assert rep["states"][2:] == ["flexor_series_spring.x_m", "extensor_series_spring.x_m"]
    statics = JointStatics(JointScenario.from_dict(_prescribed_spec((2.2, 2.0))))
    assert rep["k0_Nm_per_rad"] == pytest.approx(statics.equilibrium([2.2e5, 2.0e5]).k_Nm_per_rad, rel=1e-12)


# ---------------------------------------------------------------- hysteresis elements on the muscle's end
ELEMENTS = {"model": "maxwell_slip", "slip_displacement_m": [2e-4, 1e-3, 4e-3], "share": [1.0, 1.0, 1.0]}


def _with_elements(pressures_bar=(None, None), duration_s=1.5, **table) -> JointScenario:
    spec = copy.deepcopy(SPEC)
    spec["muscle"][0]["hysteresis"] = {**ELEMENTS, **table}
    for m, p in zip(spec["muscle"], pressures_bar):
        if p is not None:
            m["pressure"]["supply_gauge_bar"] = p
    spec["simulation"]["duration_s"] = duration_s
    return JointScenario.from_dict(spec, origin="elastic.toml", base_dir=ELASTIC.parent)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_maxwell_slip_elements_on_the_muscles_end_join_its_balance(backend):
    """The flexor's elements act on its massless end: where the end rests, its static force and the elements'
    force together equal the tendon's pull (by hand from the signals; their force is 0.68 N of a 20.4 N pull,
    which a balance that left them out missed), and the link rests elsewhere than with elements too weak to
    matter."""
    sc = _with_elements()
    run = simulate_joint(sc, backend)
    one = sc.muscles[0][1]
    x, p = run.muscle("flexor", "x_m")[-1], run.muscle("flexor", "p_gauge_Pa")[-1]
    F_static = one.build_model().static_force.force_N(x, p)
    F_elements = run.signals["flexor_hysteresis.F_N"][-1]
    T = run.muscle("flexor", "F_tendon_N")[-1]
    assert abs(F_elements) > 0.5 and T > 15.0
    assert abs(run.signals["flexor_series_spring.v_m_s"][-1]) < 1e-6  # at rest: the damping takes < 1e-6 N
    assert F_static + F_elements == pytest.approx(T, abs=1e-5)
    weak = simulate_joint(_with_elements(share=[0.01] * 3), backend)
    assert abs(weak.theta_rad[-1] - run.theta_rad[-1]) > 0.02


def test_elements_resting_on_their_limit_on_a_held_link_take_few_events():
    """The flexor at 4 bar against an empty extensor drives the link onto its stop; the flexor's end then
    comes to rest with its first element on its slip displacement, a stiff node (the element's spring over the
    end's 1 N s/m).  Both backends keep integrating it as stiff across the element's switches (native: its
    Rodas4; python: BDF after such a switch): 7 and 6 events, where each once restarted non-stiff and
    crossed the limit again at every few steps (more than 20000 events by 0.9 s), and the end rests at the
    same place on both."""
    sc = _with_elements(pressures_bar=(4.0, 0.0), duration_s=3.0)
    runs = {b: simulate_joint(sc, b) for b in ("python", "native")}
    for run in runs.values():
        assert run.theta_rad[-1] == pytest.approx(SPEC["joint"]["theta_max_rad"], abs=1e-9)
        assert len(run.transitions) < 100
    for name in ("x_m", "F_tendon_N"):
        assert runs["native"].muscle("flexor", name)[-1] == pytest.approx(runs["python"].muscle("flexor", name)[-1],
                                                                          rel=1e-5)


def test_presliding_damping_on_an_elastic_tendon_is_refused_by_key():
    with pytest.raises(ScenarioError, match="muscle 'flexor'.hysteresis.damping_N_s_per_m = 100"):
        _with_elements(damping_N_s_per_m=100.0)


@pytest.mark.parametrize("damping", ["paper", "none", "linear"])
def test_the_assembly_itself_refuses_a_damping_a_massless_end_cannot_move_under(damping):
    """Built from Python (as the MuJoCo coupling does), not from a joint scenario: on an elastic tendon the
    paper's D1 < 0 and no damping are refused where the muscle is assembled, naming the law; on a rigid
    tendon, and with linear damping on an elastic one, the muscle is built."""
    from pamsim.assemblies.muscle_only import muscle_only_assembly
    from pamsim.scenario import Scenario

    spec = tomllib.loads((ROOT / "scenarios" / "acra2012_fig4.toml").read_text())
    spec.setdefault("model", {})["damping"] = damping
    model = Scenario.from_dict(spec, base_dir=ROOT / "scenarios").build_model()
    assert isinstance(model.damping, PaperDamping) == (damping == "paper")
    muscle_only_assembly(model, 0.3, 9.81)  # rigid: the muscle's end moves with the load, any law will do
    if damping == "linear":
        muscle_only_assembly(model, 0.3, 9.81, tendon_stiffness_N_per_m=2000.0)
        return
    with pytest.raises(ValueError, match=f"damping '{damping}' on a massless muscle end.*'linear'"):
        muscle_only_assembly(model, 0.3, 9.81, tendon_stiffness_N_per_m=2000.0)


@pytest.mark.parametrize("elastic", [True, False])
def test_a_spring_on_the_muscles_end_enters_its_balance_and_its_energy(elastic):
    """A ``linear_spring`` added on the flexor's end (1000 N/m, free at 20 mm): its work is counted in the
    muscle's energy balance, which closes (``slack_J`` near zero, where it was minus the spring's work), on
    an elastic tendon and on a rigid one."""
    spec = copy.deepcopy(SPEC)
    spec["simulation"]["duration_s"] = 1.5
    if not elastic:
        for m in spec["muscle"]:
            m.pop("tendon_stiffness_N_per_m")
    spec["muscle"][0]["component"] = [{"name": "spring", "type": "linear_spring", "k_N_per_m": 1000.0,
                                       "x_free_m": 0.02, "connect": {"flange": "load.flange"}}]
    run = simulate_joint(JointScenario.from_dict(spec, origin="elastic.toml", base_dir=ELASTIC.parent), "python")
    balance = run.energy_balance()
    W_spring = float(run.signals["flexor_spring.W_spring_J"][-1])
    assert abs(W_spring) > 1e-4
    assert abs(balance["flexor.slack_J"]) < 1e-3 * abs(W_spring), (balance["flexor.slack_J"], W_spring)


def _both_with_elements(shares, max_events=5000) -> JointScenario:
    """The shipped elastic pair with three elements (0.2, 1 and 4 mm) of ``shares`` on each muscle."""
    spec = copy.deepcopy(SPEC)
    for m in spec["muscle"]:
        m["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": [2e-4, 1e-3, 4e-3], "share": list(shares)}
    spec["solver"]["max_events"] = max_events
    return JointScenario.from_dict(spec, origin="elastic.toml", base_dir=ELASTIC.parent)


@pytest.mark.parametrize("shares", [(0.3, 0.3, 0.4), (0.2, 0.3, 0.5)])
def test_elements_at_rest_on_their_limits_on_both_muscles_run_on_python_as_on_native(shares):
    """Both muscles with three elements each: their ends come to rest with elements on their limits while
    the link is held, every element's deflection held to the last bits.  Python ran into its event limit
    there (more than 5000 events by 0.82 s: an element's deflection rounded a few ulps inside its limit
    counted as having left it, and BDF, restarted with a step estimated afresh, crossed it again at
    once); it now runs the 3 s (220 and 30 events; native 18 and 101), the angle within 1e-5 rad of the
    native engine's at every sample and each muscle's end at the same place."""
    sc = _both_with_elements(shares)
    py, nat = simulate_joint(sc, "python"), simulate_joint(sc, "native")
    assert len(py.transitions) < 500
    assert np.abs(py.theta_rad - nat.theta_rad).max() < 1e-5
    for m in ("flexor", "extensor"):
        assert py.muscle(m, "x_m")[-1] == pytest.approx(nat.muscle(m, "x_m")[-1], rel=1e-5)


def test_where_python_switches_an_element_again_and_again_it_says_so():
    """At its event limit, where the last hundred events all kept the mode (elements reaching their limits
    on a held link), python's message says so and names the native backend.  (A test of the message: it
    needs python to switch this pair's elements in place more than a hundred times in a row, which it
    still does, 220 events in all.)"""
    from pamsim.errors import SolverFailure

    with pytest.raises(SolverFailure, match=r"more than 150 events .*hysteresis.slip1.* in mode stick: .*native "
                                            r"backend integrates it as stiff"):
        simulate_joint(_both_with_elements((0.3, 0.3, 0.4), max_events=150), "python")


# ---------------------------------------------------------------- the angle-stiffness controller on elastic tendons
CONTROLLED = ROOT / "scenarios" / "pair_angle_stiffness.toml"


def _controlled_on_tendons(stiffness_Nm_per_rad: float) -> dict:
    """The controlled pair on 2 kN/m tendons (linear damping, as a massless end needs) at a commanded stiffness."""
    spec = tomllib.loads(CONTROLLED.read_text())
    for m in spec["muscle"]:
        m["tendon_stiffness_N_per_m"] = 2000.0
        m["model"]["damping"] = "linear"
    spec["controller"]["stiffness_Nm_per_rad"] = stiffness_Nm_per_rad
    return spec


def test_the_controller_on_elastic_tendons_rests_the_link_with_the_series_stiffness_and_meets_its_spec():
    """The feedforward's pressures hold the link at each angle of its table with the commanded series
    stiffness (the statics'); the PID is designed on that stiffness (the ends at rest: their poles, near
    -2600 1/s, lie 30 times beyond the 80 rad/s bandwidth), so the full linear loop, ends included, is stable
    with its three slow poles within a factor 1.6 of the designed -80 1/s; and the native run meets the
    scenario's spec.  Designed on the angle row of A (the ends held, 0.40 N m/rad), the gains were refused."""
    from pamsim.joints.control import controller_of, metrics, spec_failures
    from pamsim.joints.linear import linearize_joint

    scenario = JointScenario.from_dict(_controlled_on_tendons(0.1))
    controller = controller_of(scenario)
    statics = JointStatics(scenario)
    for theta, p in zip(controller.feedforward.grid_rad, controller.feedforward.p_Pa):
        assert abs(statics.net_torque_Nm(theta, p)) < 1e-11
        assert statics.stiffness_Nm_per_rad(theta, p) == pytest.approx(0.1, rel=1e-9)
    g, w = controller.gains, scenario.controller["bandwidth_rad_s"]
    lm = linearize_joint(scenario, list(controller.feedforward(0.0)))
    # the table's pressures interpolated between its angles: the stiffness to 1e-5
    assert lm.k0_Nm_per_rad == pytest.approx(0.1, rel=1e-5) and -lm.A[1, 0] * scenario.joint["inertia_kg_m2"] > 0.3
    n, b = lm.A.shape[0], lm.B[:, 2]
    closed = np.zeros((n + 1, n + 1))
    closed[:n, :n] = lm.A
    closed[:n, 0] -= b * g.Kp
    closed[:n, 1] -= b * g.Kd
    closed[:n, n] = b * g.Ki
    closed[n, 0] = -1.0
    poles = sorted(np.linalg.eigvals(closed), key=abs)
    assert all(-1.6 * w < z.real < -w / 1.6 for z in poles[:3]) and all(z.real < -20 * w for z in poles[3:])
    run = controller.run("native")
    measured = metrics(run, controller.reference, scenario.controller["settle_s"], scenario.duration_s)
    assert spec_failures(measured, scenario.controller["spec"]) == []
    assert np.max(run.theta_rad) > 0.29 and np.min(run.theta_rad) < -0.39


def test_a_stiffness_the_elastic_pair_cannot_reach_is_refused_by_key(tmp_path):
    """0.05 N m/rad is below what the pair on its tendons can hold at -0.44 rad with the torques balanced
    (the least, over pressures in [0, 4.5] bar, leaves 0.007 N m/rad): exit code 2, the key named, no
    traceback, nothing written.  Newton's pressures there clip one muscle to 0 bar, where its tendon hangs
    slack and the Jacobian is singular: that raised numpy's LinAlgError."""
    text = CONTROLLED.read_text().replace("[[muscle]]\n", "[[muscle]]\ntendon_stiffness_N_per_m = 2000.0\n")
    text = re.sub(r'damping = "\w+"', 'damping = "linear"', text)
    text = re.sub(r"\nstiffness_Nm_per_rad = [0-9.e-]+", "\nstiffness_Nm_per_rad = 0.05", text)
    assert tomllib.loads(text) == _controlled_on_tendons(0.05)
    path = tmp_path / "soft.toml"
    path.write_text(text)
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(path), "-o", str(tmp_path / "out")],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "controller.stiffness_Nm_per_rad = 0.05: no pressures within [0, 4.5] bar" in done.stderr
    assert not (tmp_path / "out").exists()


def test_the_elastic_linear_models_stiffness_row_is_the_statics_slope_along_the_rest():
    """The stiffness output's derivatives (C's and D's second row): along the ends' rest, ``dk/dtheta`` is
    ``C[1, theta] + C[1, ends] dx_rest/dtheta`` and ``dk/dp`` is ``D[1, p] + C[1, ends] dx_rest/dp``, each against
    central differences of the statics' stiffness and of its rest state (1e-6)."""
    from pamsim.joints.linear import linearize_joint

    scenario = JointScenario.from_dict(_prescribed_spec())
    p = np.array([2.5e5, 2.0e5])
    lm = linearize_joint(scenario, list(p))
    statics = JointStatics(scenario)
    ends = list(lm.states[2:])

    def rest(theta, pressures):
        state = statics.rest_state(theta, list(pressures))
        return np.array([state[n] for n in ends])

    h, th = 1e-5, lm.theta0_rad
    slope = (statics.stiffness_Nm_per_rad(th + h, list(p)) - statics.stiffness_Nm_per_rad(th - h, list(p))) / (2 * h)
    follow = (rest(th + h, p) - rest(th - h, p)) / (2 * h)
    assert lm.C[1, 0] + lm.C[1, 2:] @ follow == pytest.approx(slope, rel=1e-6)
    for j in range(2):
        dp = np.zeros(2)
        dp[j] = 10.0
        slope = (statics.stiffness_Nm_per_rad(th, list(p + dp)) - statics.stiffness_Nm_per_rad(th, list(p - dp))) / 20.0
        follow = (rest(th, p + dp) - rest(th, p - dp)) / 20.0
        assert lm.D[1, j] + lm.C[1, 2:] @ follow == pytest.approx(slope, rel=1e-6)


def test_a_spring_on_an_elastic_muscles_end_enters_the_statics_and_the_linear_model():
    """A 1 kN/m spring (free at 20 mm) on the flexor's end: the statics rest the link where the frictionless
    joint comes to rest on native (they took the end's balance without the spring: 0.309 rad against the run's
    -0.252), and the linear model's stiffness is the statics' there."""
    from pamsim.joints.linear import linearize_joint

    spec = _prescribed_spec((2.2, 2.0))
    spec["muscle"][0]["component"] = [{"type": "linear_spring", "name": "spring", "k_N_per_m": 1000.0,
                                       "x_free_m": 0.02, "connect": {"flange": "load.flange"}}]
    statics = JointStatics(JointScenario.from_dict(copy.deepcopy(spec)))
    eq = statics.equilibrium([2.2e5, 2.0e5])
    lm = linearize_joint(JointScenario.from_dict(copy.deepcopy(spec)), [2.2e5, 2.0e5])
    assert lm.k0_Nm_per_rad == pytest.approx(eq.k_Nm_per_rad, rel=1e-12)
    for m in spec["muscle"]:
        m["model"]["friction"] = "none"
    spec["joint"]["tau_coulomb_Nm"] = 0.0
    spec["simulation"]["duration_s"] = 4.0
    run = simulate_joint(JointScenario.from_dict(spec), "native")
    assert abs(run.theta_rad[-1] - eq.theta_rad) < 1e-6


def test_an_elastic_linearisation_reports_its_elements_at_the_ends_rest():
    """Maxwell-slip elements on the flexor's end: the stick state reported gives each element the stiffness
    ``w F_c / delta`` that the model's own row of the end holds (``dv/dz_i = -k_i / c``, c = 1.01 N s/m, the
    linear damping), at the friction level of the end at its rest (not at contraction 0, where it is 0)."""
    from pamsim.joints.linear import linearize_joint

    spec = _prescribed_spec((2.2, 2.0))
    spec["muscle"][0]["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": [1e-3, 4e-3], "share": [0.5, 0.5]}
    lm = linearize_joint(JointScenario.from_dict(spec), [2.2e5, 2.0e5])
    elements = dict(lm.hysteresis)["flexor"].elements
    row = lm.states.index("flexor_series_spring.x_m")
    for i, e in enumerate(elements, start=1):
        assert e["state"] == "stick" and e["k_N_per_m"] > 10.0
        assert e["k_N_per_m"] == pytest.approx(-lm.A[row, lm.states.index(f"flexor_hysteresis.z{i}_m")] * 1.01, rel=1e-9)
