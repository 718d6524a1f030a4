"""The FMU (FMI 2.0 and 3.0, Model Exchange and Co-Simulation) against the Python simulator.

Each FMU is built once per session from the current sources.  The reference
is ``pamsim.simulate`` (solve_ivp, LSODA) on the same scenario: the two
implementations share no code, so agreement checks the C equations, the
event logic and both FMI wrappers.
"""

from __future__ import annotations

import ctypes
import math
import re
import time
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

import pamsim
from conftest import PAPER_SCENARIOS, SCENARIOS
from pamsim.fmu import build
from pamsim.fmu.muscle_spec import c_header, token
from pamsim.fmu.runner import ScenarioInputs, run_cs, run_me, set_values, start_values
from pamsim.fmu.variables import BY_NAME, VARIABLES, value_reference
from pamsim.parameters import get_parameter_set

MAX_DIFF_M = 0.2e-3
FINAL_DIFF_M = 0.05e-3


@pytest.fixture(scope="session")
def traces(fmus, paper_results):
    """{(scenario, interface, version): trace} for the five paper scenarios."""
    out = {}
    for name, (sc, _) in paper_results.items():
        for v in (2, 3):
            out[name, "cs", v] = run_cs(sc, v, fmu_path=fmus[v])
            out[name, "me", v] = run_me(sc, v, fmu_path=fmus[v])
    return out


def vr(name: str) -> int:
    """The value reference of ``name``: pinned for the FMU's own variables, the generated model's next."""
    from pamsim.fmu.muscle_spec import one_muscle_spec

    return value_reference(name) if name in BY_NAME else one_muscle_spec(2).vr(name)


def n_states(path) -> int:
    """The FMU's continuous states: contraction, velocity, chamber pressure and air mass, then the work
    integrals of the generated model (``muscle.W_muscle_J``, ...)."""
    from fmpy import read_model_description

    return len(read_model_description(str(path)).derivatives)


def _diff(trace, result):
    assert np.allclose(trace["t_s"], result.t_s, atol=1e-9)
    return np.abs(trace["contraction_m"] - result.x_m)


# ------------------------------------------------------------------ the archive


@pytest.mark.parametrize("version", [2, 3])
def test_validate_fmu_reports_no_problems(fmus, version):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(fmus[version])) == []


@pytest.mark.parametrize("version,platform", [(2, "binaries/linux64/"), (3, "binaries/x86_64-linux/")])
def test_archive_layout(fmus, version, platform):
    from pamsim.fmu.muscle_spec import one_muscle_spec

    names = zipfile.ZipFile(fmus[version]).namelist()
    assert f"{platform}pamsim_muscle.so" in names
    spec = one_muscle_spec(version)
    for src in (*(f"sources/{n}" for n in (*spec.sources, *spec.generated)), "sources/pam_variables.h",
                "sources/buildDescription.xml", f"sources/fmi{version}_wrapper.c", f"sources/fmi{version}Functions.h",
                "sources/FMI_HEADERS_LICENSE.txt"):
        assert src in names
    assert "sources/pam_model.c" in names  # the generated model


@pytest.mark.parametrize("version", [2, 3])
def test_model_description_and_header_come_from_the_table(fmus, version):
    xml = zipfile.ZipFile(fmus[version]).read("modelDescription.xml").decode()
    root = ET.fromstring(xml)
    tag = "ScalarVariable" if version == 2 else "*"
    declared = {e.get("name"): e for e in root.find("ModelVariables").findall(tag)}
    params = get_parameter_set("shadow_6x300_acra2012")
    for name, p in params.entries.items():
        e = declared[name]
        real = e.find("Real") if version == 2 else e
        assert float(real.get("start")) == p.value
        assert real.get("unit") == p.unit
        assert p.description in e.get("description")
        assert e.get("causality") == "parameter"
    for name in ("valve_command", "supply_pressure_gauge_Pa", "load_mass_kg", "external_force_N",
                 "prescribed_pressure_gauge_Pa"):
        assert declared[name].get("causality") == "input"
    for name in ("contraction_m", "velocity_m_s", "p_gauge_Pa", "F_static_N", "F_friction_N",
                 "friction_mode"):
        assert declared[name].get("causality") == "output"
    # The C header's value references are the XML's.
    header = zipfile.ZipFile(fmus[version]).read("sources/pam_variables.h").decode()
    assert header == c_header(version)
    for v in VARIABLES:
        vr = int(re.search(rf"#define VR_{re.escape(v.c_name)} (\d+)u", header).group(1))
        assert vr == int(declared[v.name].get("valueReference")) == value_reference(v.name)
    key = "guid" if version == 2 else "instantiationToken"
    assert root.get(key) == token(version) and token(version) in header


