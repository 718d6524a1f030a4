"""A component added to the rig from a scenario: the linear spring of the architecture tutorial.

Checked against hand calculations (the equilibrium of the muscle, the weight and the spring; the
spring's force law), conservation (the energy balance with the spring's work), the rig without it
(a spring of zero stiffness changes nothing), and the other backend; and every mistake in a
``[[component]]`` table is refused naming it, with exit 2 and nothing written.
"""

from __future__ import annotations

import copy
import subprocess
import sys
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

import pamsim
from conftest import SCENARIOS
from pamsim.errors import InputError

SPEC = tomllib.loads((SCENARIOS / "parallel_spring.toml").read_text())


def _scenario(changes=None, spring=None, **top):
    spec = copy.deepcopy(SPEC)
    for section, values in (changes or {}).items():
        if section == "model" and "muscle" in values:
            spec["model"].pop("parameter_set")
        spec.setdefault(section, {}).update(values)
    spec["component"][0].update(spring or {})
    spec.update(top)
    return pamsim.Scenario.from_dict(spec, base_dir=SCENARIOS)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_a_frictionless_load_settles_where_muscle_weight_and_spring_balance(backend):
    """No Coulomb friction and linear damping: the load comes to rest where F_static(x, p_supply) =
    W + k (x - x_free), found here by root-finding on the static model."""
    k, x_free = 300.0, 0.005
    sc = _scenario({"model": {"friction": "none", "damping": "linear"}, "simulation": {"duration_s": 12.0}},
                   {"k_N_per_m": k, "x_free_m": x_free})
    res = pamsim.simulate(sc, backend=backend)
    model = sc.build_model()
    p = sc.final_pressure_gauge_Pa
    x_eq = brentq(lambda x: model.static_force.force_N(x, p) - model.load.weight_N - k * (x - x_free), 0.0, 0.06)
    assert abs(res.x_m[-1] - x_eq) < 1e-6  # 1 um: the decaying oscillation's last trace
    assert abs(res.v_m_s[-1]) < 1e-4


@pytest.mark.parametrize("backend", ["python", "native"])
def test_the_spring_force_is_its_law_and_the_energy_balance_closes(backend):
    sc = pamsim.load_scenario(SCENARIOS / "parallel_spring.toml")
    res = pamsim.simulate(sc, backend=backend)
    spring = SPEC["component"][0]
    np.testing.assert_allclose(res.signals["spring.F_spring_N"],
                               -spring["k_N_per_m"] * (res.x_m - spring["x_free_m"]), rtol=1e-12, atol=1e-12)
    balance = res.energy_balance()
    assert balance["spring.W_spring_J"] < -0.1  # the spring took energy as the load rose
    assert balance["relative"] < 2e-5
    # held at the end: the net force at rest counts the spring (static - weight + spring)
    net, _ = res.final_rest_forces_N
    last = res.signals
    assert net == pytest.approx(last["F_static_N"][-1] + last["F_gravity_N"][-1] + last["spring.F_spring_N"][-1],
                                abs=1e-9)


def test_a_spring_of_no_stiffness_changes_nothing():
    with_spring = pamsim.simulate(_scenario(spring={"k_N_per_m": 0.0}))
    without = pamsim.simulate(pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml"))
    assert np.array_equal(with_spring.x_m, without.x_m)
    assert with_spring.transitions == without.transitions


def test_the_native_backend_agrees_with_python():
    sc = pamsim.load_scenario(SCENARIOS / "parallel_spring.toml")
    py, nat = pamsim.simulate(sc), pamsim.simulate(sc, backend="native")
    assert abs(py.x_m[-1] - nat.x_m[-1]) < 2e-6
    assert [e.kind for e in py.transitions] == [e.kind for e in nat.transitions]


BAD = [
    ({"type": "lineer_spring"}, "component[0].type", "did you mean 'linear_spring'"),
    ({"k_N_per_mm": 2.0}, "component[0].k_N_per_mm", "not a parameter of linear_spring"),
    ({"k_N_per_m": "stiff"}, "component[0].k_N_per_m", "must be a number, not a string"),
    ({"k_N_per_m": True}, "component[0].k_N_per_m = true", "must be a number, not a boolean"),
    ({"k_N_per_m": float("nan")}, "component[0].k_N_per_m = nan", "must be a finite number"),
    ({"name": "load"}, "component[0].name", "is taken"),
    ({"name": "motion"}, "component[0].name", "is taken"),  # a muscle alone's: run on a length, or in MuJoCo
    ({"name": "series_spring"}, "component[0].name", "is taken"),
    ({"connect": {}}, "[[component]]", "spring.flange"),
    ({"connect": {"flange": "chamber.port"}}, "[[component]]", "spring.flange"),
    ({"connect": {"flange": "load.flang"}}, "[[component]]", "load.flang"),
]


@pytest.mark.parametrize("entry, key, why", BAD)
def test_a_bad_component_table_is_refused_naming_it(entry, key, why):
    with pytest.raises(InputError) as err:
        _scenario(spring=entry)
    assert key in str(err.value) and why in str(err.value)


def test_a_parameter_outside_its_range_is_refused():
    spec = copy.deepcopy(SPEC)
    spec["component"][0]["k_N_per_m"] = -200.0
    with pytest.raises(InputError, match=r"component\[0\]\.k_N_per_m = -200.*must be >= 0"):
        pamsim.Scenario.from_dict(spec)


def test_a_missing_parameter_is_refused():
    spec = copy.deepcopy(SPEC)
    del spec["component"][0]["x_free_m"]
    with pytest.raises(InputError, match=r"missing key component\[0\]\.x_free_m: linear_spring needs"):
        pamsim.Scenario.from_dict(spec)


def test_the_cli_refuses_with_exit_2_and_writes_nothing(tmp_path):
    text = (SCENARIOS / "parallel_spring.toml").read_text().replace('type = "linear_spring"', 'type = "coil"')
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "pamsim", "run", str(bad), "-o", str(tmp_path / "out")],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and "component[0].type" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "out").exists()


