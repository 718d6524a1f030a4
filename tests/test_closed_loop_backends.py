"""The closed-loop scenario on every backend: the controller is a component of the run's assembly, so the
native backend runs it on the generic C engine and the FMU backends through the FMU generated from that
assembly.  Each must give the python backend's response: the same step metrics, final position and
specification check."""

from __future__ import annotations

import json

import numpy as np
import pytest

import pamsim
from pamsim.errors import InputError

from conftest import SCENARIOS, run_cli

CLOSED_LOOP = SCENARIOS / "closed_loop_position.toml"
SAMPLE_S = 1e-3
"""The scenario's output interval: the metrics' times are sample times, so one sample is their resolution."""


@pytest.fixture(scope="module")
def python_run():
    return pamsim.run(CLOSED_LOOP)


@pytest.fixture(scope="module")
def native_run():
    return pamsim.run(CLOSED_LOOP, backend="native")


def assert_same_response(run, reference, final_um: float) -> None:
    """Step metrics within one sample (times), 0.1 % (overshoot) and ``final_um`` (steady-state error,
    final position) of ``reference``'s; the specification met on both."""
    m, ref = run.closed_loop.metrics, reference.closed_loop.metrics
    for key in ("rise_time_s", "settling_time_s"):
        assert abs(m[key] - ref[key]) <= SAMPLE_S + 1e-12, key
    assert abs(m["overshoot_percent"] - ref["overshoot_percent"]) <= 0.1
    assert abs(m["steady_state_error_mm"] - ref["steady_state_error_mm"]) * 1e3 <= final_um
    assert abs(run.result.x_m[-1] - reference.result.x_m[-1]) * 1e6 <= final_um
    assert run.failures == [] and reference.failures == []
    assert run.summary()["controller"]["meets_spec"] is True


def test_native_runs_the_closed_loop_as_python_does(native_run, python_run):
    assert native_run.backend == "native" and native_run.result.stats["method"].startswith("native")
    assert_same_response(native_run, python_run, final_um=1.0)
    # The controller ran in C: its states and the valve command it gave are the python run's.
    for column in ("valve_command", "z_error_integral_m_s", "reference_m", "feedforward_gauge_Pa"):
        assert column in native_run.result.signals
    u_native, u_python = native_run.result.signals["valve_command"], python_run.result.signals["valve_command"]
    assert np.max(u_native) == 1.0 and np.mean(np.abs(u_native - u_python)) < 1e-3
    assert [e.kind for e in native_run.result.transitions] == [e.kind for e in python_run.result.transitions]


def test_native_refuses_a_law_written_for_floats_alone_by_name(monkeypatch):
    """A friction law with no generated C (one called on floats) is refused by name, not run without it."""
    from pamsim.native import backend

    monkeypatch.setattr(backend, "in_c", lambda assembly, name: name != "friction")
    with pytest.raises(InputError, match="component 'friction' is written for floats alone") as err:
        pamsim.run(CLOSED_LOOP, backend="native")
    assert "\n" not in str(err.value)


def test_native_closed_loop_writes_what_python_writes(tmp_path, cli):
    outputs = {}
    for backend in ("python", "native"):
        proc = cli("run", CLOSED_LOOP, "--backend", backend, "-o", tmp_path / backend, "--no-progress")
        assert proc.returncode == 0, proc.stderr
        outputs[backend] = sorted(p.name for p in (tmp_path / backend).iterdir())
        header = (tmp_path / backend / "closed_loop_position.csv").read_text().splitlines()[0]
        outputs[backend + " columns"] = header
        summary = json.loads((tmp_path / backend / "closed_loop_position.json").read_text())
        outputs[backend + " keys"] = sorted(summary)
        assert summary["backend"] == backend and summary["controller"]["meets_spec"] is True
    assert outputs["native"] == outputs["python"] == ["closed_loop_position.csv", "closed_loop_position.json",
                                                      "closed_loop_position.png"]
    assert outputs["native columns"] == outputs["python columns"]
    assert outputs["native keys"] == outputs["python keys"]


# ---------------------------------------------------------------- the FMU of the assembly, controller included
@pytest.fixture(scope="module")
def fmu_runs():
    pytest.importorskip("fmpy")
    return {backend: pamsim.run(CLOSED_LOOP, backend=backend) for backend in ("fmu-cs", "fmu-me")}


@pytest.mark.parametrize("backend", ["fmu-cs", "fmu-me"])
def test_fmu_backends_run_the_closed_loop_as_python_does(fmu_runs, python_run, backend):
    run = fmu_runs[backend]
    assert run.backend == backend and run.result.stats["method"] == backend
    assert_same_response(run, python_run, final_um=1.0)
    assert np.max(run.result.signals["valve_command"]) == 1.0  # the controller in the FMU saturated the valve
    assert run.summary()["controller"]["events"] == python_run.summary()["controller"]["events"]


@pytest.fixture(scope="module")
def built_fmu(tmp_path_factory):
    """The closed-loop scenario's FMU (FMI 3.0), built as a user builds it."""
    pytest.importorskip("fmpy")
    path = tmp_path_factory.mktemp("closed_loop_fmu") / "closed_loop.fmu"
    proc = run_cli("fmu", "build", "--scenario", CLOSED_LOOP, "--fmi", "3", "-o", path)
    assert proc.returncode == 0, proc.stderr
    assert "with its controller" in proc.stdout
    return path


@pytest.mark.parametrize("kind", ["CoSimulation", "ModelExchange"])
def test_plain_fmpy_runs_the_closed_loop_fmu_as_python_does(built_fmu, python_run, kind):
    """No start values, no inputs: the FMU contains the controller, its reference and feedforward follow
    the scenario's steps, and its DefaultExperiment is the scenario's run."""
    import fmpy

    from pamsim.control.closed_loop import step_metrics

    md = fmpy.read_model_description(str(built_fmu))
    inputs = {v.name: float(v.start) for v in md.modelVariables if v.causality == "input"}
    assert inputs["reference_m"] == pytest.approx(0.020)
    assert "controller.Kx_per_m" in {v.name for v in md.modelVariables}
    r = fmpy.simulate_fmu(str(built_fmu), fmi_type=kind, output_interval=SAMPLE_S, output=["load.x_m", "load.mode"])
    last = np.r_[r["time"][1:] != r["time"][:-1], True]  # after the event where fmpy records both sides
    t, x = r["time"][last], r["load.x_m"][last]
    assert t[-1] == pytest.approx(3.0)
    config = python_run.closed_loop.config
    m = step_metrics(t, x, config.step_time_s, 0.020, config.target_contraction_m, config.spec["settling_band_mm"] * 1e-3)
    ref = python_run.closed_loop.metrics
    for key in ("rise_time_s", "settling_time_s"):
        assert abs(m[key] - ref[key]) <= SAMPLE_S + 1e-12, key
    assert m["overshoot_percent"] == pytest.approx(ref["overshoot_percent"], abs=0.1)
    assert abs(x[-1] - python_run.result.x_m[-1]) < 1e-6


def test_the_one_muscle_fmu_still_refuses_a_controller():
    from pamsim.fmu.assembly_fmu import assembly_spec
    from pamsim.fmu.preset import for_scenario

    scenario = pamsim.load_scenario(CLOSED_LOOP)
    for build in (for_scenario, assembly_spec):
        with pytest.raises(InputError, match="pamsim fmu build --scenario"):
            build(scenario)
