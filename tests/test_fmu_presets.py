"""An FMU built for a muscle or a scenario carries it.

Run by fmpy alone, with no start values and no inputs set, and without pamsim's runner (which sets
every value itself, so that its tests cannot see what an FMU starts with), an FMU built with
``--scenario S`` runs what the python backend runs for S, and one built with ``--muscle M`` starts
with M's parameters.  References: ``pamsim.simulate`` on the same scenario, and the muscle files.
"""

from __future__ import annotations

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

import pamsim
from conftest import SCENARIOS, run_main
from pamsim.fmu import build
from pamsim.fmu.preset import for_scenario
from pamsim.fmu.runner import set_values
from pamsim.fmu.variables import VARIABLES
from pamsim.muscle_setup import muscle_parameters
from pamsim.muscles import load_muscle
from test_fmu import _Api, _error_status, _instance

MAX_DIFF_M = 0.2e-3
FINAL_DIFF_M = 0.05e-3
FMU_PARAMETERS = {v.name for v in VARIABLES if v.causality == "parameter" and v.kind == "real"}


def _scenarios(folder):
    """Scenarios of three muscles (the exact polynomial and two tables) and with every kind of signal."""
    fig4 = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    (folder / "pressure.csv").write_text("t_s,p_gauge_bar\n0,0\n0.5,1.0\n0.9,3.0\n1.4,2.0\n2.0,3.5\n")
    return {
        "shadow_fig4": fig4,
        # The survey's 45 mm muscle at 7.58 bar with 0.05 N: it rises past the braid lock to 13.26 mm.
        "survey_45mm": pamsim.Scenario.from_dict({
            "model": {"muscle": "mpam_survey_45mm"}, "load": {"weight_N": 0.05},
            "pressure": {"source": "valve", "supply_gauge_bar": 7.58, "valve_open_time_s": 1.0},
            "simulation": {"duration_s": 3.0}}, name="survey_45mm"),
        "kothera_5a_energy": fig4.with_changes(
            {"model": {"muscle": "kothera2009_5a", "static_force": "kothera_energy"}, "load": {"weight_N": 10.0},
             "simulation": {"duration_s": 3.0}}, name="kothera_5a_energy"),
        # A valve command through a lag and a ramp of external force.
        "lag_and_ramp": pamsim.Scenario.from_dict({
            "load": {"weight_N": 12.74, "external_force": {"kind": "ramp", "start_s": 2.0, "end_s": 3.0,
                                                          "final_N": -6.0}},
            "pressure": {"source": "valve", "supply_gauge_bar": 3.6,
                         "command": {"kind": "lag", "time_s": 0.5, "tau_s": 0.2, "final": 1.0}},
            "simulation": {"duration_s": 5.0}}, name="lag_and_ramp"),
        # A measured pressure trace on Kothera's actuator 5a.
        "kothera_5a_trace": pamsim.Scenario.from_dict({
            "model": {"muscle": "kothera2009_5a", "static_force": "kothera_energy"}, "load": {"weight_N": 10.0},
            "pressure": {"source": "prescribed", "prescribed": {"kind": "trace", "file": "pressure.csv"}},
            "simulation": {"duration_s": 3.0}}, name="kothera_5a_trace", base_dir=folder),
    }


@pytest.fixture(scope="module")
def scenario_fmus(tmp_path_factory):
    """{name: (scenario, {version: FMU built for it})}; FMI 3.0 for two of them."""
    folder = tmp_path_factory.mktemp("presets")
    out = {}
    for name, sc in _scenarios(folder).items():
        versions = (2, 3) if name in ("survey_45mm", "lag_and_ramp") else (2,)
        out[name] = sc, {v: build(folder / f"{name}_{v}.fmu", v, preset=for_scenario(sc)) for v in versions}
    return out


CASES = [(n, v)
         for n in ("shadow_fig4", "survey_45mm", "kothera_5a_energy", "lag_and_ramp", "kothera_5a_trace")
         for v in ((2, 3) if n in ("survey_45mm", "lag_and_ramp") else (2,))]


