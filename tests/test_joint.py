"""Muscles on a rotary joint: statics against a hand-written torque balance, the exact stiffness against
finite differences, symmetry, the energy balance, slack tendons, and bad scenarios."""

from __future__ import annotations

import copy
import re
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import pamsim
from pamsim.joints import JointScenario, load_joint_scenario, simulate_joint
from pamsim.joints.static import JointStatics
from pamsim.scenario import ScenarioError

from joint_specs import on_levers

ROOT = Path(__file__).resolve().parents[1]
PAIR_FILE = ROOT / "scenarios" / "antagonistic_pair.toml"
PAIR = tomllib.loads(PAIR_FILE.read_text())
FESTO = tomllib.loads((ROOT / "scenarios" / "antagonistic_festo.toml").read_text())
SHIPPED_PAIRS = {"shadow_acra": PAIR, "festo_ogden": FESTO}
"""The shipped pairs: Shadow muscles with the ACRA 2012 model, Festo DMSP-10 muscles with the Ogden model."""
BAR = 1e5


def prescribed(spec: dict, pressures_bar, time_s: float = 0.1) -> dict:
    """``spec`` with each muscle's pressure a step to ``pressures_bar`` at ``time_s``."""
    spec = copy.deepcopy(spec)
    for table, p in zip(spec["muscle"], pressures_bar):
        table["pressure"] = {"source": "prescribed",
                             "prescribed": {"kind": "step", "time_s": time_s, "final_gauge_bar": p}}
    return spec


def static_forces(spec: dict) -> list:
    """Each muscle's static force element, as a one-muscle scenario of its [muscle.model] builds it."""
    return [pamsim.Scenario.from_dict({"model": t["model"], "load": {"weight_N": 1.0}, "simulation": {"duration_s": 1.0},
                                       "pressure": {"source": "prescribed", "prescribed": {"kind": "constant",
                                                                                          "value_gauge_bar": 0.0}}}
                                      ).build_model().static_force for t in spec["muscle"]]


def hand_torque_Nm(spec: dict, forces: list, theta: float, pressures_Pa) -> float:
    """The torque balance written out by hand: each muscle's static force (its element, called on
    floats) at its contraction x0 + side r theta, a tendon that only pulls, and the link's weight."""
    j = spec["joint"]
    total = -j["link_mass_kg"] * 9.81 * j["com_distance_m"] * math.sin(theta - j.get("theta_down_rad", 0.0))
    for table, force, p in zip(spec["muscle"], forces, pressures_Pa):
        x = table["x_at_zero_m"] + table["side"] * table["radius_m"] * theta
        total += table["side"] * table["radius_m"] * max(float(force.force_N(x, p)), 0.0)
    return total


PAIRS_BAR = [(a, b) for a in (1.5, 2.5, 3.5) for b in (1.5, 2.5, 3.5)]


@pytest.mark.parametrize("pair", SHIPPED_PAIRS)
@pytest.mark.parametrize("p_bar", PAIRS_BAR)
def test_equilibrium_is_the_hand_torque_balance(p_bar, pair):
    """At 9 pressure pairs the equilibrium from the generated code is the root of the hand-written
    torque balance (to 1e-10 rad), or the limit it pushes the link onto."""
    spec = SHIPPED_PAIRS[pair]
    statics = JointStatics(JointScenario.from_dict(spec))
    p = [v * BAR for v in p_bar]
    eq = statics.equilibrium(p)
    lo, hi = spec["joint"]["theta_min_rad"], spec["joint"]["theta_max_rad"]
    forces = static_forces(spec)
    tau = lambda t: hand_torque_Nm(spec, forces, t, p)  # noqa: E731
    if eq.on_limit is None:
        want = brentq(tau, lo, hi, xtol=1e-15)
        assert eq.theta_rad == pytest.approx(want, abs=1e-10)
        assert abs(statics.net_torque_Nm(eq.theta_rad, p) - tau(eq.theta_rad)) <= 1e-14
    else:
        assert np.sign(tau(lo)) == np.sign(tau(hi)) and eq.theta_rad == {"lower": lo, "upper": hi}[eq.on_limit]
        assert (tau(hi) > 0) == (eq.on_limit == "upper")
    if p_bar[0] == p_bar[1]:
        assert eq.on_limit is None and abs(eq.theta_rad) < 0.01  # only the link's weight moves it off zero


@pytest.mark.parametrize("pair", SHIPPED_PAIRS)
@pytest.mark.parametrize("theta", [-0.6, -0.1, 0.0, 0.25, 0.7])
@pytest.mark.parametrize("p_bar", [(1.0, 1.0), (3.0, 2.0), (2.0, 4.0)])
def test_stiffness_is_the_derivative_of_the_net_torque(theta, p_bar, pair):
    """The exact ``-d tau / d theta`` agrees with a central finite difference of the net torque to 1e-6."""
    statics = JointStatics(JointScenario.from_dict(SHIPPED_PAIRS[pair]))
    p = [v * BAR for v in p_bar]
    h = 1e-5
    fd = -(statics.net_torque_Nm(theta + h, p) - statics.net_torque_Nm(theta - h, p)) / (2 * h)
    assert statics.stiffness_Nm_per_rad(theta, p) == pytest.approx(fd, rel=1e-6)


def test_co_contraction_raises_the_stiffness_at_the_same_angle():
    """Equal pressures on the pair hold the link near zero; raising both raises the stiffness."""
    statics = JointStatics(JointScenario.from_dict(PAIR))
    ks = [statics.equilibrium([p * BAR, p * BAR]) for p in (1.5, 2.5, 3.5)]
    assert all(abs(e.theta_rad) < 0.01 for e in ks)
    assert ks[0].k_Nm_per_rad < ks[1].k_Nm_per_rad < ks[2].k_Nm_per_rad


def symmetric(spec: dict) -> dict:
    """``spec`` without gravity and without Coulomb friction (the bearing's and the muscles'), so that only
    the symmetry of the pair, not friction holding the link, keeps it at zero."""
    spec = copy.deepcopy(spec)
    spec["joint"].update(link_mass_kg=0.0, tau_coulomb_Nm=0.0)
    for table in spec["muscle"]:
        table["model"] = dict(table["model"], friction="none", damping="none")
    return spec


