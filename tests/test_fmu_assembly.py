"""The FMU of an assembly of components (pamsim.fmu.assembly_fmu): built by ``pamsim fmu build
--scenario`` for a scenario that adds a component, it validates, runs in plain fmpy as the scenario's
run, and its directional derivatives and ModelStructure are the exact Jacobians of the flat model."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

import pamsim  # noqa: E402
from pamsim.assemblies.one_muscle import scenario_assembly  # noqa: E402

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "parallel_spring.toml"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The FMI 2.0 and 3.0 FMUs of the spring scenario, built as a user builds them."""
    out = tmp_path_factory.mktemp("assembly_fmu")
    paths = {}
    for version in (2, 3):
        path = out / f"spring{version}.fmu"
        proc = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario", str(SCENARIO),
                               "--fmi", str(version), "-o", str(path)], capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
        assert "generated from the assembly" in proc.stdout
        paths[version] = str(path)
    return paths


@pytest.fixture(scope="module")
def python_run():
    return pamsim.run(pamsim.load_scenario(SCENARIO))


@pytest.fixture(scope="module")
def flat():
    return scenario_assembly(pamsim.load_scenario(SCENARIO)).flatten()


@pytest.mark.parametrize("version", [2, 3])
def test_it_validates(built, version):
    assert validate_fmu(built[version]) == []


# Co-simulation runs the engine at the scenario's tolerance (its DefaultExperiment), model exchange
# fmpy's CVode at its own default: each bound is a few times the difference measured.
@pytest.mark.parametrize("version, kind, bound_mm", [(2, "CoSimulation", 2e-4), (3, "CoSimulation", 2e-4),
                                                     (2, "ModelExchange", 2e-3), (3, "ModelExchange", 2e-3)])
def test_plain_fmpy_runs_the_scenario(built, python_run, version, kind, bound_mm):
    r = fmpy.simulate_fmu(built[version], fmi_type=kind, output=["load.x_m", "load.mode", "spring.F_spring_N"])
    x_mm = r["load.x_m"] * 1e3
    result = python_run.result
    assert abs(x_mm[-1] - result.x_m[-1] * 1e3) < bound_mm
    # The whole trajectory, at fmpy's output times (a subset of the python run's samples).
    assert np.max(np.abs(x_mm - np.interp(r["time"], result.t_s, result.x_m) * 1e3)) < bound_mm
    assert x_mm.max() > 40.0  # it did lift the load
    assert r["load.mode"][-1] == 0  # held at the end, as the python run
    assert r["time"][-1] == pytest.approx(pamsim.load_scenario(SCENARIO).duration_s)


def test_model_structure_is_the_jacobians_sparsity(built, flat):
    md = fmpy.read_model_description(built[2])
    by_name = {v.name: v for v in md.modelVariables}
    sp = flat.sparsity()
    xs = [v.name for v in flat.states]
    us = [v.name for v in flat.inputs]
    for unknown in md.derivatives:
        i = xs.index(unknown.variable.name[4:-1])
        want = {xs[j] for j in sp["A"][i]} | {us[j] for j in sp["B"][i]}
        assert {d.name for d in unknown.dependencies} == want, unknown.variable.name
    ys = [v.name for v in flat.outputs]
    checked = 0
    for unknown in md.outputs:
        name = unknown.variable.name
        if name in xs or name not in ys:
            continue
        i = ys.index(name)
        want = {xs[j] for j in sp["C"][i]} | {us[j] for j in sp["D"][i]}
        assert {d.name for d in unknown.dependencies} == want, name
        checked += 1
    assert checked >= 10 and "spring.F_spring_N" in by_name


def _instance(path, md):
    unzipped = fmpy.extract(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="t")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    return fmu


def _sliding(path):
    """A co-simulation instance stepped until its load slides (mode 1), and its model description."""
    md = fmpy.read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = _instance(path, md)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    t = 0.0
    while fmu.getInteger([vr["load.mode"]])[0] != 1:
        fmu.doStep(t, 1e-3)
        t += 1e-3
        assert t < 2.0, "the load never slid"
    return fmu, md, vr


