"""The chamber laws, valves and lines on the muscles of a joint or a slider: a muscle's ``[muscle.chamber]`` and
``[[muscle.component]]`` tables, read as a one-muscle scenario's.

The check is a second assembly of the same equations: a one-muscle rig and its slider form
(:func:`pamsim.joints.scenario.slider_of_rig`: the hanging load as a vertical carriage pulled by the muscle's
tendon) are the same system while the muscle pulls, built from other components and wired by other code, so
their traces agree to the integrators' tolerance.  Then a joint pair whose flexor has a thermal chamber behind a
tube runs on every backend, and its statics leave the pneumatics out."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

from pamsim.api import simulate
from pamsim.joints import JointScenario, load_joint_scenario, simulate_joint
from pamsim.joints.fmu import joint_fmu_spec
from pamsim.joints.scenario import slider_of_rig
from pamsim.joints.static import JointStatics
from pamsim.scenario import Scenario, ScenarioError, load_scenario

from conftest import assert_refused, run_main

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
RTOL = 1e-6  # every scenario below integrates at rtol 1e-6


def _side_volume(sc):
    """Figure 4 with a 10 cm^3 reservoir on the chamber through a 0.5 m tube (a volume the valve does not feed:
    the chamber then settles onto its own pressure, not the valve's)."""
    spec = copy.deepcopy(sc.spec)
    spec["component"] = [{"name": "side", "type": "reservoir", "volume_m3": 1e-5},
                         {"name": "hose", "type": "tube", "length_m": 0.5, "diameter_m": 0.004,
                          "connect": {"inlet": "side.port", "outlet": "chamber.port"}}]
    return Scenario.from_dict(spec, "fig4_side_volume", sc.base_dir, sc.origin)


RIGS = {
    "fig4_thermal": lambda: load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes({"chamber": {"law": "thermal"}}),
    "fig4_side_volume": lambda: _side_volume(load_scenario(SCENARIOS / "acra2012_fig4.toml")),
    "supply_chain": lambda: load_scenario(SCENARIOS / "supply_chain.toml"),
    "pwm_onoff": lambda: load_scenario(SCENARIOS / "pwm_onoff.toml"),
    "thermal_drift": lambda: load_scenario(SCENARIOS / "thermal_drift.toml"),
    "hysteresis_loops": lambda: load_scenario(SCENARIOS / "hysteresis_loops.toml"),
}


@pytest.mark.parametrize("backend, name", [*(("python", n) for n in RIGS), ("native", "supply_chain"),
                                           ("native", "fig4_thermal"), ("native", "fig4_side_volume")])
def test_the_slider_form_of_a_rig_with_its_pneumatics_is_the_rig(backend, name):
    """Contraction within 10 rtol of its largest value, pressure within 10 rtol of the supply's, the thermal
    gas's temperature within 10 rtol of 300 K, the same events (the hysteresis elements' slips aside: the
    slider counts its own)."""
    rig_scenario = RIGS[name]()
    rig = simulate(rig_scenario, backend=backend)
    slider = simulate_joint(slider_of_rig(rig_scenario), backend)
    assert np.max(np.abs(rig.x_m - slider.position)) < 10 * RTOL * np.max(rig.x_m)
    assert np.max(np.abs(rig.p_gauge_Pa - slider.muscle("muscle", "p_gauge_Pa"))) < 10 * RTOL * 3.6e5
    if rig_scenario.chamber_law == "thermal":
        gas = rig.columns()["gas_temperature_K"]
        assert np.max(gas) > 300.0  # the filling heats it: the law is the thermal one on both
        assert np.max(np.abs(gas - slider.muscle("muscle", "gas_temperature_K"))) < 10 * RTOL * 300.0
    if name != "hysteresis_loops":
        assert [e.kind for e in slider.transitions] == [e.kind for e in rig.transitions]
    if backend == "native":  # one engine, the same equations in the same order: the same numbers
        assert np.array_equal(rig.x_m, slider.position)
        assert np.array_equal(rig.p_gauge_Pa, slider.muscle("muscle", "p_gauge_Pa"))


def _pair(flexor_extra: dict) -> dict:
    """``antagonistic_pair.toml`` with ``flexor_extra`` merged into its flexor's table."""
    spec = tomllib.loads((SCENARIOS / "antagonistic_pair.toml").read_text())
    flexor = spec["muscle"][0]
    for key, value in copy.deepcopy(flexor_extra).items():
        if isinstance(value, dict) and isinstance(flexor.get(key), dict):
            flexor[key].update(value)
        else:
            flexor[key] = value
    return spec


THERMAL_TUBE = {"chamber": {"law": "thermal"}, "pressure": {"outlet_port": "tube.inlet"},
                "component": [{"name": "tube", "type": "tube", "inlet": "volume", "length_m": 1.0,
                               "diameter_m": 0.004, "connect": {"outlet": "chamber.port"}}]}


@pytest.fixture(scope="module")
def pair_runs():
    scenario = JointScenario.from_dict(_pair(THERMAL_TUBE), origin="<pair>", base_dir=SCENARIOS)
    return scenario, {b: simulate_joint(scenario, b) for b in ("python", "native", "fmu-cs", "fmu-me")}


def test_a_joint_muscle_with_a_thermal_chamber_behind_a_tube_runs_alike_on_every_backend(pair_runs):
    scenario, runs = pair_runs
    python = runs["python"]
    assert {"flexor_tube.p_gauge_Pa", "flexor_chamber.gas_temperature_K"} <= set(python.signals)
    gas = python.muscle("flexor", "gas_temperature_K")
    # Filling heats the gas; the wall (293.15 K) cools it back within the 2.5 s after.
    assert np.max(gas) > 330.0 and abs(gas[-1] - 293.15) < 1.0
    assert python.thermal_muscles() == ("flexor",)
    for backend, run in runs.items():
        assert np.max(np.abs(run.theta_rad - python.theta_rad)) < 1e-4, backend
        assert np.max(np.abs(run.muscle("flexor", "p_gauge_Pa") - python.muscle("flexor", "p_gauge_Pa"))) < 10.0, backend
        assert np.max(np.abs(run.muscle("flexor", "gas_temperature_K") - gas)) < 0.02, backend
    # The FMU's variables: the gas temperature an output, the tube's pressure and its air a state.
    variables = {v.name: v for v in joint_fmu_spec(scenario).variables}
    assert variables["flexor_chamber.gas_temperature_K"].causality == "output"
    assert variables["flexor_chamber.gas_temperature_K"].unit == "K"
    assert "flexor_tube.air_mass_kg" in variables and "flexor_tube.p_gauge_Pa" in variables


def _pair_file_with_law(folder, law: str):
    """The shipped pair's file with a ``[muscle.chamber]`` of ``law`` on its first muscle (the flexor),
    written into ``folder``: the file a user edits, not a dict."""
    text = (SCENARIOS / "antagonistic_pair.toml").read_text()
    marker = '[muscle.pressure]\nsource = "valve"\nsupply_gauge_bar = 2.2'
    assert marker in text
    path = folder / "pair.toml"
    path.write_text(text.replace(marker, f'[muscle.chamber]\nlaw = "{law}"\n' + marker, 1))
    return path


def test_the_run_writes_the_gas_temperature_of_a_thermal_muscle(tmp_path):
    proc = run_main("run", _pair_file_with_law(tmp_path, "thermal"), "-o", tmp_path / "out")
    assert proc.returncode == 0, proc.stderr
    header = (tmp_path / "out" / "antagonistic_pair.csv").read_text().splitlines()[0].split(",")
    assert "flexor.gas_temperature_K" in header and "extensor.gas_temperature_K" not in header


def test_the_statics_take_the_pressures_and_leave_the_pneumatics_out(pair_runs):
    """With its pressures prescribed a muscle's tube carries nothing to the joint: the same equilibrium and
    stiffness as the pair without it, bit for bit; a hysteresis element that reads the chamber's pressure
    reads the prescribed one."""
    scenario, _ = pair_runs
    plain = JointStatics(load_joint_scenario(SCENARIOS / "antagonistic_pair.toml"))
    statics = JointStatics(scenario)
    for p in ((2.2e5, 2.0e5), (3.0e5, 1.0e5)):
        assert statics.equilibrium(p) == plain.equilibrium(p)
    hysteresis = {**THERMAL_TUBE, "hysteresis": {"model": "maxwell_slip", "slip_displacement_m": [1e-3],
                                                 "share": [1.0]}}
    with_elements = JointScenario.from_dict(_pair(hysteresis), origin="<pair>", base_dir=SCENARIOS)
    assert JointStatics(with_elements).equilibrium((2.2e5, 2.0e5)).theta_rad == pytest.approx(
        plain.equilibrium((2.2e5, 2.0e5)).theta_rad, abs=1e-3)


def test_the_statics_leave_a_whole_supply_chain_out():
    """The supply chain's supply, feed hose, reservoir and tube on the flexor: with its pressure given none
    of them is in the statics' model (the reservoir too, which only the valve and the hose reach), and the
    equilibrium is the shipped pair's."""
    rig = tomllib.loads((SCENARIOS / "supply_chain.toml").read_text())
    chain = {"pressure": {k: rig["pressure"][k] for k in ("supply_port", "outlet_port")},
             "component": rig["component"]}
    scenario = JointScenario.from_dict(_pair(chain), origin="<pair>", base_dir=SCENARIOS)
    statics = JointStatics(scenario)
    assert not [n for n in statics.code.names["states"] if n.startswith("flexor_") and "chamber" not in n
                and n.split(".")[0] in ("flexor_supply", "flexor_feed", "flexor_reservoir", "flexor_tube")]
    plain = JointStatics(load_joint_scenario(SCENARIOS / "antagonistic_pair.toml"))
    assert statics.equilibrium((2.2e5, 2.0e5)) == plain.equilibrium((2.2e5, 2.0e5))


@pytest.mark.parametrize("change, key", [
    ({"chamber": {"law": "bogus"}}, "muscle 'flexor': chamber.law = 'bogus'"),
    ({"chamber": {"law": "thermal", "h_W_per_m2_K": -1.0}}, "muscle 'flexor': chamber.h_W_per_m2_K"),
    ({**THERMAL_TUBE, "component": [{**THERMAL_TUBE["component"][0], "diameter_m": -0.004}]},
     "muscle 'flexor': component[0].diameter_m = -0.004"),
    ({**THERMAL_TUBE, "component": [{**THERMAL_TUBE["component"][0], "connect": {"outlet": "nothing.port"}}]},
     "'nothing.port'"),
])
def test_a_bad_pneumatic_table_of_a_joint_muscle_is_refused_by_key(change, key):
    with pytest.raises(ScenarioError) as info:
        JointScenario.from_dict(_pair(change), origin="<pair>", base_dir=SCENARIOS)
    assert key in str(info.value)


def test_the_command_refuses_a_joint_muscles_unknown_law_with_exit_2(tmp_path):
    assert_refused(run_main("run", _pair_file_with_law(tmp_path, "bogus"), "-o", tmp_path / "out"),
                   "muscle 'flexor': chamber.law = 'bogus'", tmp_path / "out")


def test_on_an_elastic_tendon_the_chamber_follows_the_muscles_own_end():
    """The chamber's volume is the braid's at the muscle's own contraction (the series spring's node), not at
    its tendon path's, which the spring's stretch (about 10 mm here) keeps apart from it."""
    scenario = load_joint_scenario(SCENARIOS / "antagonistic_elastic.toml")
    run = simulate_joint(scenario)
    for m in scenario.joint_muscles():
        own = run.signals[f"{m.name}_series_spring.x_m"]
        path = run.signals[f"{m.name}_pulley.x_m"]
        assert np.max(np.abs(own - path)) > 5e-3
        volume = run.signals[f"{m.name}_chamber.volume_m3"]
        assert np.array_equal(volume, m.source.chamber.volume_m3(own)) or \
            np.max(np.abs(volume - m.source.chamber.volume_m3(own))) < 1e-15