def test_equal_pressures_without_gravity_hold_the_angle_at_zero_exactly():
    spec = prescribed(symmetric(PAIR), (2.5, 2.5))
    res = simulate_joint(JointScenario.from_dict(spec))
    assert np.all(res.theta_rad == 0.0) and np.all(res.omega_rad_s == 0.0)
    assert res.muscle("flexor", "F_tendon_N")[-1] > 10.0  # both pull, and cancel


def test_swapping_the_muscles_mirrors_the_run():
    """The pair with its muscles' sides and pressures swapped turns the other way, by the same angle."""
    spec = prescribed(symmetric(PAIR), (3.0, 2.0))
    mirror = copy.deepcopy(spec)
    mirror["muscle"] = [dict(t, side=-t["side"]) for t in reversed(copy.deepcopy(spec["muscle"]))]
    mirror["muscle"][0]["pressure"], mirror["muscle"][1]["pressure"] = spec["muscle"][1]["pressure"], spec["muscle"][0]["pressure"]
    mirror["muscle"] = list(reversed(mirror["muscle"]))
    a, b = (simulate_joint(JointScenario.from_dict(s)) for s in (spec, mirror))
    assert np.max(np.abs(a.theta_rad)) > 0.1
    np.testing.assert_allclose(b.theta_rad, -a.theta_rad, rtol=0, atol=1e-12)
    mirrored = {"release_up": "release_down", "release_down": "release_up", "stop_high": "stop_low",
                "stop_low": "stop_high", "velocity_zero": "velocity_zero"}
    assert [e.kind for e in a.transitions] == [mirrored[e.kind] for e in b.transitions]
    assert [e.t_s for e in a.transitions] == [e.t_s for e in b.transitions]


def test_the_shipped_pair_settles_within_the_friction_band_and_balances_its_energy():
    scenario = load_joint_scenario(PAIR_FILE)
    res = simulate_joint(scenario)
    balance = res.energy_balance()
    assert balance["relative"] < 2e-5
    assert balance["flexor.W_tendon_J"] > 0 > balance["extensor.W_tendon_J"]
    statics = JointStatics(scenario)
    p_end = [res.muscle(m, "p_gauge_Pa")[-1] for m in res.muscles]
    eq = statics.equilibrium(p_end)
    assert res.final_mode.name == "STICK" and eq.on_limit is None
    # held where the net torque is within the bearing's Coulomb level (the muscles' is zero at this load)
    assert abs(statics.net_torque_Nm(res.theta_rad[-1], p_end)) <= PAIR["joint"]["tau_coulomb_Nm"] + 1e-9
    assert abs(res.theta_rad[-1] - eq.theta_rad) <= PAIR["joint"]["tau_coulomb_Nm"] / eq.k_Nm_per_rad + 1e-9


def test_a_tendon_never_pushes_and_no_nan_appears():
    """A muscle whose forces add up to a push (its static force kept negative past its free contraction,
    its pressure zero) leaves its tendon slack: zero force and torque, and no NaN anywhere."""
    spec = prescribed(PAIR, (4.0, 0.0))
    for table in spec["muscle"]:
        table["model"] = dict(table["model"], static_force_negative="keep")
    res = simulate_joint(JointScenario.from_dict(spec))
    ext_static = res.signals["extensor_muscle.F_static_N"]
    assert np.min(ext_static) < -1.0  # it would push
    assert np.all(res.muscle("extensor", "F_tendon_N") >= 0.0)
    slack = res.signals["extensor_pulley.taut"] == 0.0
    assert slack.sum() > 100 and np.all(res.muscle("extensor", "tau_Nm")[slack] == 0.0)
    assert all(np.all(np.isfinite(v)) for v in res.signals.values())


BAD = [
    (lambda s: s["muscle"][0].update(radius_m=0.0), "muscle 'flexor'.radius_m = 0.0: must be > 0"),
    (lambda s: s["joint"].update(inertia_kg_m2=-1.0), "joint.inertia_kg_m2 = -1.0: must be > 0"),
    (lambda s: s["joint"].update(theta_min_rad=0.9), "joint.theta_min_rad = 0.9: must be below joint.theta_max_rad"),
    (lambda s: s["muscle"][1].update(name="flexor"), "muscle[1].name = 'flexor': is given to two muscles"),
    (lambda s: s["muscle"][1].pop("pressure"), "muscle 'extensor' has no [muscle.pressure] table"),
    (lambda s: s["muscle"][0].update(side=2), "muscle 'flexor'.side = 2: must be 1"),
    (lambda s: s["joint"].update(theta_max_rad=3.0), "muscle 'extensor' would contract to -10.00 mm there, outside its range"),
    (lambda s: s["muscle"][0]["pressure"].update(supply_gauge_bar=-1.0), "muscle 'flexor': pressure.supply_gauge_bar"),
]


@pytest.mark.parametrize("change, message", BAD, ids=[m.split(":")[0][:40] for _, m in BAD])
def test_bad_joint_scenarios_are_refused_by_key(change, message):
    spec = copy.deepcopy(PAIR)
    change(spec)
    with pytest.raises(ScenarioError) as info:
        JointScenario.from_dict(spec, origin="pair.toml")
    assert message in str(info.value) and str(info.value).startswith("pair.toml")