@pytest.mark.parametrize("interface", ["CoSimulation", "ModelExchange"])
@pytest.mark.parametrize("name,version", CASES)
def test_scenario_fmu_alone_runs_as_the_python_backend(scenario_fmus, name, version, interface):
    sc, paths = scenario_fmus[name]
    ref = pamsim.simulate(sc)
    assert ref.x_m.max() > 2e-3  # the load rose: an FMU that never opens its valve stays at 0 mm
    res = simulate_fmu(str(paths[version]), fmi_type=interface)  # nothing set: the FMU's own start values
    assert res["time"][-1] == pytest.approx(sc.duration_s)  # its DefaultExperiment is the scenario's run
    x = res["contraction_m"]
    diff = np.abs(x - np.interp(res["time"], ref.t_s, ref.x_m))
    assert diff.max() <= MAX_DIFF_M, f"max contraction difference {diff.max() * 1e3:.4f} mm"
    assert abs(x[-1] - ref.x_m[-1]) <= FINAL_DIFF_M, f"final {x[-1] * 1e3:.4f} mm, python {ref.x_m[-1] * 1e3:.4f} mm"


def test_scenario_fmu_declares_the_scenario_as_its_start_and_run(scenario_fmus):
    sc, paths = scenario_fmus["survey_45mm"]
    md = read_model_description(str(paths[2]))
    start = {v.name: v for v in md.modelVariables}
    for name, p in sc.parameters.entries.items():
        if name in FMU_PARAMETERS:
            assert float(start[name].start) == p.value, name
            assert p.source in start[name].description, name
    assert float(start["supply_pressure_gauge_Pa"].start) == sc.final_pressure_gauge_Pa
    assert float(start["load_mass_kg"].start) == sc.mass_kg
    assert start["input_source"].start == "1"
    assert "step 0 -> 1 at 1 s" in start["valve_command"].description
    assert "scenario survey_45mm" in md.description
    run = md.defaultExperiment
    assert (float(run.stopTime), float(run.stepSize), float(run.tolerance)) == (
        sc.duration_s, 1.0 / sc.solver.sample_rate_Hz, sc.solver.rtol)


@pytest.mark.parametrize("muscle", ["shadow_6x300_acra2012", "mpam_survey_45mm", "kothera2009_5a"])
def test_muscle_fmu_starts_with_the_muscle_values_and_its_default_model(tmp_path, muscle):
    """``--muscle M`` alone: M's parameters (with the dynamics' defaults it lacks, each with its
    provenance) are the start values, and M's default static model is the FMU's static force."""
    path = tmp_path / "m.fmu"
    out = run_main("fmu", "build", "--muscle", muscle, "-o", path)
    assert out.returncode == 0, out.stderr
    default = load_muscle(muscle).default_static_force
    table = default != "acra2012_polynomial"
    assert (f"table of {default}" if table else "the ACRA 2012 polynomial, exact") in out.stdout
    md = read_model_description(str(path))
    start = {v.name: v for v in md.modelVariables}
    _, params = muscle_parameters(muscle)
    carried = [n for n in params.entries if n in FMU_PARAMETERS]
    assert {"L0_m", "r0_m", "theta0_deg", "rated_pressure_gauge_Pa"} <= set(carried)
    for name in carried:
        assert float(start[name].start) == params[name], name
        assert params.entries[name].source in start[name].description, name
    assert start["static_force_model"].start == ("1" if table else "0")
    assert f"muscle {muscle}" in md.description


def test_survey_muscle_fmu_takes_its_own_rating_and_stops_at_its_own_stop(tmp_path):
    """Its own rating (8.27 bar) is accepted, where the Shadow muscle's 4.5 bar refused 7.58 bar, and the
    load comes to rest where the python backend has it (13.55 mm, past the braid lock)."""
    path = tmp_path / "survey.fmu"
    assert run_main("fmu", "build", "--muscle", "mpam_survey_45mm", "-o", path).returncode == 0
    _, params = muscle_parameters("mpam_survey_45mm")
    rating, weight_N = params["rated_pressure_gauge_Pa"], 0.05
    res = simulate_fmu(str(path), stop_time=2.0, start_values={
        "valve_command": 1.0, "supply_pressure_gauge_Pa": rating, "load_mass_kg": weight_N / params["g_m_s2"]})
    ref = pamsim.simulate(pamsim.Scenario.from_dict({
        "model": {"muscle": "mpam_survey_45mm"}, "load": {"weight_N": weight_N},
        "pressure": {"source": "valve", "supply_gauge_Pa": rating, "valve_open_time_s": 0.0},
        "simulation": {"duration_s": 2.0}}))
    assert ref.x_m[-1] > 5e-3
    assert abs(res["contraction_m"][-1] - ref.x_m[-1]) <= FINAL_DIFF_M