def test_token_is_deterministic_and_differs_between_versions(fmus, tmp_path):
    again = build(tmp_path / "again.fmu", 2)
    read = lambda p: ET.fromstring(zipfile.ZipFile(p).read("modelDescription.xml")).get("guid")  # noqa: E731
    assert read(again) == read(fmus[2]) == token(2)
    assert token(2) != token(3)


# ------------------------------------------------------------------ against the Python simulator


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("interface", ["cs", "me"])
@pytest.mark.parametrize("name", sorted(PAPER_SCENARIOS))
def test_paper_scenarios_match_python_simulator(traces, paper_results, name, interface, version):
    d = _diff(traces[name, interface, version], paper_results[name][1])
    assert d.max() <= MAX_DIFF_M, f"max contraction difference {d.max() * 1e3:.4f} mm"
    assert d[-1] <= FINAL_DIFF_M, f"final contraction difference {d[-1] * 1e3:.4f} mm"


@pytest.mark.parametrize("name", sorted(PAPER_SCENARIOS))
def test_friction_modes_match_python_simulator(traces, paper_results, name):
    ref = paper_results[name][1]
    for key in ("cs", "me"):
        modes = traces[name, key, 2]["friction_mode"]
        # Mode switches may land one sample apart; everything else must agree.
        assert np.mean(modes == ref.mode) > 0.995
        assert modes[-1] == ref.mode[-1]


@pytest.mark.parametrize("name", sorted(PAPER_SCENARIOS))
def test_model_exchange_and_co_simulation_agree(traces, name):
    for v in (2, 3):
        cs, me = traces[name, "cs", v], traces[name, "me", v]
        assert np.max(np.abs(cs["contraction_m"] - me["contraction_m"])) <= 0.05e-3
        assert np.max(np.abs(cs["p_gauge_Pa"] - me["p_gauge_Pa"])) <= 100.0
    # Both versions run the same core.
    assert np.array_equal(traces[name, "cs", 2]["contraction_m"], traces[name, "cs", 3]["contraction_m"])


def test_stick_resets_velocity_to_zero(traces):
    for (name, interface, v), tr in traces.items():
        held = tr["friction_mode"] != 1
        held &= tr["friction_mode"] != -1
        assert np.all(tr["velocity_m_s"][held] == 0.0), (name, interface, v)


@pytest.mark.parametrize("version", [2, 3])
def test_random_non_uniform_communication_steps(fmus, paper_results, version):
    sc, ref = paper_results["acra2012_fig4"]
    rng = np.random.default_rng(4)
    steps = rng.uniform(1e-5, 0.07, 400)
    steps[::7] = 1e-11  # tiny steps, some of which land next to events
    times = np.concatenate([[0.0], np.cumsum(steps)])
    times = np.append(times[times < sc.duration_s], sc.duration_s)
    t0 = time.perf_counter()
    tr = run_cs(sc, version, communication_times=times, fmu_path=fmus[version])
    assert time.perf_counter() - t0 < 20.0
    assert np.array_equal(tr["t_s"], times)
    x_ref = np.interp(times, ref.t_s, ref.x_m)
    assert np.max(np.abs(tr["contraction_m"] - x_ref)) <= MAX_DIFF_M
    assert abs(tr["contraction_m"][-1] - ref.x_m[-1]) <= FINAL_DIFF_M


# ------------------------------------------------------------------ other importers


def _inputs_and_starts(name):
    sc = pamsim.load_scenario(SCENARIOS / f"{name}.toml")
    return sc, ScenarioInputs(sc), start_values(sc)