def test_pamsim_run_writes_a_joint_run_and_refuses_what_it_cannot_run(tmp_path):
    """``pamsim run`` on a joint scenario writes its CSV, JSON and figure; a bad one and another backend
    exit 2 with a message naming the key, and write nothing."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(PAIR_FILE), "-o", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    summary = __import__("json").loads((out / "antagonistic_pair.json").read_text())
    eq = summary["equilibrium_at_final_pressures"]
    assert abs(summary["final_theta_rad"] - eq["theta_rad"]) <= PAIR["joint"]["tau_coulomb_Nm"] / eq["k_Nm_per_rad"]
    assert (out / "antagonistic_pair.png").stat().st_size > 10_000
    header = (out / "antagonistic_pair.csv").read_text().splitlines()[0].split(",")
    assert header[:4] == ["t_s", "theta_rad", "omega_rad_s", "mode"] and "extensor.F_tendon_N" in header
    bad = tmp_path / "bad.toml"
    bad.write_text(PAIR_FILE.read_text().replace("inertia_kg_m2 = 2.0e-5", "inertia_kg_m2 = 0.0"))
    for args, message in [([str(bad)], "joint.inertia_kg_m2 = 0.0: must be > 0")]:
        again = subprocess.run([sys.executable, "-m", "pamsim", "run", *args, "-o", str(tmp_path / "none")],
                               capture_output=True, text=True)
        assert again.returncode == 2 and message in again.stderr and "Traceback" not in again.stderr
        assert not (tmp_path / "none").exists()


def test_exact_jacobians_of_the_joint_agree_with_central_differences():
    """df/dx, df/du, dy/dx, dy/du of the pair (the joint, the pulleys, every muscle's components) at 1,000
    random states, inputs and modes, to 1e-7 relative; an entry whose step straddles a kink (a slack
    tendon, |omega|, the valve's switches) is counted, not tested: at most 1 % of them."""
    from test_components import _fd_jacobian

    flat = JointScenario.from_dict(PAIR).assembly().flatten()
    g = flat.compile_python()
    P = flat.parameter_values
    x_nom = np.array([v.nominal for v in flat.states])
    u_nom = np.array([{"1": 1.0, "Pa": 1e5, "N m": 0.1}[v.unit] for v in flat.inputs])
    names = [v.name for v in flat.states]
    rng = np.random.default_rng(23)
    compared = skipped = 0
    for _ in range(1000):
        x = x_nom * rng.uniform(-1.0, 1.0, len(x_nom))
        x[names.index("joint.theta_rad")] = rng.uniform(-0.8, 0.8)
        for m in ("flexor", "extensor"):
            p_abs = rng.uniform(1.0e5, 4.5e5)
            x[names.index(f"{m}_chamber.p_abs_Pa")] = p_abs
            x[names.index(f"{m}_chamber.air_mass_kg")] = p_abs * rng.uniform(2e-6, 8e-6) / (287.0 * 293.15)
        u = np.array([rng.uniform(-1, 1), rng.uniform(0, 4e5), rng.uniform(-1, 1), rng.uniform(0, 4e5),
                      rng.uniform(-0.1, 0.1)])
        q = [float(rng.choice([-1, 0, 1, 2, 3]))]
        A, B, C, D = g.jacobian(list(x), list(u), P, q)
        for exact, fun in ((np.hstack([A, B]), lambda z: g.f(list(z[:len(x)]), list(z[len(x):]), P, q)[0]),
                           (np.hstack([C, D]), lambda z: g.y(list(z[:len(x)]), list(z[len(x):]), P, q)[0])):
            nom = np.concatenate([x_nom, u_nom])
            fd, kink = _fd_jacobian(fun, np.concatenate([x, u]), nom)
            row_scale = np.max(np.abs(exact) * nom, axis=1, keepdims=True) / nom
            bad = ~(np.abs(exact - fd) <= 1e-7 * (np.abs(exact) + np.abs(fd)) + 1e-9 * row_scale) & ~kink
            compared += int(np.sum(~kink))
            skipped += int(np.sum(kink))
            assert not bad.any(), (np.argwhere(bad), exact[bad], fd[bad], q)
    assert skipped <= 0.01 * compared, (skipped, compared)


def _variants():
    limit = prescribed(PAIR, (3.5, 1.0))
    limit["joint"].update(restitution=0.4, min_rebound_speed_rad_s=0.05)
    slack = prescribed(PAIR, (4.0, 0.0))
    return {"shipped pair (valves)": copy.deepcopy(PAIR), "prescribed steps": prescribed(PAIR, (3.0, 2.2)),
            "onto a limit, with rebounds": limit, "one muscle slack": slack}


@pytest.mark.parametrize("name", list(_variants()))
def test_native_agrees_with_python(name):
    """The generic C engine (Dormand-Prince 5(4)) against solve_ivp's LSODA, both at rtol 1e-9: the same
    events, at times within 1e-6 s, and the angle within 1e-6 rad at every sample."""
    spec = _variants()[name]
    spec["solver"] = {"method": "LSODA", "rtol": 1e-9}
    scenario = JointScenario.from_dict(spec)
    py, nat = simulate_joint(scenario), simulate_joint(scenario, "native")
    assert [e.kind for e in nat.transitions[:5]] == [e.kind for e in py.transitions[:5]]
    np.testing.assert_allclose([e.t_s for e in nat.transitions[:5]], [e.t_s for e in py.transitions[:5]], atol=1e-6)
    assert np.max(np.abs(nat.theta_rad - py.theta_rad)) < 1e-6
    for m in py.muscles:
        np.testing.assert_allclose(nat.muscle(m, "p_gauge_Pa"), py.muscle(m, "p_gauge_Pa"), atol=1.0)
    assert nat.energy_balance()["relative"] < 1e-6


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_pair_fmu_validates_and_agrees_with_python(tmp_path, fmi):
    """``pamsim fmu build --scenario antagonistic_pair.toml`` gives an FMU that fmpy validates, with the
    joint's and both muscles' variables under structured names; co-simulation (its own Dormand-Prince
    5(4)) and model exchange (fmpy's CVode), both at rtol 1e-6, follow the python backend's angle within
    1e-5 rad and end in the same mode, and the FMU's own start pressures are the scenario's."""
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    path = tmp_path / "pair.fmu"
    done = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario", str(PAIR_FILE), "-o",
                           str(path), "--fmi", str(fmi)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert validate_fmu(str(path)) == []
    names = {v.name for v in read_model_description(str(path)).modelVariables}
    assert {"joint.theta_rad", "flexor_chamber.p_gauge_Pa", "extensor_pulley.tau_Nm", "flexor.valve_command",
            "joint.inertia_kg_m2", "extensor_pulley.radius_m"} <= names
    if fmi == 2:
        scenario = load_joint_scenario(PAIR_FILE)
        py = simulate_joint(scenario)
        for backend in ("fmu-cs", "fmu-me"):
            res = simulate_joint(scenario, backend)
            assert np.max(np.abs(res.theta_rad - py.theta_rad)) < 1e-5, backend
            assert res.final_mode == py.final_mode and res.stats["events"] == len(py.transitions)
            for m in py.muscles:
                assert res.muscle(m, "p_gauge_Pa")[-1] == pytest.approx(py.muscle(m, "p_gauge_Pa")[-1], rel=1e-6)


def test_pamsim_joint_map_writes_the_equilibria_over_both_pressures(tmp_path):
    """``pamsim joint-map`` writes one row per pressure pair: its angle and stiffness are JointStatics'
    at those pressures, equal pressures hold the link at zero, and bad options exit 2 writing nothing."""
    import csv

    out = tmp_path / "map"
    done = subprocess.run([sys.executable, "-m", "pamsim", "joint-map", str(PAIR_FILE), "-o", str(out),
                           "--points", "4", "--min-bar", "1", "--max-bar", "4"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader((out / "antagonistic_pair_map.csv").open()))
    assert len(rows) == 16 and (out / "antagonistic_pair_map.png").stat().st_size > 10_000
    statics = JointStatics(load_joint_scenario(PAIR_FILE))
    for row in rows:
        p = [float(row["flexor.p_gauge_Pa"]), float(row["extensor.p_gauge_Pa"])]
        eq = statics.equilibrium(p)
        assert float(row["theta_rad"]) == eq.theta_rad and float(row["k_Nm_per_rad"]) == eq.k_Nm_per_rad
        if p[0] == p[1]:
            assert eq.theta_rad == 0.0 and row["on_limit"] == ""
    for bad, message in ((["--points", "1"], "--points = 1"), (["--max-bar", "20"], "above muscle 'flexor'")):
        again = subprocess.run([sys.executable, "-m", "pamsim", "joint-map", str(PAIR_FILE), "-o",
                                str(tmp_path / "none"), *bad], capture_output=True, text=True)
        assert again.returncode == 2 and message in again.stderr and not (tmp_path / "none").exists()


def test_co_contraction_shrinks_the_deflection_under_the_same_torque():
    """pair_cocontraction.toml: equal pressures 1-4 bar, a 0.02 N m pulse at each level.  The link turns
    less at each higher level; where it comes to rest under the pulse, its angle is the static
    deflection tau / k of the exact stiffness at that level, within the friction band (level / k); and
    the run's external work balances."""
    scenario = load_joint_scenario(ROOT / "scenarios" / "pair_cocontraction.toml")
    res = simulate_joint(scenario)
    statics = JointStatics(scenario)
    peaks = []
    for level, (start, end) in zip((1, 2, 3, 4), ((1.0, 1.5), (3.0, 3.5), (5.0, 5.5), (7.0, 7.5))):
        during = (res.t_s >= start) & (res.t_s < end)
        peaks.append(np.max(res.theta_rad[during]))
        held = during & (res.mode == 0) & (res.t_s > start + 0.1)
        if level > 1:
            k = statics.equilibrium([level * BAR] * 2).k_Nm_per_rad
            theta = res.theta_rad[held][-1]
            band = (statics.net_torque_Nm(theta, [level * BAR] * 2) + 0.02)  # what friction holds, at rest
            assert abs(theta - 0.02 / k) < 0.1 * 0.02 / k and abs(band) < 0.06
    assert peaks[0] == 0.0 and peaks[1] > peaks[2] > peaks[3] > 0.05
    # 38 events and four pressure steps at rtol 1e-6: within the one-muscle rig's bound (1e-3), by far
    assert res.energy_balance()["relative"] < 1e-4 and res.energy_balance()["W_external_J"] > 0.007


def prescribed_pair(p_bar=(2.0, 2.0)) -> JointScenario:
    spec = copy.deepcopy(PAIR)
    for table, p in zip(spec["muscle"], p_bar):
        table["pressure"] = {"source": "prescribed", "prescribed": {"kind": "constant", "value_gauge_bar": p}}
    return JointScenario.from_dict(spec)


@pytest.mark.parametrize("p_bar", [(2.0, 2.0), (2.5, 2.0), (3.0, 3.4)])
def test_the_mimo_linearisation_agrees_with_finite_differences(p_bar):
    """A, B against central differences of the generated right-hand side (Coulomb terms dropped), C, D
    against those of the angle and of JointStatics' exact stiffness, to 1e-6 relative; and the angle row
    of A is -k / J, the statics' stiffness over the inertia."""
    from pamsim.joints.linear import linearize_joint

    scenario = prescribed_pair()
    p = [v * BAR for v in p_bar]
    lm = linearize_joint(scenario, p)
    assert lm.states == ("joint.theta_rad", "joint.omega_rad_s") and lm.outputs[1] == "joint.k_Nm_per_rad"
    statics = JointStatics(scenario)
    J = PAIR["joint"]["inertia_kg_m2"]
    assert lm.A[1, 0] == pytest.approx(-statics.stiffness_Nm_per_rad(lm.theta0_rad, p) / J, rel=1e-12)
    assert lm.k0_Nm_per_rad == pytest.approx(statics.equilibrium(p).k_Nm_per_rad, rel=1e-12)
    flat = scenario.assembly().flatten()
    g = flat.compile_python()
    params = [0.0 if v.name == "joint.tau_coulomb_Nm" or v.name.split(".")[0].endswith("_friction") else value
              for v, value in zip(flat.parameters, flat.parameter_values)]
    names = [v.name for v in flat.states]
    rows = [names.index(s) for s in lm.states]

    def f(theta, omega, u):
        x = [0.0] * len(names)
        x[rows[0]], x[rows[1]] = theta, omega
        return np.array(g.f(x, list(u), params, [1.0])[0])[rows]

    u0 = np.array([*p, 0.0])
    for j, h in enumerate((1e-6, 1e-4)):
        z = [lm.theta0_rad, 0.0]
        zp, zm = list(z), list(z)
        zp[j] += h
        zm[j] -= h
        fd = (f(*zp, u0) - f(*zm, u0)) / (2 * h)
        np.testing.assert_allclose(lm.A[:, j], fd, rtol=1e-6, atol=1e-9 * np.max(np.abs(lm.A)))
    for j, h in enumerate((10.0, 10.0, 1e-6)):
        du = np.zeros(3)
        du[j] = h
        fd = (f(lm.theta0_rad, 0.0, u0 + du) - f(lm.theta0_rad, 0.0, u0 - du)) / (2 * h)
        np.testing.assert_allclose(lm.B[:, j], fd, rtol=1e-6, atol=1e-12)
    h = 1e-5
    k_fd = (statics.stiffness_Nm_per_rad(lm.theta0_rad + h, p) - statics.stiffness_Nm_per_rad(lm.theta0_rad - h, p)) / (2 * h)
    assert lm.C[1, 0] == pytest.approx(k_fd, rel=1e-6) and lm.C[0, 0] == 1.0 and lm.C[1, 1] == 0.0
    for j in range(2):
        dp = [0.0, 0.0]
        dp[j] = 10.0
        up = [a + b for a, b in zip(p, dp)]
        down = [a - b for a, b in zip(p, dp)]
        k_fd = (statics.stiffness_Nm_per_rad(lm.theta0_rad, up) - statics.stiffness_Nm_per_rad(lm.theta0_rad, down)) / 20.0
        assert lm.D[1, j] == pytest.approx(k_fd, rel=1e-6)
    assert lm.to_control().output_labels == ["joint_theta_rad", "joint_k_Nm_per_rad"]


def test_a_joint_on_valves_or_on_a_limit_is_not_linearised():
    from pamsim.errors import InputError
    from pamsim.joints.linear import linearize_joint

    with pytest.raises(InputError, match="muscle 'flexor': pressure.source = 'valve'"):
        linearize_joint(load_joint_scenario(PAIR_FILE), [2e5, 2e5])
    with pytest.raises(InputError, match="rests on its upper limit"):
        linearize_joint(prescribed_pair(), [4e5, 1e5])


def test_a_joints_hysteresis_elements_are_linearised_relaxed_and_sticking_as_springs(tmp_path):
    """At the equilibrium each muscle's elements are taken relaxed, Maxwell-slip's sticking and Bouc-Wen on its
    loading branch, and the model says so: springs of ``w F_c / delta`` (Maxwell-slip) and ``F_c / z_u``
    (Bouc-Wen at z = 0) on the muscles' flanges.  The joint's oscillation is then the plain pair's with the
    springs' ``r^2 sum k`` added to its stiffness over the inertia, by hand; the static stiffness output is the
    plain pair's (the springs act through their deflections, states).  ``pamsim linearize`` prints it."""
    import json

    from pamsim.joints.linear import linearize_joint

    spec = copy.deepcopy(PAIR)
    for table in spec["muscle"]:
        table["pressure"] = {"source": "prescribed", "prescribed": {"kind": "constant", "value_gauge_bar": 2.0}}
        table["model"]["friction"] = "constant"  # 2.5 N: the paper's level is zero at this link's load
    plain = linearize_joint(JointScenario.from_dict(copy.deepcopy(spec)), [2.2e5, 2.0e5])
    spec["muscle"][0]["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": [1e-3, 4e-3],
                                       "share": [0.5, 0.5]}
    spec["muscle"][1]["hysteresis"] = {"model": "bouc_wen", "beta_per_m_n": 200.0, "gamma_per_m_n": 200.0,
                                       "exponent": 1.0}
    lm = linearize_joint(JointScenario.from_dict(spec), [2.2e5, 2.0e5])
    loops = dict(lm.hysteresis)
    assert [e["state"] for e in loops["flexor"].elements] == ["stick", "stick"]
    assert [e["k_N_per_m"] for e in loops["flexor"].elements] == pytest.approx([0.5 * 2.5 / 1e-3, 0.5 * 2.5 / 4e-3])
    assert loops["extensor"].elements[0]["k_N_per_m"] == pytest.approx(2.5 * (200.0 + 200.0))  # F_c / z_u
    assert {loop.branch for loop in loops.values()} == {"at rest"}
    springs = sum(t["radius_m"] ** 2 * e["k_N_per_m"] for t, (_, loop) in zip(spec["muscle"], lm.hysteresis)
                  for e in loop.elements)
    by_hand = plain.A.copy()
    by_hand[1, 0] -= springs / spec["joint"]["inertia_kg_m2"]
    moving = np.sort_complex([z for z in lm.poles() if abs(z) > 1.0])
    np.testing.assert_allclose(moving, np.sort_complex(np.linalg.eigvals(by_hand)), rtol=1e-9)
    assert abs(moving[0].imag) > 1.5 * abs(np.linalg.eigvals(plain.A)[0].imag)
    assert lm.k0_Nm_per_rad == plain.k0_Nm_per_rad
    text = PAIR_FILE.read_text().replace('friction = "load_dependent"', 'friction = "constant"')
    for name, (bar, table) in {"2.2": ("2.2", 'model = "maxwell_slip"\nslip_displacement_m = [1e-3, 4e-3]\n'
                                              'share = [0.5, 0.5]'),
                               "2.0": ("2.0", 'model = "bouc_wen"\nbeta_per_m_n = 200.0\ngamma_per_m_n = 200.0\n'
                                              'exponent = 1.0')}.items():
        valve = f'[muscle.pressure]\nsource = "valve"\nsupply_gauge_bar = {name}\nvalve_open_time_s = 0.5'
        assert valve in text
        text = text.replace(valve, f'[muscle.hysteresis]\n{table}\n[muscle.pressure]\nsource = "prescribed"\n'
                                   f'[muscle.pressure.prescribed]\nkind = "constant"\nvalue_gauge_bar = {bar}')
    path = tmp_path / "pair.toml"
    path.write_text(text)
    done = subprocess.run([sys.executable, "-m", "pamsim", "linearize", str(path), "--json"], capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    rep = json.loads(done.stdout)["hysteresis"]
    assert rep["flexor"]["branch"] == "at rest" and [e["state"] for e in rep["flexor"]["elements"]] == ["stick"] * 2
    text = subprocess.run([sys.executable, "-m", "pamsim", "linearize", str(path)], capture_output=True, text=True)
    assert "flexor: hysteresis: maxwell_slip, branch at rest" in text.stdout, text.stdout
    assert ("friction: Coulomb friction dropped (the bearing's: no linearisation at rest); the [hysteresis] "
            "elements of muscles flexor and extensor take their Coulomb friction's place (below)") in text.stdout, text.stdout


def test_pamsim_linearize_a_joint_prints_the_mimo_model():
    """``pamsim linearize`` on a joint scenario with prescribed pressures: the model about the equilibrium at
    the final pressures (pair_cocontraction: 4 bar on both, the link at zero), as JSON; the stiffness is the
    statics'; on valves it exits 2 naming the muscle."""
    import json

    done = subprocess.run([sys.executable, "-m", "pamsim", "linearize", str(ROOT / "scenarios" / "pair_cocontraction.toml"),
                           "--json"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    rep = json.loads(done.stdout)
    scenario = load_joint_scenario(ROOT / "scenarios" / "pair_cocontraction.toml")
    assert rep["p0_gauge_Pa"] == [4e5, 4e5] and rep["theta0_rad"] == 0.0
    assert rep["k0_Nm_per_rad"] == pytest.approx(JointStatics(scenario).equilibrium([4e5, 4e5]).k_Nm_per_rad, rel=1e-12)
    assert rep["inputs"][:2] == ["flexor.prescribed_pressure_gauge_Pa", "extensor.prescribed_pressure_gauge_Pa"]
    again = subprocess.run([sys.executable, "-m", "pamsim", "linearize", str(PAIR_FILE)], capture_output=True, text=True)
    assert again.returncode == 2 and "muscle 'flexor': pressure.source = 'valve'" in again.stderr


CONTROLLED = ROOT / "scenarios" / "pair_angle_stiffness.toml"


def test_the_feedforward_rests_the_link_at_the_angle_with_the_commanded_stiffness():
    """At each angle of its table the feedforward's pressures hold the link there at rest (net torque 0)
    with the commanded stiffness, to the statics' precision."""
    from pamsim.joints.control import controller_of

    scenario = load_joint_scenario(CONTROLLED)
    controller = controller_of(scenario)
    statics = JointStatics(scenario)
    ff = controller.feedforward
    for theta, p in zip(ff.grid_rad, ff.p_Pa):
        assert abs(statics.net_torque_Nm(theta, p)) < 1e-11
        assert statics.stiffness_Nm_per_rad(theta, p) == pytest.approx(0.15, rel=1e-9)


def test_the_pid_puts_the_linear_loops_poles_where_it_was_designed():
    """The linear model about the reference's start, closed with the PID (its torque through the model's
    own torque input), has the characteristic polynomial J (s + w)^3 / J, w the scenario's bandwidth."""
    from pamsim.joints.control import controller_of
    from pamsim.joints.linear import linearize_joint

    scenario = load_joint_scenario(CONTROLLED)
    controller = controller_of(scenario)
    g, w = controller.gains, scenario.controller["bandwidth_rad_s"]
    lm = linearize_joint(scenario, list(controller.feedforward(0.0)))
    b = lm.B[:, 2]  # the external torque's column: 1 / J on the angular acceleration
    # states theta, omega, integral of (reference - theta); torque = -Kp theta + Ki z - Kd omega
    closed = np.array([[lm.A[0, 0], lm.A[0, 1], 0.0],
                       [lm.A[1, 0] - b[1] * g.Kp, lm.A[1, 1] - b[1] * g.Kd, b[1] * g.Ki],
                       [-1.0, 0.0, 0.0]])
    np.testing.assert_allclose(np.poly(closed), [1.0, 3 * w, 3 * w * w, w ** 3], rtol=1e-9)


@pytest.mark.parametrize("backend", ["python", "native", "fmu-cs"])
def test_the_controlled_pair_meets_its_spec(backend):
    """pair_angle_stiffness.toml on the python and native backends and through its FMU in co-simulation: the angle settles on each step and follows the
    sinusoid, the stiffness stays at its command, within the scenario's [controller.spec]."""
    from pamsim.joints.control import controller_of, metrics, spec_failures

    scenario = load_joint_scenario(CONTROLLED)
    controller = controller_of(scenario)
    run = controller.run(backend)
    measured = metrics(run, controller.reference, scenario.controller["settle_s"], scenario.duration_s)
    assert set(measured) == {"step_angle_rms_rad", "sine_angle_rms_rad", "stiffness_rms_Nm_per_rad"}
    assert spec_failures(measured, scenario.controller["spec"]) == []
    assert np.max(run.theta_rad) > 0.29 and np.min(run.theta_rad) < -0.39  # it did move through the references


CONTROLLER_BAD = [
    (lambda c: c.update(kind="lqr"), "controller.kind = 'lqr': must be 'angle_stiffness'"),
    (lambda c: c.update(gain=1.0), "controller.gain = 1.0: unknown key"),
    (lambda c: c.update(steps_angle_rad=[0.9, -0.2]), "controller.steps_angle_rad[0] = 0.9: must lie between"),
    (lambda c: c.update(steps_time_s=[2.0, 0.5]), "controller.steps_time_s[1] = 0.5: must be after"),
    (lambda c: c.pop("stiffness_Nm_per_rad"), "controller.stiffness_Nm_per_rad is required"),
    (lambda c: c["spec"].update(overshoot_max=1.0), "controller.spec.overshoot_max = 1.0: unknown key"),
    (lambda c: c.update(sine_amplitude_rad=1.5), "controller.sine_amplitude_rad = 1.5: the sinusoid about -0.2 rad"),
]


@pytest.mark.parametrize("change, message", CONTROLLER_BAD, ids=[m.split(":")[0] for _, m in CONTROLLER_BAD])
def test_a_bad_controller_table_is_refused_by_key(change, message):
    spec = tomllib.loads(CONTROLLED.read_text())
    change(spec["controller"])
    with pytest.raises(ScenarioError, match=re.escape(message)):
        JointScenario.from_dict(spec, origin="c.toml")
    valve = tomllib.loads(CONTROLLED.read_text())
    valve["muscle"][0]["pressure"] = {"source": "valve", "supply_gauge_bar": 3.0, "valve_open_time_s": 0.1}
    with pytest.raises(ScenarioError, match="muscle 'flexor'.pressure.source = 'valve'"):
        JointScenario.from_dict(valve, origin="c.toml")


def test_pamsim_run_exits_1_when_the_controlled_joint_misses_its_spec(tmp_path):
    strict = tmp_path / "strict.toml"
    strict.write_text(CONTROLLED.read_text().replace("sine_angle_rms_max_rad = 5.0e-3", "sine_angle_rms_max_rad = 1.0e-4"))
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(strict), "-o", str(tmp_path / "out"), "--no-plot",
                           "--backend", "native"], capture_output=True, text=True)
    assert done.returncode == 1, done.stderr
    assert "misses its specification: sine_angle_rms_rad" in done.stdout
    summary = __import__("json").loads((tmp_path / "out" / "pair_angle_stiffness.json").read_text())
    assert summary["meets_spec"] is False and summary["metrics"]["step_angle_rms_rad"] < 1e-3


def lever_pair() -> dict:
    """The pair on levers (:func:`joint_specs.on_levers`) at 2.5 and 2 bar."""
    return on_levers(prescribed(PAIR, (2.5, 2.0)))


def test_a_lever_attachment_follows_its_geometry():
    """Muscles on levers: the contraction, the lever arm a d sin(phi) / L and the equilibrium of the hand
    torque balance written with the geometry, and the stiffness against finite differences."""
    spec = lever_pair()
    scenario = JointScenario.from_dict(spec)
    forces = static_forces(spec)
    g, j = 9.81, spec["joint"]

    def geometry(side, theta):
        phi = math.pi / 2 - side * theta
        L = math.sqrt(0.03 ** 2 + 0.35 ** 2 - 2 * 0.03 * 0.35 * math.cos(phi))
        return 0.3 - (L - spec["muscle"][0]["tendon_length_m"]), side * 0.03 * 0.35 * math.sin(phi) / L

    def tau(theta, p):
        total = -j["link_mass_kg"] * g * j["com_distance_m"] * math.sin(theta)
        for table, force, pk in zip(spec["muscle"], forces, p):
            x, arm = geometry(table["side"], theta)
            total += arm * max(float(force.force_N(x, pk)), 0.0)
        return total

    statics = JointStatics(scenario)
    p = [2.5 * BAR, 2.0 * BAR]
    eq = statics.equilibrium(p)
    assert eq.on_limit is None and eq.theta_rad == pytest.approx(brentq(lambda t: tau(t, p), -0.5, 0.5, xtol=1e-15), abs=1e-10)
    h = 1e-5
    assert eq.k_Nm_per_rad == pytest.approx(-(tau(eq.theta_rad + h, p) - tau(eq.theta_rad - h, p)) / (2 * h), rel=1e-6)
    res = simulate_joint(scenario)
    x, arm = geometry(1.0, res.theta_rad[-1])
    assert res.muscle("flexor", "x_m")[-1] == pytest.approx(x, abs=1e-12)
    assert res.muscle("flexor", "moment_arm_m")[-1] == pytest.approx(arm, rel=1e-12)
    nat = simulate_joint(scenario, "native")
    assert abs(nat.theta_rad[-1] - res.theta_rad[-1]) < 1e-5 and res.energy_balance()["relative"] < 2e-5


def test_a_lever_whose_arms_line_up_is_refused():
    for angle in (0.3, 3.0):  # the arms line up at 0 (below the range) or at pi (above it)
        spec = lever_pair()
        spec["muscle"][0]["angle_at_zero_rad"] = angle
        with pytest.raises(ScenarioError, match=f"muscle 'flexor'.angle_at_zero_rad = {angle}: its lever's arms would line up"):
            JointScenario.from_dict(spec, origin="lever.toml")
    spec = lever_pair()
    spec["muscle"][0]["radius_m"] = 0.01
    with pytest.raises(ScenarioError, match="radius_m = 0.01: not a key of attachment = 'lever'"):
        JointScenario.from_dict(spec, origin="lever.toml")


def test_the_papers_damping_alone_does_not_hold_a_frictionless_joint():
    """The ACRA 2012 damping's slope at rest is negative: without any Coulomb friction a slightly asymmetric
    pair at 2.5 bar rings up to its limits with it, and settles at its equilibrium with a dissipative law."""
    spec = prescribed(PAIR, (2.5, 2.5), time_s=0.0)
    spec["joint"]["tau_coulomb_Nm"] = 0.0
    spec["muscle"][0]["x_at_zero_m"] = 0.0201
    ends = {}
    for damping in ("paper", "linear", "none"):
        case = copy.deepcopy(spec)
        for table in case["muscle"]:
            table["model"] = dict(table["model"], damping=damping)
        res = simulate_joint(JointScenario.from_dict(case))
        ends[damping] = (np.max(np.abs(res.theta_rad[res.t_s > 2.5])), res.theta_rad[-1])
    eq = JointStatics(JointScenario.from_dict(spec)).equilibrium([2.5 * BAR] * 2).theta_rad
    assert ends["paper"][0] > 0.7
    for damping in ("linear", "none"):
        assert abs(ends[damping][1] - eq) < 2e-4


@pytest.mark.parametrize("args, message", [
    (["fmu", "build", "--scenario", str(PAIR_FILE), "--muscle-only", "-o", "{tmp}/m.fmu"], "is a joint scenario"),
    (["linearize", str(CONTROLLED)], "[controller]: its muscles' prescribed pressures are placeholders"),
    (["linearize", str(ROOT / "scenarios" / "pair_cocontraction.toml"), "--friction", "regularised"], "--friction:"),
    (["joint-map", str(ROOT / "scenarios" / "acra2012_fig4.toml"), "-o", "{tmp}/map"], "not a joint scenario"),
])
def test_commands_refuse_what_does_not_apply_to_a_joint(tmp_path, args, message):
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    done = subprocess.run([sys.executable, "-m", "pamsim", *args], capture_output=True, text=True)
    assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr
    assert not any(tmp_path.iterdir())


def test_a_bandwidth_below_the_joints_own_stiffness_is_refused():
    spec = tomllib.loads(CONTROLLED.read_text())
    spec["controller"]["bandwidth_rad_s"] = 20.0
    from pamsim.errors import InputError
    from pamsim.joints.control import controller_of

    with pytest.raises(InputError, match="controller.bandwidth_rad_s = 20: the joint's own stiffness"):
        controller_of(JointScenario.from_dict(spec, origin="c.toml"))


@pytest.mark.parametrize("backend", ["python", "native", "fmu-cs"])
def test_the_festo_pair_settles_in_its_friction_band_on_every_backend(backend):
    """The Festo DMSP-10 pair with the Ogden model: at rest within the bearing's friction band of the
    static equilibrium at its final pressures (|theta - theta_eq| <= tau_c / k), its energy balanced
    within the shipped pair's bound, and every backend at python's final angle within 10 rtol."""
    scenario = load_joint_scenario(ROOT / "scenarios" / "antagonistic_festo.toml")
    res = simulate_joint(scenario, backend)
    eq = JointStatics(scenario).equilibrium([res.muscle(m, "p_gauge_Pa")[-1] for m in res.muscles])
    assert res.final_mode.label == "stick" and eq.on_limit is None
    assert abs(res.theta_rad[-1] - eq.theta_rad) <= FESTO["joint"]["tau_coulomb_Nm"] / eq.k_Nm_per_rad
    if backend != "fmu-cs":  # the FMU reports no energy of its impacts (none here) nor its events
        assert res.energy_balance()["relative"] < 2e-5
    python = res if backend == "python" else simulate_joint(scenario)
    assert abs(res.theta_rad[-1] - python.theta_rad[-1]) < 1e-5


def test_a_joint_scenario_run_again_on_native_reuses_its_case_by_the_object():
    """The native backend keeps a joint scenario's assembly, engine and case for the scenario object: a
    second run finds them and gives the same trace; an equal scenario (another object) builds its own."""
    from pamsim.joints import native

    scenario = load_joint_scenario(PAIR_FILE)
    first = simulate_joint(scenario, "native")
    kept = native._PREPARED.get(scenario)
    assert kept is not None and native._prepared(scenario) is kept
    assert not kept[2].segment_u.flags.writeable and not kept[2].params.flags.writeable
    again = simulate_joint(scenario, "native")
    assert all(np.array_equal(first.signals[k], again.signals[k]) for k in ("joint.theta_rad", "flexor_chamber.p_abs_Pa"))
    twin = load_joint_scenario(PAIR_FILE)
    assert native._PREPARED.get(twin) is None and native._prepared(twin) is not kept


def test_a_release_turned_back_at_once_is_held_on_every_backend():
    """The flexor under PWM (50 Hz, 60 %, from 0.5 s; its valve shut while off): at 0.5547 s the joint at rest is
    released downwards, and the two muscles' frictions turn it back before it has moved (its speed reaches the
    velocity tolerance, 1e-9 rad/s, within a nanosecond), again and again.  The python backend holds it for
    1 ns, doubling at each repetition (``pamsim.simulator._HOLD_S``); the native engine and the FMU's ran
    out of internal steps there (more than a million between 0.552 and 0.56 s) and now hold it the same way.
    In model exchange the FMU holds it too, the hold's end a time event (fmpy's CVode did not finish the run
    in 100 s before; now the angle ends 1.7e-4 rad from python's, the pressures 3e-8 Pa).
    Against python: the same 31 events (native) in the same order, the first within 1e-6 s (measured 2.2e-7 s),
    the final angle within 1e-3 rad (measured 1.7e-4 rad: where a slip sticks depends on its path), the final
    pressures within 1e-3 Pa, the same final mode; native's energy balance within 1e-6."""
    spec = copy.deepcopy(PAIR)
    pressure = spec["muscle"][0]["pressure"]
    del pressure["valve_open_time_s"]
    pressure["command"] = {"kind": "pwm", "frequency_Hz": 50.0, "duty": 0.6, "start_s": 0.5, "end_s": 3.0,
                           "low": 0.0, "high": 1.0}
    scenario = JointScenario.from_dict(spec)
    py = simulate_joint(scenario)
    kinds = [e.kind for e in py.transitions[:6]]
    assert kinds == ["release_down"] + ["velocity_zero"] * 5  # the holds, each twice the last
    gaps = np.diff([e.t_s for e in py.transitions[1:6]])
    np.testing.assert_allclose(gaps[1:] / gaps[:-1], 2.0, rtol=1e-3)
    for backend in ("native", "fmu-cs", "fmu-me"):
        res = simulate_joint(scenario, backend)
        print(f"{backend}: final angle {abs(res.theta_rad[-1] - py.theta_rad[-1]):.2g} rad from python's, pressures "
              + ", ".join(f"{abs(res.muscle(m, 'p_gauge_Pa')[-1] - py.muscle(m, 'p_gauge_Pa')[-1]):.2g} Pa"
                          for m in py.muscles))
        assert res.final_mode == py.final_mode, backend
        assert abs(res.theta_rad[-1] - py.theta_rad[-1]) < 1e-3, backend
        for m in py.muscles:
            assert abs(res.muscle(m, "p_gauge_Pa")[-1] - py.muscle(m, "p_gauge_Pa")[-1]) < 1e-3, (backend, m)
    nat = simulate_joint(scenario, "native")
    assert [e.kind for e in nat.transitions] == [e.kind for e in py.transitions]
    assert abs(nat.transitions[0].t_s - py.transitions[0].t_s) < 1e-6
    assert nat.energy_balance()["relative"] < 1e-6


def test_a_muscle_of_the_pair_on_two_on_off_valves_runs_on_every_backend():
    """The flexor on two 2/2 valves ([pressure.inlet] under 50 Hz PWM at 60 % from 0.5 s, [pressure.exhaust]
    complementary): native and fmu-cs end where python does, the angle within 1e-6 rad (measured 6e-8) and each
    muscle's pressure within 0.1 Pa (measured 3.6e-3), in the same mode.  Between, the PWM's releases and sticks
    fall a little apart on each integrator, and the traces part by up to 0.03 rad and 1.3 kPa before they meet."""
    spec = copy.deepcopy(PAIR)
    pressure = spec["muscle"][0]["pressure"]
    del pressure["valve_open_time_s"]
    pressure["inlet"] = {"command": {"kind": "pwm", "frequency_Hz": 50.0, "duty": 0.6, "start_s": 0.5, "end_s": 3.0}}
    pressure["exhaust"] = {"command": {"kind": "complementary"}}
    scenario = JointScenario.from_dict(spec)
    py = simulate_joint(scenario)
    assert py.theta_rad[-1] < -0.3  # the venting flexor lets the extensor win
    for backend in ("native", "fmu-cs"):
        res = simulate_joint(scenario, backend)
        assert res.final_mode == py.final_mode, backend
        assert abs(res.theta_rad[-1] - py.theta_rad[-1]) < 1e-6, backend
        for m in py.muscles:
            assert abs(res.muscle(m, "p_gauge_Pa")[-1] - py.muscle(m, "p_gauge_Pa")[-1]) < 0.1, (backend, m)