def _exact(flat, fmu, vr):
    """The flat model's exact Jacobian [A B; C D] at the FMU's state, inputs, parameters and mode."""
    x = fmu.getReal([vr[v.name] for v in flat.states])
    u = fmu.getReal([vr[v.name] for v in flat.inputs])
    p = fmu.getReal([vr[v.name] for v in flat.parameters])
    q = [float(fmu.getInteger([vr["load.mode"]])[0])]
    A, B, C, D = (np.array(m) for m in flat.function("jacobian")(x, u, p, q))
    return np.block([[A, B], [C, D]])


@pytest.mark.parametrize("n_knowns", [1, 2, "all"])
def test_directional_derivatives_are_the_exact_jacobian(built, flat, n_knowns):
    fmu, md, vr = _sliding(built[2])
    J = _exact(flat, fmu, vr)
    xs, us, ys = [v.name for v in flat.states], [v.name for v in flat.inputs], [v.name for v in flat.outputs]
    knowns = xs + us
    unknown_rows = {f"der({n})": i for i, n in enumerate(xs)}
    unknown_rows.update({n: len(xs) + i for i, n in enumerate(ys) if n not in xs and n in vr and n not in
                         {v.name for v in flat.parameters}})
    rng = np.random.default_rng(7)
    chosen = knowns if n_knowns == "all" else list(rng.choice(knowns, n_knowns, replace=False))
    seed = rng.normal(size=len(chosen))
    names = list(unknown_rows)
    got = fmu.getDirectionalDerivative([vr[n] for n in names], [vr[k] for k in chosen], list(seed))
    cols = [knowns.index(k) for k in chosen]
    want = J[[unknown_rows[n] for n in names]][:, cols] @ seed
    scale = np.abs(J[[unknown_rows[n] for n in names]][:, cols]) @ np.abs(seed) + 1e-300
    assert np.all(np.abs(np.array(got) - want) <= 1e-12 * scale + 1e-300), (names, got, want)
    assert np.count_nonzero(want) > 3  # a sliding load: the derivatives do depend on the knowns
    fmu.terminate()
    fmu.freeInstance()


def test_initialisation_derivatives_follow_the_start(built, flat):
    md = fmpy.read_model_description(built[2])
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = _instance(built[2], md)
    fmu.enterInitializationMode()
    d_x = fmu.getDirectionalDerivative([vr["load.x_m"]], [vr["load.initial_contraction_m"]], [1.0])
    assert d_x[0] == pytest.approx(1.0, abs=1e-15)
    # The initial air mass against a central difference of the generated initial state.
    x0 = flat.function("x0")
    p = np.array(fmu.getReal([vr[v.name] for v in flat.parameters]))
    u = fmu.getReal([vr[v.name] for v in flat.inputs])
    k = [v.name for v in flat.parameters].index("chamber.initial_pressure_gauge_Pa")
    m = [v.name for v in flat.states].index("chamber.air_mass_kg")
    h = 1e3
    hi, lo = p.copy(), p.copy()
    hi[k] += h
    lo[k] -= h
    fd = (float(x0(u, hi)[0][m]) - float(x0(u, lo)[0][m])) / (2 * h)
    got = fmu.getDirectionalDerivative([vr["chamber.air_mass_kg"]], [vr["chamber.initial_pressure_gauge_Pa"]], [1.0])
    assert got[0] == pytest.approx(fd, rel=1e-9)
    fmu.freeInstance()