def test_libcosim_matches_fmpy(fmus, traces):
    pytest.importorskip("libcosimpy", reason="libcosimpy (test extra) is not installed")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    sc, inputs, starts = _inputs_and_starts("acra2012_fig4")
    ex = CosimExecution.from_step_size(step_size=1_000_000)  # nanoseconds
    slave = ex.add_local_slave(CosimLocalSlave(fmu_path=str(fmus[2]), instance_name="muscle"))
    manipulator = CosimManipulator.create_override()
    ex.add_manipulator(manipulator)
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    for k, v in starts.items():
        (ex.real_initial_value if isinstance(v, float) else ex.integer_initial_value)(slave, value_reference(k), v)
    names = list(inputs(0.0))
    for k, v in inputs(0.0).items():
        ex.real_initial_value(slave, value_reference(k), v)
    x = []
    for k in range(8000):
        u = inputs(k * 1e-3)
        manipulator.slave_real_values(slave, [value_reference(n) for n in names], [u[n] for n in names])
        assert ex.step()
        x.append(observer.last_real_values(slave, [value_reference("contraction_m")])[0])
    fmpy_x = traces["acra2012_fig4", "cs", 2]["contraction_m"][1:]
    assert np.max(np.abs(np.array(x) - fmpy_x)) <= 1e-9


def _require_ecospy():
    """Skip unless ecospy imports; it loads libtbb12 (a Debian package, installed by .ci/run) at import."""
    try:
        import ecospy  # noqa: F401
    except ImportError:
        pytest.skip("ecospy (test extra) is not installed")
    except OSError as exc:
        pytest.skip(f"the Ecos importer cannot load libtbb12 (apt-get install libtbb12): {exc}")


@pytest.mark.parametrize("version", [2, 3])
def test_ecos_matches_fmpy(fmus, traces, version):
    _require_ecospy()
    from ecospy import EcosSimulation, EcosSimulationStructure

    sc, inputs, starts = _inputs_and_starts("acra2012_fig6a")
    structure = EcosSimulationStructure()
    structure.add_model("muscle", str(fmus[version]))
    init = {f"muscle::{k}": v for k, v in starts.items()}
    init.update({f"muscle::{k}": v for k, v in inputs(0.0).items()})
    structure.add_parameter_set("init", init)
    sim = EcosSimulation(structure=structure, step_size=1e-3)
    sim.init(parameter_set="init")
    x = [sim.get_real("muscle::contraction_m")]
    for k in range(8000):
        for n, v in inputs(k * 1e-3).items():
            sim.set_real(f"muscle::{n}", v)
        sim.step()
        x.append(sim.get_real("muscle::contraction_m"))
    sim.terminate()
    sim.free()
    assert np.max(np.abs(np.array(x) - traces["acra2012_fig6a", "cs", version]["contraction_m"])) <= 1e-9


# ------------------------------------------------------------------ FMI protocol


def _instance(fmus, version, interface="cs"):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Model, FMU2Slave
    from fmpy.fmi3 import FMU3Model, FMU3Slave

    md = read_model_description(fmus[version])
    cls = {(2, "cs"): FMU2Slave, (2, "me"): FMU2Model, (3, "cs"): FMU3Slave, (3, "me"): FMU3Model}[version, interface]
    fmu = cls(guid=md.guid if version == 2 else md.instantiationToken, unzipDirectory=extract(fmus[version]),
              modelIdentifier="pamsim_muscle", instanceName="muscle")
    fmu.instantiate()
    return fmu


class _Api:
    """Version-neutral calls on an fmpy instance."""

    def __init__(self, fmu, version):
        self.fmu, self.v = fmu, version

    def set(self, name, value):
        f = self.fmu.setReal if self.v == 2 else self.fmu.setFloat64
        f([vr(name)], [value])

    def get(self, *names):
        f = self.fmu.getReal if self.v == 2 else self.fmu.getFloat64
        return f([vr(n) for n in names])

    def mode(self):
        return (self.fmu.getInteger if self.v == 2 else self.fmu.getInt32)([value_reference("friction_mode")])[0]

    def init(self):
        if self.v == 2:
            self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def step(self, t, h):
        self.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)