@pytest.mark.parametrize("version", [2, 3])
def test_inputs_follow_the_scenario_until_the_importer_takes_them(scenario_fmus, version, capfd):
    """With input_source = scenario, an input set to its signal's value is accepted (an importer
    echoing start values) and another value refused: at the end of initialisation (until then the
    importer may still set input_source, in any order), and at once after it."""
    sc, paths = scenario_fmus["survey_45mm"]
    fmus = {version: paths[version]}
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    api.set("valve_command", 1.0)
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    assert _error_status(fmu.exitInitializationMode) == 3
    assert ("valve_command = 1, set by the importer: this FMU's inputs follow the signals of the scenario it was "
            "built from (input_source = scenario; 0 at t = 0 s)") in capfd.readouterr().out
    fmu.freeInstance()
    # Echoed start values are its signals' values: accepted; after initialisation another value is refused.
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    api.set("valve_command", 0.0)
    api.init()
    assert _error_status(lambda: api.set("valve_command", 1.0)) == 3
    assert "valve_command = 1: this FMU's inputs follow the signals" in capfd.readouterr().out
    api.step(0.0, 1.5)
    assert api.get("valve_command")[0] == 1.0 and api.get("contraction_m")[0] > 5e-3  # its step at 1 s
    fmu.terminate()
    fmu.freeInstance()
    # Taken over, input set before input_source: the valve stays shut until the importer opens it.
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    api.set("supply_pressure_gauge_Pa", 3e5)
    set_values(fmu, version, {"input_source": 0})
    api.init()
    api.step(0.0, 1.5)
    assert api.get("valve_command")[0] == 0.0 and api.get("contraction_m")[0] == 0.0
    api.set("valve_command", 1.0)
    api.step(1.5, 1.5)
    assert api.get("supply_pressure_gauge_Pa", "p_gauge_Pa") == pytest.approx([3e5, 3e5], rel=1e-6)
    assert api.get("contraction_m")[0] > 5e-3
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_an_fmu_without_a_scenario_refuses_to_follow_one(fmus, version, capfd):
    fmu = _instance(fmus, version)
    set_values(fmu, version, {"input_source": 1})
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    assert _error_status(fmu.exitInitializationMode) == 3
    assert "input_source = 1 (scenario): this FMU was built without a scenario" in capfd.readouterr().out
    fmu.freeInstance()


def test_a_signal_beyond_a_changed_rating_is_refused(scenario_fmus, capfd):
    """The signals are checked against the parameters at initialisation, at every knot."""
    sc, paths = scenario_fmus["kothera_5a_trace"]
    top = max(v for v in _trace_values(sc))
    fmu = _instance({2: paths[2]}, 2)
    _Api(fmu, 2).set("rated_pressure_gauge_Pa", 0.9 * top)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    assert _error_status(fmu.exitInitializationMode) == 3
    log = capfd.readouterr().out
    assert f"prescribed_pressure_gauge_Pa = {top:g} Pa: exceeds the muscle's rating" in log
    assert "the scenario's signal of prescribed_pressure_gauge_Pa leaves the input's range" in log
    fmu.freeInstance()


def _trace_values(sc):
    return sc.build_model().source.p_gauge_Pa.values


def test_cli_builds_a_scenario_fmu(tmp_path):
    path = tmp_path / "fig4.fmu"
    out = run_main("fmu", "build", "--scenario", SCENARIOS / "acra2012_fig4.toml", "-o", path)
    assert out.returncode == 0, out.stderr
    assert "for scenario acra2012_fig4" in out.stdout
    assert read_model_description(str(path)).defaultExperiment.stopTime == "8.0"


def test_the_runner_drives_a_scenario_fmu(scenario_fmus):
    """pamsim's runner sets input_source = importer, so it also runs an FMU built for a scenario."""
    from pamsim.fmu.runner import run_cs

    sc, paths = scenario_fmus["lag_and_ramp"]
    ref = pamsim.simulate(sc)
    tr = run_cs(sc, 2, fmu_path=paths[2])
    assert np.abs(tr["contraction_m"] - ref.x_m).max() <= MAX_DIFF_M


def test_docs_snippet_runs_a_scenario_fmu_as_pamsim_run(tmp_path, paper_results):
    import re
    import subprocess
    import sys

    docs = (SCENARIOS.parent / "docs" / "fmu.md").read_text()
    (code,) = [b for b in re.findall(r"```python\n(.*?)```", docs, flags=re.S) if "fig4.fmu" in b]
    command = re.search(r"# pamsim (fmu build .*)", code).group(1).split()
    out = run_main(*[SCENARIOS.parent / a if a.startswith("scenarios/") else tmp_path / a if a.endswith(".fmu")
                     else a for a in command])
    assert out.returncode == 0, out.stderr
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    expected = f"{paper_results['acra2012_fig4'][1].x_m[-1] * 1e3:.2f}"
    assert re.findall(r"final contraction (\S+) mm", r.stdout) == [expected]