def test_native_runs_added_components_with_a_tabulated_static_force_as_python_does():
    """An implicit model (tabulated: a spline table, which has a CasADi form) with the spring runs natively
    on the generated engine, the table's C among its helpers, and meets the python backend's run of the
    same table: the two integrators' difference (measured 4.0e-8 m at most)."""
    blocked_N = 0.8716  # mpam_two_phase on the 45 mm muscle at 6 bar, x = 0 (E_nylon = 3 GPa)
    sc = _scenario({"model": {"muscle": "mpam_survey_45mm", "static_force": "mpam_two_phase", "friction": "none",
                              "damping": "linear"},
                    "parameters": {"E_nylon_Pa": 3e9},  # nylon 6: 2-4 GPa
                    "load": {"weight_N": 0.3 * blocked_N}, "pressure": {"supply_gauge_bar": 6.0},
                    "simulation": {"duration_s": 3.0, "sample_rate_Hz": 200.0}})
    py, nat = pamsim.simulate(sc), pamsim.simulate(sc, backend="native")
    assert py.x_m.max() > 1e-3  # it lifts the load against the spring
    assert np.max(np.abs(py.x_m - nat.x_m)) < 1e-6
    # The lift-off agrees; the velocity zeros of the decaying micro-oscillation after it (amplitude far below
    # the 1 um bound) are ill-conditioned and their count differs.
    assert py.transitions[0].kind == nat.transitions[0].kind == "release_up"
    assert abs(py.transitions[0].t_s - nat.transitions[0].t_s) < 1e-6
    np.testing.assert_allclose(nat.signals["spring.F_spring_N"], py.signals["spring.F_spring_N"], atol=2e-4)


def test_native_runs_a_floats_only_static_force_as_its_table_with_the_component(floats_only_gaylord):
    """A static model that takes floats alone has no C: the native backend runs it as its spline table,
    with the component added, as the python backend runs the model itself (within the table's error)."""
    sc = _scenario({"model": {"static_force": "gaylord"}})
    native, python = pamsim.simulate(sc, backend="native"), pamsim.simulate(sc)
    assert "spring.F_spring_N" in native.signals
    assert np.max(np.abs(native.x_m - python.x_m)) < 1e-6


@pytest.mark.parametrize("backend, bound_m", [("fmu-cs", 2e-7), ("fmu-me", 1e-6)])
def test_the_fmu_backends_run_the_assembly_fmu(backend, bound_m):
    """The one-muscle FMU has the rig alone: the FMU backends run the FMU generated from the assembly,
    spring included, and meet the python run (co-simulation at the scenario's rtol, model exchange
    with CVode at it)."""
    sc = pamsim.load_scenario(SCENARIOS / "parallel_spring.toml")
    fmu, py = pamsim.simulate(sc, backend=backend), pamsim.simulate(sc)
    assert np.max(np.abs(fmu.x_m - py.x_m)) < bound_m
    np.testing.assert_allclose(fmu.signals["spring.F_spring_N"], py.signals["spring.F_spring_N"], atol=300 * bound_m)


def test_commands_that_take_the_rig_alone_refuse_added_components(tmp_path):
    from pamsim.sweep import load_sweep

    sweep = tmp_path / "sweep.toml"
    sweep.write_text(f'base_scenario = "{SCENARIOS / "parallel_spring.toml"}"\n'
                     '[axes]\npressure_bar = [2.0, 3.0]\nweight_N = [12.74]\n')
    with pytest.raises(InputError, match="static analysis.*'spring'"):
        load_sweep(sweep)
    from pamsim.control.closed_loop import ControllerConfig

    with pytest.raises(InputError, match="controller design.*'spring'"):
        ControllerConfig.from_scenario(pamsim.load_scenario(SCENARIOS / "parallel_spring.toml"))