def _error_status(call):
    from fmpy.fmi1 import FMICallException

    with pytest.raises(FMICallException) as info:
        call()
    return info.value.status


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("name,value,message", [
    ("load_mass_kg", -1.0, "load_mass_kg = -1: must be >= 0.001"),
    ("load_mass_kg", float("nan"), "must be a finite number"),
    ("supply_pressure_gauge_Pa", 5.0e5, "exceeds the muscle's rating"),
    ("valve_command", 2.0, "must lie in [-1, 1]"),
    ("L0_m", float("inf"), "must be a finite number"),
])
def test_bad_inputs_return_error_status_with_message(fmus, version, name, value, message, capfd):
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    assert _error_status(lambda: api.set(name, value)) == 3  # fmi2Error / fmi3Error
    assert message in capfd.readouterr().out
    # The value was rejected: the instance still initialises and steps.
    api.init()
    api.step(0.0, 0.01)
    fmu.terminate()
    fmu.freeInstance()


def _initialise_with(unzipped, version, values):
    """Instantiate (CS), set ``values`` and initialise; returns the status of exitInitializationMode
    (0 OK, 3 error).  The FMU logs to stdout."""
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    cls = FMU2Slave if version == 2 else FMU3Slave
    fmu = cls(guid=token(version), unzipDirectory=unzipped[version], modelIdentifier="pamsim_muscle",
              instanceName="check")
    fmu.instantiate()
    api = _Api(fmu, version)
    try:
        set_values(fmu, version, {n: int(x) if BY_NAME[n].kind == "integer" else float(x) for n, x in values.items()})
        if version == 2:
            fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        try:
            fmu.exitInitializationMode()
            status = 0
            fmu.terminate()
        except FMICallException as exc:
            status = exc.status
    finally:
        fmu.freeInstance()
    return status


def _python_reason(name, value):
    """Why ``pamsim.Scenario.from_dict`` refuses ``parameters.name = value`` (it must refuse)."""
    spec = {"load": {"weight_N": 22.74}, "pressure": {"source": "valve", "supply_gauge_bar": 3.6,
                                                      "valve_open_time_s": 1.0},
            "simulation": {"duration_s": 1.0}, "parameters": {name: value}}
    with pytest.raises(pamsim.ScenarioError, match=rf"parameters\.{name} = ") as info:
        pamsim.Scenario.from_dict(spec)
    return str(info.value).split(f"parameters.{name} = {value!r}: ", 1)[1]


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("name,value", [
    ("r0_m", 0.0),
    ("L0_m", -0.3),
    ("theta0_deg", 60.0),
    ("valve_b", 0.9995),  # inside its own range [0, 1), above valve_laminar_ratio
    ("polytropic_index", 0.5),
    ("stop_restitution", 1.5),
    ("dead_volume_m3", -1e-6),
    ("valve_laminar_ratio", 1.0),
    ("fit_x_min_m", 0.08),  # above fit_x_max_m
])
def test_out_of_range_parameters_are_refused_by_fmu_and_scenario_alike(unzipped, version, name, value, capfd):
    why = _python_reason(name, value)
    capfd.readouterr()
    status = _initialise_with(unzipped, version, {name: value})
    log = capfd.readouterr().out
    assert status == 3, log  # fmi2Error / fmi3Error at exit from initialisation
    assert f"invalid parameters: {name} = {value:g}: {why}" in log


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("values,message", [
    ({"friction_negative_level": 2}, "friction_negative_level = 2: must lie in [0, 1]"),
    ({"friction_model": -1}, "friction_model = -1: must lie in [0, 2]"),
    ({"pressure_source": 2}, "pressure_source = 2: must lie in [0, 1]"),
    ({"release_margin_N": 1e-7}, "release_margin_N = 1e-07: must be above stick_margin_N = 1e-07"),
    ({"cs_relative_tolerance": 0.1}, "cs_relative_tolerance = 0.1: must lie in (0, 0.01]"),
    ({"initial_pressure_gauge_Pa": -1e3}, "initial_pressure_gauge_Pa = -1000: must be >= 0"),
    ({"initial_pressure_gauge_Pa": 5e5},
     "initial_pressure_gauge_Pa = 500000: must be at most rated_pressure_gauge_Pa = 450000"),
    ({"initial_contraction_m": 0.12}, "initial_contraction_m = 0.12: must lie between the stops, 0 and 0.1157 m"),
    ({"initial_contraction_m": -1e-3}, "initial_contraction_m = -0.001: must lie between the stops"),
    ({"x_high_m": 0.5}, "x_high_m = 0.5: the upper stop must be below the rest length L0_m = 0.3"),
    ({"x_high_m": 0.05, "initial_contraction_m": 0.06}, "initial_contraction_m = 0.06: must lie between the stops, "
     "0 and 0.0500 m"),
])
def test_invalid_fmu_parameters_fail_initialisation(unzipped, version, values, message, capfd):
    capfd.readouterr()
    status = _initialise_with(unzipped, version, values)
    log = capfd.readouterr().out
    assert status == 3 and message in log, log


