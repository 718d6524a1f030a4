"""A serialized FMU state holds values only, with a format version, the build's token and a checksum:
loaded in another process (a table FMU's state crashed there when it was a raw copy of the instance,
pointers included) it continues the run exactly as the process that saved it does, and a changed byte,
a truncated state or a state of another build is refused.  An absurd step bound is refused up front."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import SCENARIOS

fmpy = pytest.importorskip("fmpy", reason="fmpy is in the test extra; the FMU checks need it")
from fmpy.fmi2 import FMU2Slave  # noqa: E402

OUTPUTS = ("contraction_m", "velocity_m_s", "p_gauge_Pa", "air_mass_kg")

CONTINUE = """
import sys
import fmpy
from fmpy.fmi2 import FMU2Slave
path, blob_path = sys.argv[1], sys.argv[2]
md = fmpy.read_model_description(path)
vr = {v.name: v.valueReference for v in md.modelVariables}
fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="other_process")
fmu.instantiate()
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.exitInitializationMode()
fmu.setFMUstate(fmu.deSerializeFMUstate(open(blob_path, "rb").read()))
now = fmu.getReal([vr[n] for n in %r])
fmu.doStep(1.3, 0.2)
later = fmu.getReal([vr[n] for n in %r])
print(repr((now, later)))
""" % (OUTPUTS, OUTPUTS)


@pytest.fixture(scope="module")
def table_fmu(tmp_path_factory):
    """An FMU of Chou and Hannaford's model (a force table baked in), its scenario's start values."""
    path = tmp_path_factory.mktemp("fmu") / "chou_hannaford.fmu"
    proc = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario",
                           str(SCENARIOS / "acra2012_fig4_chou_hannaford.toml"), "-o", str(path)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return path


def _started(path, name="saver"):
    md = fmpy.read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(path)),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu, vr


def test_a_state_saved_in_one_process_continues_in_another(table_fmu, tmp_path):
    fmu, vr = _started(table_fmu)
    fmu.doStep(0.0, 1.3)  # the valve opened at 1 s: the load is moving
    blob = fmu.serializeFMUstate(fmu.getFMUstate())
    (tmp_path / "state.bin").write_bytes(bytes(blob))
    now = fmu.getReal([vr[n] for n in OUTPUTS])
    fmu.doStep(1.3, 0.2)
    later = fmu.getReal([vr[n] for n in OUTPUTS])
    fmu.terminate()
    fmu.freeInstance()
    assert now[1] != 0.0  # moving, so the continuation is a real test
    proc = subprocess.run([sys.executable, "-c", CONTINUE, str(table_fmu), str(tmp_path / "state.bin")],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    there_now, there_later = eval(proc.stdout.strip())
    assert list(there_now) == list(now) and list(there_later) == list(later)


@pytest.mark.parametrize("damage, why", [
    (lambda b: b[:100] + bytes([b[100] ^ 0x01]) + b[101:], "checksum"),  # a bit of a value
    (lambda b: b[:-1], "wrong size"),
    (lambda b: b"XXXXXXXX" + b[8:], "format version"),
    (lambda b: b[:12] + bytes([b[12] ^ 0xFF]) + b[13:], "another build"),  # the token
])
def test_a_damaged_state_is_refused(table_fmu, damage, why, capfd):
    fmu, _ = _started(table_fmu, "loader")
    fmu.doStep(0.0, 0.5)
    blob = bytes(fmu.serializeFMUstate(fmu.getFMUstate()))
    assert fmu.deSerializeFMUstate(blob) is not None  # the undamaged one loads
    with pytest.raises(Exception):
        fmu.deSerializeFMUstate(damage(blob))
    fmu.terminate()
    fmu.freeInstance()
    assert why in capfd.readouterr().out


def test_an_absurd_step_bound_is_refused_at_initialisation(table_fmu, capfd):
    """cs_max_step_s = 1e-12 took 12.6 s to fail a step; it is refused when initialisation ends, as a
    scenario's solver.max_step_s below 1 us is."""
    import time

    from pamsim.simulator import MIN_MAX_STEP_S

    md = fmpy.read_model_description(str(table_fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(table_fmu)),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="steps")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    t = time.perf_counter()
    try:
        fmu.setReal([vr["cs_max_step_s"]], [1e-12])
        fmu.exitInitializationMode()
        refused = False
    except Exception:
        refused = True
    assert refused and time.perf_counter() - t < 1.0
    assert f"cs_max_step_s = 1e-12: must be >= {MIN_MAX_STEP_S:g}" in capfd.readouterr().out
    fmu.freeInstance()


def test_a_state_carries_the_engines_stiff_switch(tmp_path):
    """Thermal Figure 4's assembly FMU, stepped in co-simulation: by 2 s the load is held and the cooling gas
    has switched the engine to Rodas4 (docs/scaling.md, Stiff held phases). A state saved there and loaded
    into another instance goes on with Rodas4 as the saver does, bit for bit; without the switch in the
    state the loader tested afresh with Dormand-Prince (and each communication step did, so the FMU never
    switched at 1 ms steps)."""
    scenario = tmp_path / "thermal_fig4.toml"
    scenario.write_text((SCENARIOS / "acra2012_fig4.toml").read_text() + '\n[chamber]\nlaw = "thermal"\n')
    path = tmp_path / "thermal.fmu"
    proc = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--generated", "--scenario", str(scenario),
                           "-o", str(path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    names = ("load.x_m", "chamber.p_abs_Pa", "chamber.gas_temperature_K")
    saver, vr = _started(path)
    saver.doStep(0.0, 2.0)
    blob = bytes(saver.serializeFMUstate(saver.getFMUstate()))
    saver.doStep(2.0, 6.0)
    want = saver.getReal([vr[n] for n in names])
    loader, _ = _started(path, "loader")
    loader.setFMUstate(loader.deSerializeFMUstate(blob))
    loader.doStep(2.0, 6.0)
    got = loader.getReal([vr[n] for n in names])
    for fmu in (saver, loader):
        fmu.terminate()
        fmu.freeInstance()
    assert list(got) == list(want)