def _linear(scenario, pull_added=True):
    from pamsim.control.exact import rest_pull
    from pamsim.control.linear import linearize
    from pamsim.control.operating_point import open_valve_equilibrium

    model = scenario.build_model()
    added = scenario.added_components
    op = open_valve_equilibrium(model, scenario.final_pressure_gauge_Pa, pull=rest_pull(model, added))
    return linearize(model, op, added=added, drop_unobservable_air_mass=False), model


def test_linearize_takes_the_spring_exactly():
    """The operating point is where F_static(x, p_supply) = W + k (x - x_free) (root-finding on the static
    model), and the spring adds -k/m to d(acceleration)/dx and -k to d(tendon force)/dx, nothing else:
    the rig alone, linearised at the same point, differs by exactly that."""
    from pamsim.control.linear import linearize

    k, x_free = 300.0, 0.005
    sc = _scenario(spring={"k_N_per_m": k, "x_free_m": x_free})
    lin, model = _linear(sc)
    p = sc.final_pressure_gauge_Pa
    x_eq = brentq(lambda x: model.static_force.force_N(x, p) - model.load.weight_N - k * (x - x_free), 0.0, 0.07,
                  xtol=1e-14)
    assert lin.op.states[0] == pytest.approx(x_eq, abs=1e-9)
    assert np.max(np.abs(lin.residual[:2])) < 1e-6  # at rest: no acceleration, no velocity
    alone = linearize(model, lin.op, drop_unobservable_air_mass=False)
    A, C = np.array(lin.sys.A), np.array(lin.sys.C)
    dA, dC = A - np.array(alone.sys.A), C - np.array(alone.sys.C)
    m = model.load.mass_kg
    assert dA[1, 0] == pytest.approx(-k / m, rel=1e-9) and dC[2, 0] == pytest.approx(-k, rel=1e-9)
    dA[1, 0] = dC[2, 0] = 0.0
    assert np.max(np.abs(dA)) <= 1e-9 * np.max(np.abs(A)) and np.max(np.abs(dC)) <= 1e-9 * np.max(np.abs(C))
    np.testing.assert_array_equal(np.array(lin.sys.B), np.array(alone.sys.B))


def test_a_spring_of_no_stiffness_linearises_as_the_rig_alone():
    from pamsim.control.linear import linearize
    from pamsim.control.operating_point import open_valve_equilibrium

    sc = _scenario(spring={"k_N_per_m": 0.0})
    lin, model = _linear(sc)
    alone = linearize(model, open_valve_equilibrium(model, sc.final_pressure_gauge_Pa),
                      drop_unobservable_air_mass=False)
    np.testing.assert_allclose(lin.op.states, alone.op.states, rtol=1e-12)
    for a, b in zip((lin.sys.A, lin.sys.B, lin.sys.C, lin.sys.D), (alone.sys.A, alone.sys.B, alone.sys.C, alone.sys.D)):
        np.testing.assert_allclose(np.array(a), np.array(b), rtol=1e-12, atol=0.0)


def test_the_cli_linearizes_the_spring_scenario(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "pamsim", "linearize", str(SCENARIOS / "parallel_spring.toml"),
                           "-o", str(tmp_path / "lin")], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "Jacobians: exact" in proc.stdout
    assert (tmp_path / "lin" / "parallel_spring_linear_bode.png").is_file()


def test_the_casadi_export_holds_the_added_component():
    from pamsim.export import casadi_model

    flat = casadi_model(pamsim.load_scenario(SCENARIOS / "parallel_spring.toml"))._assembly.flatten()
    assert "spring.W_spring_J" in [v.name for v in flat.states]
    assert "spring.F_spring_N" in [v.name for v in flat.outputs]


@pytest.mark.parametrize("k_N_per_m, x_free_m, share", [
    # A spring free at 50 mm pulls 2000 * 0.045 = 90 N at 5 mm, the unpressurised muscle nothing there.
    (2000.0, 0.05, "where the muscle pulls 0.00 N and component 'spring' 90.00 N"),
    # A stiff spring free at 0 resists 20000 * 0.005 = 100 N at 5 mm, more than the muscle gives at 3.6 bar.
    (20000.0, 0.0, "component 'spring' -100.00 N"),
])
def test_linearize_says_what_the_spring_pulls_when_no_pressure_can_hold_the_load(k_N_per_m, x_free_m, share):
    """Where no gauge pressure in [0, supply] holds the load, the message names the spring and its share,
    rather than laying the whole pull on the muscle."""
    from pamsim.control.exact import rest_pull
    from pamsim.control.operating_point import held_equilibrium

    scenario = _scenario(spring={"k_N_per_m": k_N_per_m, "x_free_m": x_free_m})
    model = scenario.build_model()
    added = scenario.added_components
    with pytest.raises(InputError) as err:
        held_equilibrium(model, 0.005, scenario.final_pressure_gauge_Pa, pull=rest_pull(model, added))
    assert "muscle with component 'spring'" in str(err.value)
    assert share in str(err.value)