def _header_bounds(version):
    """{name: (lower, upper, lower_open, upper_open)} parsed from the generated PAM_VARS[]."""
    num = lambda t: {"HUGE_VAL": math.inf, "-HUGE_VAL": -math.inf}.get(t) or float(t)  # noqa: E731
    rows = re.findall(r'^    \{"([^"]+)", \'[rie]\', \d+, \w+, [^,]+, ([^,]+), ([^,]+), ([01]), ([01])\},$',
                      c_header(version), flags=re.M)
    assert {n for n, *_ in rows} >= {v.name for v in VARIABLES}
    return {n: (num(lo), num(hi), lo_open == "1", hi_open == "1") for n, lo, hi, lo_open, hi_open in rows}


@pytest.mark.parametrize("version", [2, 3])
def test_generated_bounds_are_the_parameter_bounds(fmus, unzipped, version, capfd):
    """The C header carries every Parameter's range, and the compiled check agrees with
    ParameterSet.violations at each finite bound and just beyond it."""
    assert zipfile.ZipFile(fmus[version]).read("sources/pam_variables.h").decode() == c_header(version)
    bounds = _header_bounds(version)
    params = get_parameter_set("shadow_6x300_acra2012")
    for name, p in params.entries.items():
        assert bounds[name] == (p.lower, p.upper, p.lower_open, p.upper_open), name
    for v in VARIABLES:
        if v.choices:
            assert bounds[v.name] == (0, len(v.choices) - 1, False, False)
    assert sum(math.isfinite(b) for n in params for b in bounds[n][:2]) >= 20
    checked = 0
    for name, p in params.entries.items():
        for bound, step in ((p.lower, -1), (p.upper, 1)):
            if not math.isfinite(bound):
                continue
            for value in (bound, bound + step * max(1e-9, 1e-6 * abs(bound))):
                python_ok = not params.with_overrides({name: value}).violations()
                status = _initialise_with(unzipped, version, {name: value})
                log = capfd.readouterr().out
                assert (status == 0) == python_ok, f"{name} = {value!r}: {log}"
                checked += 1
    assert checked >= 40


@pytest.mark.parametrize("version", [2, 3])
def test_calls_out_of_state_machine_order_are_errors(fmus, version, capfd):
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    assert _error_status(lambda: api.step(0.0, 0.1)) == 3  # before initialisation
    assert _error_status(fmu.exitInitializationMode) == 3  # not in initialisation mode
    api.init()
    assert _error_status(lambda: api.set("L0_m", 0.2)) == 3  # a fixed parameter after initialisation
    assert _error_status(lambda: api.set("contraction_m", 0.01)) == 3  # an output
    assert "not allowed in the current state" in capfd.readouterr().out
    fmu.terminate()
    assert _error_status(lambda: api.step(0.0, 0.1)) == 3  # after termination
    fmu.freeInstance()


def _start_fig4(api):
    sc, inputs, starts = _inputs_and_starts("acra2012_fig4")
    for k, v in starts.items():
        if isinstance(v, float):
            api.set(k, v)
    for k, v in inputs(1.0).items():
        api.set(k, v)