def test_a_serialized_state_continues_in_another_instance(built):
    fmu, md, vr = _sliding(built[2])
    state = fmu.serializeFMUstate(fmu.getFMUstate())
    other = _instance(built[2], md)
    other.enterInitializationMode()
    other.exitInitializationMode()
    other.setFMUstate(other.deSerializeFMUstate(state))
    names = [vr["load.x_m"], vr["load.v_m_s"], vr["chamber.p_abs_Pa"], vr["spring.W_spring_J"]]
    assert other.getReal(names) == fmu.getReal(names)
    broken = bytearray(state)
    broken[len(broken) // 2] ^= 1
    with pytest.raises(Exception):
        other.deSerializeFMUstate(bytes(broken))
    for inst in (fmu, other):
        inst.terminate()
        inst.freeInstance()


@pytest.mark.parametrize("name, value", [("valve_command", 2.0), ("spring.k_N_per_m", math.nan),
                                         ("load.mass_kg", -1.0), ("load.restitution", 2.0),
                                         ("spring.k_N_per_m", -1.0), ("chamber.T_initial_K", -1.0)])
def test_bad_values_are_refused(built, name, value, capfd):
    """Refused when set (an input) or at the end of initialisation (a parameter), naming it: the ranges
    the components declare (a mass, a temperature above zero, a restitution in [0, 1])."""
    md = fmpy.read_model_description(built[2])
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = _instance(built[2], md)
    capfd.readouterr()
    with pytest.raises(Exception):
        fmu.setReal([vr[name]], [value])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
    assert f"{name} = {value:g}" in capfd.readouterr().out
    fmu.freeInstance()


def test_the_generated_fmu_of_the_rig_alone_runs_figure_4(tmp_path):
    """``--generated``: the paper's rig itself as the FMU generated from its components, run by plain
    fmpy as ``pamsim run`` runs it (56.03 mm)."""
    path = tmp_path / "fig4.fmu"
    scenario = SCENARIO.with_name("acra2012_fig4.toml")
    proc = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario", str(scenario), "--generated",
                           "-o", str(path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert validate_fmu(str(path)) == []
    ref = pamsim.simulate(pamsim.load_scenario(scenario))
    for kind, bound_mm in (("CoSimulation", 2e-4), ("ModelExchange", 2e-3)):
        r = fmpy.simulate_fmu(str(path), fmi_type=kind, output=["load.x_m"])
        assert abs(r["load.x_m"][-1] - ref.x_m[-1]) * 1e3 < bound_mm
        assert np.max(np.abs(r["load.x_m"] - np.interp(r["time"], ref.t_s, ref.x_m))) * 1e3 < 10 * bound_mm


def test_generated_needs_a_scenario(tmp_path):
    bad = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--generated", "-o", str(tmp_path / "a.fmu")],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "--generated: needs --scenario" in bad.stderr


def test_the_generated_fmu_of_a_tabulated_model_runs_its_table_as_python_does(tmp_path):
    """An implicit model's spline table has a CasADi form: the generated FMU evaluates the same knots and
    coefficients in C (its Jacobians, and so the ModelStructure, through them) and meets the python
    backend's run of the table (measured 4.5e-14 m at the end in co-simulation, 2.5e-11 m with CVode)."""
    implicit = tmp_path / "implicit.toml"
    implicit.write_text('[model]\nmuscle = "mpam_survey_45mm"\nstatic_force = "mpam_two_phase"\n'
                        '[parameters]\nE_nylon_Pa = 3e9\n[load]\nweight_N = 0.05\n'
                        '[pressure]\nsource = "valve"\nsupply_gauge_bar = 7.58\nvalve_open_time_s = 0.1\n'
                        '[simulation]\nduration_s = 1.0\n')
    path = tmp_path / "b.fmu"
    proc = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario", str(implicit), "--generated",
                           "-o", str(path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert validate_fmu(str(path)) == []
    ref = pamsim.simulate(pamsim.load_scenario(implicit))
    assert ref.x_m[-1] > 0.01  # it lifts the load
    for kind, bound_mm in (("CoSimulation", 2e-4), ("ModelExchange", 2e-3)):
        r = fmpy.simulate_fmu(str(path), fmi_type=kind, output=["load.x_m"])
        assert abs(r["load.x_m"][-1] - ref.x_m[-1]) * 1e3 < bound_mm
        assert np.max(np.abs(r["load.x_m"] - np.interp(r["time"], ref.t_s, ref.x_m))) * 1e3 < 10 * bound_mm


def test_generated_needs_a_scenario_whose_physics_has_c(tmp_path, floats_only_gaylord):
    """A static model that takes floats alone has no C: the generated FMU is refused naming it, and
    nothing is written."""
    from pamsim.errors import InputError
    from pamsim.fmu.assembly_fmu import build_assembly

    scenario = pamsim.load_scenario(SCENARIO).with_changes({"model": {"static_force": "gaylord"}})
    with pytest.raises(InputError, match="needs C for every component.*muscle.force_N"):
        build_assembly(scenario, tmp_path / "c.fmu")
    assert not (tmp_path / "c.fmu").exists()


def test_a_supply_a_rounding_off_the_chamber_runs_on(built, python_run):
    """fmpy's input interpolation sets the supply 6e-11 Pa above the chamber it settled at: no flow, so
    nothing to settle the air mass by (it once became 0/0 = NaN and the step failed); the run goes on."""
    sig = np.array([(0.0, 0.0, 360000.0, 0.0), (1.0, 0.0, 360000.0, 0.0), (1.0, 1.0, 360000.0, 0.0),
                    (8.0, 1.0, 360000.0, 0.0)],
                   dtype=[("time", float), ("valve_command", float), ("supply_pressure_gauge_Pa", float),
                          ("external_force_N", float)])
    r = fmpy.simulate_fmu(built[2], fmi_type="CoSimulation", start_values={"input_source": 0}, input=sig,
                          output=["load.x_m", "chamber.air_mass_kg"])
    assert np.isfinite(r["chamber.air_mass_kg"]).all()
    assert abs(r["load.x_m"][-1] - python_run.result.x_m[-1]) < 2e-7


def test_the_generated_code_kept_per_structure_gives_the_spec_generated_afresh():
    """A scenario of the same structure with other values reuses the kept C; its FMU description, sources
    and token equal those generated with nothing kept, and differ from the first scenario's."""
    from pamsim.fmu import assembly_fmu

    sc = pamsim.load_scenario(SCENARIO)
    other = sc.with_changes({"load": {"weight_N": 30.0}})
    first = assembly_fmu.assembly_spec(sc)
    kept = assembly_fmu.assembly_spec(other)
    assembly_fmu._GENERATED.clear()
    afresh = assembly_fmu.assembly_spec(other)
    assert kept == afresh and kept.token == afresh.token
    assert first.token != kept.token and first.generated == kept.generated


def test_the_temporary_fmu_folder_keeps_the_recently_used(tmp_path, monkeypatch):
    """Beyond TEMP_FMUS_KEPT entries the least recently used idle ones go; recently used ones stay."""
    import importlib
    import os
    import time

    build = importlib.import_module("pamsim.fmu.build")  # the package's `build` is the function

    root = tmp_path / "pamsim-fmu"
    monkeypatch.setattr(build, "temp_fmu_root", lambda: root)
    now = time.time()
    for k in range(build.TEMP_FMUS_KEPT + 6):  # entry 0 the newest, all idle for over an hour
        (root / f"old{k}").mkdir(parents=True)
        os.utime(root / f"old{k}", (now - 3600 - k, now - 3600 - k))
    for k in range(3):
        (root / f"busy{k}").mkdir()  # used a minute ago: never removed, though the oldest would go first
        os.utime(root / f"busy{k}", (now - 60, now - 60))

    made = []
    path = build.temp_fmu("{new}", "m.fmu", lambda p: (p.parent.mkdir(parents=True), p.write_text("x"), made.append(p)))
    assert path == root / "new" / "m.fmu" and path.is_file() and made == [path]
    names = {p.name for p in root.iterdir()}
    assert {"new", "busy0", "busy1", "busy2"} <= names and len(names) == build.TEMP_FMUS_KEPT
    assert {f"old{k}" for k in range(build.TEMP_FMUS_KEPT - 4)} <= names  # the newest idle kept
    assert build.temp_fmu("{new}", "m.fmu", lambda p: made.append(p)) == path and len(made) == 1  # built once


@pytest.mark.parametrize("backend", ["fmu-cs", "fmu-me"])
def test_pamsim_run_takes_a_scenario_with_added_components_on_the_fmu_backends(tmp_path, python_run, backend):
    """``pamsim run --backend fmu-cs|fmu-me`` runs the spring scenario through its assembly's FMU, as
    ``pamsim.simulate`` does (it was refused naming the key 'component'), and ends where python does."""
    import json

    out = tmp_path / backend
    proc = subprocess.run([sys.executable, "-m", "pamsim", "run", str(SCENARIO), "--backend", backend, "--no-plot",
                           "-o", str(out)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    final = json.loads((out / "parallel_spring.json").read_text())["final_contraction_m"]
    assert final == pytest.approx(python_run.result.x_m[-1], abs=2e-6)  # within the FMU runs' bounds above