@pytest.mark.parametrize("version", [2, 3])
def test_fmu_state_get_set_and_serialise_repeat_a_step(fmus, version):
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    _start_fig4(api)
    api.init()
    api.step(0.0, 0.3)
    get, put = (fmu.getFMUstate, fmu.setFMUstate) if version == 2 else (fmu.getFMUState, fmu.setFMUState)
    ser, deser = (fmu.serializeFMUstate, fmu.deSerializeFMUstate) if version == 2 else \
        (fmu.serializeFMUState, fmu.deserializeFMUState)
    state = get()
    blob = ser(state)
    api.step(0.3, 0.4)
    first = api.get("contraction_m", "velocity_m_s", "p_gauge_Pa")
    assert first[0] > 0.0  # the load moved during the repeated step
    put(state)
    api.step(0.3, 0.4)
    assert api.get("contraction_m", "velocity_m_s", "p_gauge_Pa") == first
    put(deser(blob))
    api.step(0.3, 0.4)
    assert api.get("contraction_m", "velocity_m_s", "p_gauge_Pa") == first
    fmu.terminate()
    # As in the standard's Reference FMUs, a state may be set in any state, Terminated included: it
    # brings back the state machine's state with the values, so the run resumes where it was saved.
    put(state)
    api.step(0.3, 0.4)
    assert api.get("contraction_m", "velocity_m_s", "p_gauge_Pa") == first
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_directional_derivative_matches_python_model(fmus, version):
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    _start_fig4(api)
    api.init()
    api.step(0.0, 0.25)
    mode = api.mode()
    assert mode in (1, -1)  # sliding: the acceleration depends on x and p
    x, v, p, m = api.get("contraction_m", "velocity_m_s", "chamber_pressure_abs_Pa", "air_mass_kg")
    unknown, known = [value_reference("der(velocity_m_s)")], [value_reference("contraction_m")]
    dd = fmu.getDirectionalDerivative(unknown, known, [1.0])[0]
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    model = sc.build_model()
    inputs = model.source.inputs(2.0)
    acc = lambda xx: model.slip_rhs(np.array([xx, v, p, m, 0, 0, 0, 0]), float(mode), inputs, 0.0)[1]  # noqa: E731
    h = 1e-6
    expected = (acc(x + h) - acc(x - h)) / (2 * h)
    assert dd == pytest.approx(expected, rel=1e-4)
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_model_exchange_events_protocol(fmus, version):
    """Drive the ME interface by hand: every event leaves all indicators strictly positive
    (no chattering) and stopping resets the velocity with valuesOfContinuousStatesChanged."""
    fmu = _instance(fmus, version, "me")
    api = _Api(fmu, version)
    _start_fig4(api)
    api.init()

    def update():
        # fmpy returns (update needed, terminate, nominals changed, values changed, time defined, next time)
        r = fmu.newDiscreteStates() if version == 2 else fmu.updateDiscreteStates()
        return r[3], r[0]

    update()
    fmu.enterContinuousTimeMode()
    n = n_states(fmus[version])  # the four of the model, then its work integrals
    x, dx, z = np.zeros(n), np.zeros(n), np.zeros(2)

    def ptr(a):
        return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    get_x = lambda: fmu.getContinuousStates(ptr(x), n)  # noqa: E731
    get_dx = (lambda: fmu.getDerivatives(ptr(dx), n)) if version == 2 else \
        (lambda: fmu.getContinuousStateDerivatives(ptr(dx), n))
    get_z = lambda: fmu.getEventIndicators(ptr(z), 2)  # noqa: E731
    get_x()
    get_z()
    t, h, events, stops = 0.0, 1e-4, 0, 0
    while t < 2.0 and stops == 0:
        get_dx()
        z_old = z.copy()
        x += h * dx
        t += h
        fmu.setTime(t)
        fmu.setContinuousStates(ptr(x), n)
        get_z()
        if np.any((z_old > 0) & (z <= 0)):
            mode_before = api.mode()
            fmu.enterEventMode()
            changed, again = update()
            assert not again
            events += 1
            if mode_before == 1 and api.mode() in (0, -1):
                assert changed  # the velocity was reset
                get_x()
                assert x[1] == 0.0
                stops += 1
            fmu.enterContinuousTimeMode()
            get_x()
            get_z()
            assert np.all(z > 0), "an event left an indicator at or below zero (would chatter)"
    assert events >= 2 and stops == 1  # released from the lower stop, then stopped at the top of the swing
    fmu.terminate()
    fmu.freeInstance()


# ------------------------------------------------------------------ other element choices and inputs

OTHER_CHOICES = {
    "prescribed_lag_constant_friction": """
[model]
friction = "constant"
damping = "linear"
[load]
weight_N = 12.74
external_force = { kind = "step", time_s = 4.0, initial_N = 0.0, final_N = -3.0 }
[pressure]
source = "prescribed"
prescribed = { kind = "lag", time_s = 0.5, initial_gauge_bar = 0.0, final_gauge_bar = 3.0, tau_s = 0.3 }
[simulation]
duration_s = 6.0
""",
    "valve_vent_no_friction": """
[model]
friction = "none"
damping = "paper"
[load]
weight_N = 22.74
[pressure]
source = "valve"
supply_gauge_bar = 3.0
command = { kind = "step", time_s = 3.0, initial = 1.0, final = -1.0 }
[parameters]
stop_restitution = 0.3
[simulation]
duration_s = 5.0
""",
}


@pytest.mark.parametrize("interface", ["cs", "me"])
@pytest.mark.parametrize("case", sorted(OTHER_CHOICES))
def test_other_element_choices_match_python_simulator(fmus, case, interface):
    """Constant friction, linear damping, a prescribed lagged pressure, an external force
    step, venting through the valve and a rebounding stop.
    """
    import tomllib

    sc = pamsim.Scenario.from_dict(tomllib.loads(OTHER_CHOICES[case]), name=case)
    ref = pamsim.simulate(sc)
    tr = run_cs(sc, 2, fmu_path=fmus[2]) if interface == "cs" else run_me(sc, 2, fmu_path=fmus[2])
    d = _diff(tr, ref)
    assert d.max() <= MAX_DIFF_M, f"max contraction difference {d.max() * 1e3:.4f} mm"
    assert d[-1] <= FINAL_DIFF_M, f"final contraction difference {d[-1] * 1e3:.4f} mm"
    # A prescribed pressure is an input, held over each 1 ms co-simulation step at its midpoint
    # value, so the CS output lags by half a step (the lag rises at up to 10 bar/s).
    held = interface == "cs" and sc.spec["pressure"]["source"] == "prescribed"
    assert np.max(np.abs(tr["p_gauge_Pa"] - ref.p_gauge_Pa)) <= (1000.0 if held else 50.0)


@pytest.mark.parametrize("interface", ["cs", "me"])
def test_friction_negative_level_abs_matches_python_simulator(fmus, paper_results, interface):
    """Fig. 6(b) (2 bar, 22.74 N: P - m is negative at the start) with the magnitude of the
    negative friction level; it ends 1.2 mm away from the clamped run, so an FMU that ignored the
    setting would fail."""
    clamped = paper_results["acra2012_fig6b"][1]
    sc = paper_results["acra2012_fig6b"][0].with_changes({"model": {"friction_negative_level": "abs"}})
    assert start_values(sc)["friction_negative_level"] == 1
    ref = pamsim.simulate(sc)
    assert abs(ref.x_m[-1] - clamped.x_m[-1]) > 5 * MAX_DIFF_M
    tr = run_cs(sc, 2, fmu_path=fmus[2]) if interface == "cs" else run_me(sc, 2, fmu_path=fmus[2])
    d = _diff(tr, ref)
    assert d.max() <= MAX_DIFF_M, f"max contraction difference {d.max() * 1e3:.4f} mm"
    assert d[-1] <= FINAL_DIFF_M, f"final contraction difference {d[-1] * 1e3:.4f} mm"


INITIAL_PRESSURE = """
[load]
weight_N = 22.74
[pressure]
source = "valve"
supply_gauge_bar = 3.6
valve_open_time_s = 1.0
initial_gauge_bar = 2.5
[simulation]
duration_s = 3.0
initial_contraction_m = 0.02
"""


def test_initial_pressure_sets_the_initial_chamber_state(unzipped):
    import tomllib

    from fmpy.fmi2 import FMU2Slave

    sc = pamsim.Scenario.from_dict(tomllib.loads(INITIAL_PRESSURE), name="initial_pressure")
    starts = start_values(sc)
    assert starts["initial_pressure_gauge_Pa"] == pytest.approx(2.5e5)
    fmu = FMU2Slave(guid=token(2), unzipDirectory=unzipped[2], modelIdentifier="pamsim_muscle", instanceName="p0")
    fmu.instantiate()
    api = _Api(fmu, 2)
    for k, v in starts.items():
        if isinstance(v, float):
            api.set(k, v)
    api.init()
    p, m, x = api.get("chamber_pressure_abs_Pa", "air_mass_kg", "contraction_m")
    fmu.terminate()
    fmu.freeInstance()
    model = sc.build_model()
    expected = model.source.initial_state(0.02, 2.5e5)  # ValveChamberSource: [p_abs, air mass]
    assert (x, p) == (0.02, pytest.approx(expected[0], rel=1e-12))
    assert m == pytest.approx(expected[1], rel=1e-12)


@pytest.mark.parametrize("interface", ["cs", "me"])
def test_initial_pressure_matches_python_simulator(fmus, interface):
    import tomllib

    sc = pamsim.Scenario.from_dict(tomllib.loads(INITIAL_PRESSURE), name="initial_pressure")
    ref = pamsim.simulate(sc)
    assert abs(ref.p_gauge_Pa[0] - 2.5e5) <= 1.0
    tr = run_cs(sc, 2, fmu_path=fmus[2]) if interface == "cs" else run_me(sc, 2, fmu_path=fmus[2])
    assert abs(tr["p_gauge_Pa"][0] - 2.5e5) <= 1.0
    d = _diff(tr, ref)
    assert d.max() <= MAX_DIFF_M, f"max contraction difference {d.max() * 1e3:.4f} mm"
    assert d[-1] <= FINAL_DIFF_M, f"final contraction difference {d[-1] * 1e3:.4f} mm"
    assert np.max(np.abs(tr["p_gauge_Pa"] - ref.p_gauge_Pa)) <= 50.0


@pytest.mark.parametrize("section,key", [("model", "friction_negative_level"), ("pressure", "initial_gauge_bar"),
                                         ("simulation", "initial_contraction_m"), ("", "description")])
def test_runner_refuses_scenario_settings_the_fmu_cannot_represent(fmus, monkeypatch, section, key):
    """A scenario key the runner does not map to the FMU is refused, not silently dropped: with
    the key taken out of the runner's list, a scenario that sets it cannot run."""
    import tomllib

    import pamsim.fmu.runner as runner

    spec = tomllib.loads(INITIAL_PRESSURE)
    spec["model"] = {"friction_negative_level": "abs"}
    spec["description"] = "every key the test takes out"
    sc = pamsim.Scenario.from_dict(spec, name="initial_pressure")
    start_values(sc)
    monkeypatch.setitem(runner.REPRESENTED, section, runner.REPRESENTED[section] - {key})
    full = f"{section}.{key}" if section else key
    with pytest.raises(pamsim.errors.InputError, match=re.escape(f"cannot represent scenario key {full!r}")):
        start_values(sc)
    for run in (run_cs, run_me):
        with pytest.raises(pamsim.errors.InputError, match="cannot represent"):
            run(sc, 2, fmu_path=fmus[2])


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("known, unknown", [
    ("initial_contraction_m", "contraction_m"),   # the state follows the parameter: 1
    ("r0_m", "air_mass_kg"),                      # the chamber's volume follows the braid's geometry
    ("theta0_deg", "air_mass_kg"),
    ("initial_contraction_m", "air_mass_kg"),
])
def test_directional_derivatives_in_initialisation_follow_the_parameters(fmus, version, known, unknown):
    """In initialisation mode a parameter's seed moves the states, the geometry and the stops derived
    from it, as the end of initialisation will: against the difference of two instances initialised
    with the parameter either side."""
    h = {"initial_contraction_m": 1e-5, "r0_m": 1e-6, "theta0_deg": 1e-3}[known]

    def initialised(delta):
        fmu = _instance(fmus, version)
        api = _Api(fmu, version)
        _start_fig4(api)
        base = _inputs_and_starts("acra2012_fig4")[2][known]
        if known == "initial_contraction_m" and base == 0.0:
            base = 0.02  # inside the travel, where the state is free to follow
        api.set(known, base + delta)
        if version == 2:
            fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        return fmu, api

    fmu, api = initialised(0.0)
    dd_fmu = fmu.getDirectionalDerivative([value_reference(unknown)], [value_reference(known)], [1.0])[0]
    fmu.freeInstance()
    values = []
    for delta in (h, -h):
        other, other_api = initialised(delta)
        other.exitInitializationMode()
        values.append(other_api.get(unknown)[0])
        other.terminate()
        other.freeInstance()
    expected = (values[0] - values[1]) / (2 * h)
    assert expected != 0.0
    assert dd_fmu == pytest.approx(expected, rel=1e-4)
