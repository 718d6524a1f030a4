"""A muscle alone driven by its length (``[motion]``): its force against the muscle's elements called on floats and
the standalone Maxwell-slip operator driven along the same contraction (a second implementation), the
operator's properties in the run (rate independence, return-point memory, loop area = dissipated energy), the
backends against each other, the CSV as a loop ``pamsim fit hysteresis`` reads, and the refusals."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.hysteresis.loop_data import read_loop
from pamsim.hysteresis.maxwell_slip import MaxwellSlip
from pamsim.muscle_alone import simulate_length_drive
from pamsim.muscle_alone.run import LengthDrive
from pamsim.scenario import Scenario

SHIPPED = str(Path(__file__).resolve().parents[1] / "scenarios" / "hysteresis_force_cycles.toml")
DELTAS, SHARES, LEVEL_N, P_PA = (2e-4, 1e-3, 4e-3), (0.3, 0.3, 0.4), 2.5, 3e5


def scenario(motion: dict, friction: str = "constant", damping: str = "none", sample_rate_Hz: float = 100.0,
             duration_s: float | None = None, **extra) -> Scenario:
    """The shipped muscle and elements at 3 bar, along ``motion``."""
    base = pamsim.load_scenario(SHIPPED)
    spec = {k: v for k, v in base.spec.items() if k not in ("motion", "simulation", "model")}
    spec["model"] = {"parameter_set": "shadow_6x300_acra2012", "friction": friction, "damping": damping}
    spec["motion"] = motion
    last = motion["times_s"][-1] if "times_s" in motion else motion["period_s"] * (len(motion["amplitudes_m"]) - 0.5) / 2
    spec["simulation"] = {"duration_s": duration_s or last, "sample_rate_Hz": sample_rate_Hz}
    spec.update(extra)
    return Scenario.from_dict(spec, name="alone")


def operator(x_m: np.ndarray, level_N: float = LEVEL_N) -> MaxwellSlip:
    """The standalone operator of the scenario's elements: slip force ``w_i F_c``, stiffness ``w_i F_c / delta_i``."""
    F = np.array(SHARES) * level_N
    return MaxwellSlip(F / np.array(DELTAS), F)


@pytest.mark.parametrize("damping", ["linear", "none"])
def test_the_force_is_static_plus_damping_plus_the_standalone_operator(damping):
    """Along the shipped triangle (turns on the sample grid, so the samples hold every vertex and the operator's
    exact update between them is the path's): F = F_static(x, p) - F_damping(v) - MaxwellSlip(x), the static
    force and damping called on floats, to 1e-6 N; each element's deflection is the operator's to 1e-12 m."""
    sc = pamsim.load_scenario(SHIPPED).with_changes({"model": {"damping": damping}})
    r = simulate_length_drive(sc, "python")
    model = sc.build_model()
    x, v = r.contraction_m, r.velocity_m_s
    assert np.max(np.abs(x - r.motion.contraction_m(r.t_s))) < 1e-15
    run = operator(x).run(x)
    static = np.array([float(model.static_force.force_N(a, P_PA)) for a in x])
    damp = np.array([float(model.damping.force_N(b)) for b in v])
    if damping == "linear":  # the damping is there to be checked: c |v| of some 10 mN at 2.5 mm/s
        assert np.max(np.abs(damp)) > 1e-3
    assert np.max(np.abs(r.force_N - (static - damp - run.force_N))) < 1e-6
    for i in range(3):
        assert np.max(np.abs(r.signals[f"hysteresis.z{i + 1}_m"] - run.deflection_m[:len(x), i])) < 1e-12
    assert len(r.events) == 17 and {k for _, k in r.events} == {"hysteresis.slip1", "hysteresis.slip2",
                                                                 "hysteresis.slip3"}


def test_with_a_level_that_follows_the_force_the_deflections_are_still_the_stop_operator():
    """With the paper's load-dependent level the stiffness moves with the force, but the slip displacement is a
    constant: each deflection is the stop operator of threshold delta_i (any stiffness) to 1e-12 m, and the
    elements' force ``-sum w_i F_c(x, p, F_static / g) z_i / delta_i``, the level called on floats, to 1e-9 N."""
    sc = pamsim.load_scenario(SHIPPED).with_changes({"model": {"friction": "load_dependent"}, "pressure": {
        "source": "prescribed", "prescribed": {"kind": "constant", "value_gauge_bar": 2.0}}})
    r = simulate_length_drive(sc, "python")
    x, p = r.contraction_m, 2e5
    model, g = sc.build_model(), sc.parameters["g_m_s2"]
    level_law = pamsim.scenario.FRICTION_MODELS["load_dependent"](sc.parameters, sc.spec["model"])
    z = MaxwellSlip(np.ones(3), np.array(DELTAS)).run(x).deflection_m[:len(x)]
    static = np.array([float(model.static_force.force_N(a, p)) for a in x])
    level = np.array([float(level_law.level_N(a, p, max(f, 0.0) / g)) for a, f in zip(x, static)])
    assert np.ptp(level) > 1.0  # at 2 bar the level runs from 0 (20 mm) to 2.1 N (40 mm)
    want = -(level[:, None] * np.array(SHARES) / np.array(DELTAS) * z).sum(axis=1)
    for i in range(3):
        assert np.max(np.abs(r.signals[f"hysteresis.z{i + 1}_m"] - z[:, i])) < 1e-12
    assert np.max(np.abs(r.signals["hysteresis.F_N"] - want)) < 1e-9


def test_rate_independence_without_damping():
    """Without damping, the same turns travelled 100 times faster (sampled 100 times as often, so the samples
    are the same points of the path) give the same force-contraction loop, to 1e-9 N."""
    amplitudes = [0.01, 0.01, 0.006, 0.004, 0.008]
    slow = simulate_length_drive(scenario({"kind": "triangle", "center_m": 0.03, "amplitudes_m": amplitudes,
                                           "period_s": 8.0}, sample_rate_Hz=50.0), "python")
    fast = simulate_length_drive(scenario({"kind": "triangle", "center_m": 0.03, "amplitudes_m": amplitudes,
                                           "period_s": 0.08}, sample_rate_Hz=5000.0), "python")
    assert slow.t_s.size == fast.t_s.size
    assert np.max(np.abs(slow.contraction_m - fast.contraction_m)) < 1e-12
    assert np.max(np.abs(slow.force_N - fast.force_N)) < 1e-9
    assert np.ptp(slow.force_N) > 10.0


def test_return_point_memory():
    """Out to 38 mm, down to 22 mm, a minor loop 34 -> 26 -> 34 mm, then down to 22 mm: back at 34 mm the
    elements' states and the force are those left there (1e-9 N), and the descent after it goes on as if the
    minor loop had not happened: at 22 mm the force is the first descent's (1e-9 N)."""
    t = [0.0, 2.0, 6.0, 7.0, 8.0, 9.0, 10.0, 12.0, 14.0, 16.0]
    x = [0.030, 0.038, 0.022, 0.026, 0.034, 0.026, 0.034, 0.022, 0.038, 0.038]
    r = simulate_length_drive(scenario({"kind": "linear", "times_s": t, "contraction_m": x}), "python")

    def at(time_s, key="motion.F_N"):
        return float(r.signals[key][np.argmin(np.abs(r.t_s - time_s))])

    assert at(8.0) == pytest.approx(at(10.0), abs=1e-9)
    for i in (1, 2, 3):
        assert at(8.0, f"hysteresis.z{i}_m") == pytest.approx(at(10.0, f"hysteresis.z{i}_m"), abs=1e-13)
    assert at(12.0) == pytest.approx(at(6.0), abs=1e-9)
    assert abs(at(9.0) - at(7.0)) > 0.1  # the minor loop is a loop


@pytest.mark.parametrize("backend, rel", [("python", 1e-4), ("native", 1e-9)])
def test_the_loop_area_is_the_dissipated_energy(backend, rel):
    """Cycles of amplitude A = 8 mm about 30 mm without damping: over the second full cycle the elements
    dissipate the area of their parallelograms, sum 4 F_i (A - delta_i) (by hand), which is the work done on
    the muscle (-delta W_muscle_out, the static force being conservative), to ``rel`` (the work integrals are
    quadratures: LSODA at rtol 1e-6 leaves 2.7e-5 of them, the native engine's Gauss rule on its dense output
    1e-14); and the loop's area, -sum of trapezoids of F over x at 1 ms samples, exact for a force linear in x
    between events, to 1e-9."""
    A, period = 0.008, 4.0
    r = simulate_length_drive(scenario({"kind": "triangle", "center_m": 0.03, "amplitudes_m": [A] * 5,
                                        "period_s": period}, sample_rate_Hz=1000.0), backend)
    hand = sum(4 * w * LEVEL_N * (A - d) for w, d in zip(SHARES, DELTAS))
    i0, i1 = (int(np.argmin(np.abs(r.t_s - (period / 4 + k * period)))) for k in (1, 2))
    one = slice(i0, i1 + 1)
    W = r.signals["motion.W_muscle_out_J"][one]
    E = sum(r.signals[f"hysteresis.E_element{i}_J"][one] for i in (1, 2, 3))
    assert E[-1] - E[0] == pytest.approx(hand, rel=rel)
    assert -(W[-1] - W[0]) == pytest.approx(hand, rel=rel)
    area = -np.trapezoid(r.force_N[one], r.contraction_m[one])
    assert area == pytest.approx(hand, rel=1e-9)


@pytest.mark.parametrize("backend, tol_N, tol_m", [("native", 1e-6, 1e-9), ("fmu-cs", 1e-4, 1e-7),
                                                    ("fmu-me", 2e-3, 1e-6)])
def test_the_backends_agree(backend, tol_N, tol_m):
    """The shipped scenario on each backend against python: the force (N) and each deflection (m) at every
    sample, and the events (python and the native engine report each with its time; the FMUs' are counted
    from the slipping outputs between samples).

    Python's and the engine's event times agree to 1e-9 s where the deflection reaches its slip displacement
    on a straight leg, where both integrate it exactly.  At 18 s the largest element's deflection reaches
    its slip displacement exactly at a turn and touches it there without crossing (no event): the step onto
    that turn meets the element's switch at its end, and the state leaves it with an error within the
    integrator's tolerance, rtol * delta_3; that element's next slip is then timed to rtol * delta_3 / |v|."""
    sc = pamsim.load_scenario(SHIPPED)
    ref, r = simulate_length_drive(sc, "python"), simulate_length_drive(sc, backend)
    assert r.t_s.size == ref.t_s.size and np.max(np.abs(r.t_s - ref.t_s)) < 1e-12
    assert np.max(np.abs(r.force_N - ref.force_N)) < tol_N
    for i in (1, 2, 3):
        assert np.max(np.abs(r.signals[f"hysteresis.z{i}_m"] - ref.signals[f"hysteresis.z{i}_m"])) < tol_m
    assert len(r.events) == len(ref.events)
    if backend == "native":
        assert [k for _, k in r.events] == [k for _, k in ref.events]
        speed = float(np.min(np.abs(ref.velocity_m_s[ref.velocity_m_s != 0.0])))
        after_touch = np.array([t > 18.0 and k.endswith("slip3") for t, k in ref.events])
        gap = np.array([abs(a - b) for (a, _), (b, _) in zip(r.events, ref.events)])
        assert np.max(gap[~after_touch]) < 1e-9
        assert np.max(gap[after_touch]) < sc.solver.rtol * DELTAS[2] / speed


def test_pamsim_run_writes_a_loop_the_fit_reads(tmp_path):
    """``pamsim run`` writes NAME.csv, NAME.json and the figure; the CSV's first columns are the loop
    ``pamsim fit hysteresis`` reads (time, gauge pressure, contraction, force), equal to the run's."""
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", SHIPPED, "-o", str(tmp_path), "--no-progress"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    name = "hysteresis_force_cycles"
    assert {p.name for p in tmp_path.iterdir()} == {f"{name}.csv", f"{name}.json", f"{name}.png"}
    loop = read_loop(tmp_path / f"{name}.csv")
    r = simulate_length_drive(pamsim.load_scenario(SHIPPED), "python")
    assert np.allclose(loop.x_m, r.contraction_m, rtol=1e-9, atol=1e-12)
    assert np.allclose(loop.force_N, r.force_N, rtol=1e-9) and np.allclose(loop.p_gauge_Pa, P_PA, rtol=1e-9)
    summary = json.loads((tmp_path / f"{name}.json").read_text())
    assert summary["motion"] == "triangle" and len(summary["events"]) == 17


BAD = [
    ("motion.contraction_m", {"motion": {"kind": "linear", "times_s": [0.0, 1.0], "contraction_m": [0.03, -0.01]}}),
    ("motion.amplitudes_m", {"motion": {"kind": "triangle", "center_m": 0.03, "amplitudes_m": [0.01, 0.2],
                                        "period_s": 1.0}}),
    ("motion.amplitudes_m[1]", {"motion": {"kind": "triangle", "center_m": 0.03, "amplitudes_m": [0.01, -0.005],
                                           "period_s": 1.0}}),
    ("motion.times_s", {"motion": {"kind": "linear", "times_s": [0.0, 2.0, 2.0], "contraction_m": [0.03, 0.04, 0.02]}}),
    ("motion.times_s", {"motion": {"kind": "linear", "times_s": [0.0, 2.0, 1.0], "contraction_m": [0.03, 0.04, 0.02]}}),
    ("motion.period_s", {"motion": {"kind": "sine", "center_m": 0.03, "amplitudes_m": [0.01], "period_s": 0.0}}),
    ("motion.points_per_leg", {"motion": {"kind": "sine", "center_m": 0.03, "amplitudes_m": [0.01], "period_s": 1.0,
                                          "points_per_leg": 0}}),
    ("motion.kind", {"motion": {"kind": "square", "center_m": 0.03}}),
    ("[load]", {"load": {"weight_N": 10.0}}),
    ("simulation.initial_contraction_m", {"simulation": {"duration_s": 2.0, "initial_contraction_m": 0.01}}),
]


def _value(v) -> str:
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    return json.dumps(v)


def toml_text(spec: dict) -> str:
    """``spec`` (top-level scalars, then tables of scalars, lists and inline tables) as TOML."""
    lines = [f"{k} = {_value(v)}" for k, v in spec.items() if not isinstance(v, dict)]
    for name, table in spec.items():
        if isinstance(table, dict):
            lines += [f"[{name}]", *(f"{k} = {_value(v)}" for k, v in table.items())]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("key, change", BAD, ids=[f"{k}-{i}" for i, (k, _) in enumerate(BAD)])
def test_bad_motion_tables_are_refused_naming_the_key(tmp_path, key, change):
    """One line naming the key, exit code 2, nothing written.  ``[load]`` with ``[motion]`` is refused: the length
    is prescribed, so a weight or an external force would be a load the run ignores."""
    spec = dict(pamsim.load_scenario(SHIPPED).spec)
    spec = {k: v for k, v in spec.items() if k != "load"}
    spec.update(change)
    src = tmp_path / "bad.toml"
    src.write_text(toml_text(spec))
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(src), "-o", str(out), "--no-progress"],
                          capture_output=True, text=True)
    assert done.returncode == 2, done.stderr
    assert key in done.stderr and len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert not out.exists()


def test_a_sine_is_its_knots_and_the_velocity_their_slope():
    """A sine's knots lie on the half cosines through the turns (by hand), the run's contraction passes through
    them, and its velocity is the chord's slope on each leg."""
    sc = scenario({"kind": "sine", "center_m": 0.03, "amplitudes_m": [0.01, 0.01], "period_s": 2.0,
                   "points_per_leg": 8}, sample_rate_Hz=1600.0)  # every knot on the sample grid
    r = simulate_length_drive(sc, "python")
    m = r.motion
    assert m.t_s.size == 17 and m.x_m[8] == pytest.approx(0.04) and m.x_m[16] == pytest.approx(0.02)
    assert m.x_m[4] == pytest.approx(0.03 + 0.01 * np.sin(np.pi / 4))
    assert m.x_m[12] == pytest.approx(0.04 - 0.02 * 0.5 * (1 - np.cos(np.pi / 2)))
    knots = np.searchsorted(r.t_s, m.t_s - 1e-9)
    assert np.max(np.abs(r.contraction_m[knots] - m.x_m)) < 1e-12
    inside = (r.t_s > m.t_s[0]) & (r.t_s < m.t_s[-1]) & ~np.isin(np.round(r.t_s, 9), np.round(m.t_s, 9))
    leg = np.searchsorted(m.t_s, r.t_s[inside]) - 1
    assert np.allclose(r.velocity_m_s[inside], m.velocity_m_s[leg], rtol=1e-12)


def test_the_fit_recovers_the_elements_from_the_written_loop(tmp_path):
    """``pamsim fit hysteresis`` on the CSV ``pamsim run`` writes for the shipped scenario: the BIC picks the three
    elements, each stiffness ``w_i F_c / delta_i`` and slip force ``w_i F_c`` (F_c = 2.5 N) within 5 %, and the
    linear static part's slope within 5 % of the static force's chord over 20 to 40 mm at 3 bar (its curvature
    and the damping are what the fit's linear part misses)."""
    run = subprocess.run([sys.executable, "-m", "pamsim", "run", SHIPPED, "-o", str(tmp_path), "--no-plot",
                          "--no-progress"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    fit = subprocess.run([sys.executable, "-m", "pamsim", "fit", "hysteresis", str(tmp_path / "hysteresis_force_cycles.csv"),
                          "-o", str(tmp_path / "fit"), "--model", "maxwell_slip"], capture_output=True, text=True)
    assert fit.returncode == 0, fit.stderr
    got = json.loads((tmp_path / "fit" / "fit.json").read_text())["fit"]
    assert got["label"] == "maxwell_slip N=3"
    values = {k: v["value"] for k, v in got["parameters"].items()}
    for i, (w, d) in enumerate(zip(SHARES, DELTAS), start=1):
        assert values[f"k{i}_N_per_m"] == pytest.approx(w * LEVEL_N / d, rel=0.05)
        assert values[f"F{i}_N"] == pytest.approx(w * LEVEL_N, rel=0.05)
    static = pamsim.load_scenario(SHIPPED).build_model().static_force
    chord = (float(static.force_N(0.04, P_PA)) - float(static.force_N(0.02, P_PA))) / 0.02
    assert values["k0_N_per_m"] == pytest.approx(chord, rel=0.05)


def test_a_csv_above_the_limit_is_refused_before_the_run(tmp_path):
    """``--max-csv-MB`` holds for a muscle driven by its length too: 2401 samples of 29 columns are about 1.3 MB
    at most, refused at 1 MB naming the sample rate, exit code 2, nothing written."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", SHIPPED, "-o", str(out), "--max-csv-MB", "1"],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "simulation.sample_rate_Hz" in done.stderr and not out.exists()


@pytest.mark.parametrize("command", [["linearize", SHIPPED], ["fmu", "build", "--scenario", SHIPPED, "-o", "x.fmu"]])
def test_the_rigs_tools_refuse_a_length_driven_scenario(tmp_path, command):
    """A scenario with ``[motion]`` has no load: the tools of the hanging-load rig refuse it naming ``[motion]``
    with exit code 2 (the muscle-only FMU, ``--muscle-only``, takes it), and so does ``pamsim.simulate``."""
    done = subprocess.run([sys.executable, "-m", "pamsim", *command], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 2 and "[motion]" in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(pamsim.errors.InputError, match=r"\[motion\]"):
        pamsim.simulate(SHIPPED)


def _model_exchange(sc: Scenario):
    """The muscle-only FMU of ``sc`` (FMI 2) in model exchange, initialised at 0 s and in continuous time after
    its first event; its value references by name; the time of its next event."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Model

    from pamsim.fmu.build import build_spec, temp_fmu
    from pamsim.fmu.muscle_only import muscle_only_spec
    from pamsim.muscle_alone.run import LengthDrive

    spec = muscle_only_spec(sc, motion=LengthDrive(sc).motion)
    path = temp_fmu(spec.token, f"{spec.identifier}_fmi2.fmu", lambda out: build_spec(out, spec))
    md = read_model_description(str(path))
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(str(path)), modelIdentifier=md.modelExchange.modelIdentifier,
                    instanceName="alone")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    info = fmu.newDiscreteStates()
    assert info[4]  # a next event time is defined
    fmu.enterContinuousTimeMode()
    return fmu, {v.name: v.valueReference for v in md.modelVariables}, info[5]


def _read_at(fmu, ref, name, t):
    fmu.setTime(t)
    return fmu.getReal([ref[name]])[0]


def _event_at(fmu, t):
    fmu.setTime(t)
    fmu.enterEventMode()
    fmu.newDiscreteStates()
    fmu.enterContinuousTimeMode()


def test_model_exchange_follows_a_leg_past_its_turn_until_the_turns_event():
    """The FMU in model exchange between two events: the importer's integrator may evaluate it past the next
    time event (CVode steps past its output time and interpolates back), and there the motion is the leg the
    last event began, continued (a line through its two ends), not the next leg: a jump the continuous
    equations meet without an event made CVode stop short of the turn in thousands of events.  After the turn's
    event, it is the next leg."""
    sc = pamsim.load_scenario(SHIPPED)
    motion = LengthDrive(sc).motion
    fmu, ref, turn = _model_exchange(sc)
    try:
        assert turn == pytest.approx(2.0, abs=1e-12)  # the first leg ends at the first turn
        along = lambda t: motion.contraction_m(np.array([t]))[0]  # noqa: E731
        continued = along(turn) + (along(turn) - along(turn - 0.5))  # the first leg's line, 0.5 s past its end
        assert continued != pytest.approx(along(turn + 0.5), abs=1e-3)  # the two legs part there by 5 mm
        assert _read_at(fmu, ref, "motion.x_m", turn + 0.5) == pytest.approx(continued, abs=1e-15)
        assert _read_at(fmu, ref, "motion.x_m", turn - 0.5) == pytest.approx(along(turn - 0.5), abs=1e-15)
        _event_at(fmu, turn)
        assert _read_at(fmu, ref, "motion.x_m", turn + 0.5) == pytest.approx(along(turn + 0.5), abs=1e-15)
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_model_exchange_holds_a_step_until_its_event_and_takes_an_echo_of_what_it_applies():
    """A step (the valve's command opening at 0.5 s, a knot time given twice) is held at its value before the
    step past 0.5 s until the step's time event, and an importer that writes back the value it read is not
    refused there (the FMU compares with the value it applies)."""
    base = pamsim.load_scenario(SHIPPED)
    spec = dict(base.spec)
    spec["pressure"] = {"source": "valve", "supply_gauge_bar": 3.0, "valve_open_time_s": 0.5}
    sc = Scenario.from_dict(spec, name="valve_step", base_dir=base.base_dir)
    fmu, ref, step = _model_exchange(sc)
    try:
        assert step == pytest.approx(0.5, abs=1e-12)
        before = _read_at(fmu, ref, "valve_command", 0.25)
        held = _read_at(fmu, ref, "valve_command", 0.75)
        assert held == before
        fmu.setReal([ref["valve_command"]], [held])  # an echo, past the step's time, before its event
        _event_at(fmu, step)
        after = _read_at(fmu, ref, "valve_command", 0.75)
        assert after != before and after == sc.build_model().source.command(0.75)
    finally:
        fmu.terminate()
        fmu.freeInstance()


def _shipped_with(hysteresis: dict) -> Scenario:
    base = pamsim.load_scenario(SHIPPED)
    spec = dict(base.spec)
    spec["hysteresis"] = hysteresis
    return Scenario.from_dict(spec, name=hysteresis["model"], base_dir=base.base_dir)


@pytest.mark.parametrize("backend", ["python", "native", "fmu-cs", "fmu-me"])
def test_prandtl_ishlinskii_on_a_length_drive_is_the_standalone_operator(backend):
    """The generalized Prandtl-Ishlinskii element (envelope g(x) = s tanh(x / s)) along the shipped triangle:
    its force is ``-sum w_j (g - P_rj[g])`` of the standalone plays (:mod:`pamsim.hysteresis.play`, a second
    implementation) driven by g of the prescribed contraction, whose turns are samples, within 1e-4 N
    (measured: python 1.3e-5, native 7.7e-7, fmu-cs 1e-13, fmu-me 4.7e-5 N); the classical operator on x
    itself is about 2 N away."""
    from pamsim.hysteresis.play import play

    r_m, w = np.array([2e-4, 1e-3, 4e-3]), np.array([3750.0, 750.0, 250.0])
    s = 0.02
    sc = _shipped_with({"model": "pi", "thresholds_m": r_m.tolist(), "weights_N_per_m": w.tolist(),
                        "envelope_scale_m": s})
    res = simulate_length_drive(sc, backend)
    g = s * np.tanh(res.contraction_m / s)
    expected = -((g[:, None] - play(g, r_m, np.full(r_m.size, g[0]))) @ w)
    assert np.max(np.abs(res.signals["hysteresis.F_N"] - expected)) < 1e-4
    x = res.contraction_m
    classical = -((x[:, None] - play(x, r_m, np.full(r_m.size, x[0]))) @ w)
    assert np.max(np.abs(res.signals["hysteresis.F_N"] - classical)) > 0.2  # the envelope's slope shows


@pytest.mark.parametrize("backend", ["python", "native", "fmu-cs", "fmu-me"])
def test_bouc_wen_on_a_length_drive_follows_its_closed_form_first_branch(backend):
    """Bouc-Wen (n = 1, A = 1) along the shipped triangle's first leg, 30 to 40 mm of contraction: from z = 0,
    ``z = z_u (1 - exp(-(x - x0) / z_u))`` with ``z_u = 1 / (beta + gamma)``, within 1e-4 z_u (measured:
    python 1.1e-5, native 1.2e-7, fmu-cs 1.5e-6, fmu-me 4.2e-5); the force on the load is then the level
    times ``-z / z_u``."""
    beta = gamma = 5000.0
    z_u = 1.0 / (beta + gamma)
    sc = _shipped_with({"model": "bouc_wen", "beta_per_m_n": beta, "gamma_per_m_n": gamma, "exponent": 1.0})
    res = simulate_length_drive(sc, backend)
    leg = res.t_s <= 2.0 + 1e-12
    x = res.contraction_m[leg]
    assert x[0] == pytest.approx(0.03, abs=1e-12) and x[-1] == pytest.approx(0.04, abs=1e-12)
    z = res.signals["hysteresis.z_m"][leg]
    assert np.max(np.abs(z - z_u * (1.0 - np.exp(-(x - x[0]) / z_u)))) < 1e-4 * z_u
    np.testing.assert_allclose(res.signals["hysteresis.F_N"][leg], -LEVEL_N * z / z_u, rtol=0, atol=1e-9)


@pytest.fixture(scope="module")
def valve_driven():
    """The shipped cycles with the muscle's pressure from the rig's valve and chamber (3 bar supply, open at 0 s)
    in place of the prescribed 3 bar, on every backend."""
    base = pamsim.load_scenario(SHIPPED)
    spec = dict(base.spec)
    spec["pressure"] = {"source": "valve", "supply_gauge_bar": 3.0, "valve_open_time_s": 0.0}
    sc = Scenario.from_dict(spec, name="valve_driven", base_dir=base.base_dir)
    return sc, {b: simulate_length_drive(sc, b) for b in ("python", "native", "fmu-cs", "fmu-me")}


def test_a_valve_fed_chamber_drives_the_force_of_a_length_driven_muscle(valve_driven):
    """With the chamber's pressure in place of a prescribed one, the force is still the static force at the
    chamber's pressure (called on floats) minus damping plus the elements' (1e-6 N): this checks that the
    chamber's pressure is the one the force takes, both sides being python's; the backends are checked
    against python below.  The chamber fills from 0 through the valve and then follows the supply while the
    muscle's volume changes, within 200 Pa of it after 1 s (measured 119 Pa)."""
    sc, runs = valve_driven
    r, model = runs["python"], sc.build_model()
    p = r.signals["chamber.p_gauge_Pa"]
    static = np.array([float(model.static_force.force_N(a, b)) for a, b in zip(r.contraction_m, p)])
    damp = np.array([float(model.damping.force_N(b)) for b in r.velocity_m_s])
    assert np.max(np.abs(r.force_N - (static - damp + r.signals["hysteresis.F_N"]))) < 1e-6
    assert p[0] == 0.0 and np.max(np.abs(p[r.t_s > 1.0] - 3e5)) < 200.0


@pytest.mark.parametrize("backend, tol_N", [("native", 5e-4), ("fmu-cs", 5e-4), ("fmu-me", 3e-3)])
def test_every_backend_runs_the_valve_fed_length_drive(valve_driven, backend, tol_N):
    """Each backend's force within its bound of python's at every sample (measured: native 1.5e-4, fmu-cs
    1.6e-4, fmu-me 1.2e-3 N: the chamber's fill at 3 bar through the valve, integrated to rtol 1e-6), the same
    17 slips.  At 18 s the largest element's deflection meets its slip displacement exactly at a turn (the
    shipped cycles' design): an integrator may leave it a hair short there or put it a hair past, a slip of no
    length (python does, here); that instant is left out of the comparison."""
    _, runs = valve_driven
    ref, r = runs["python"], runs[backend]
    assert r.t_s.size == ref.t_s.size
    assert np.max(np.abs(r.force_N - ref.force_N)) < tol_N

    def slips(run):
        return [k for t, k in run.events if abs(t - 18.0) > 1e-6]
    assert slips(r) == slips(ref) and len(slips(ref)) == 17


def test_slips_between_two_samples_leave_pieces_without_a_sample():
    """At 2 Hz the first three slips (0.04, 0.2 and 0.8 s) fall between samples, so the pieces from one to the
    next hold none (python failed on them): the run keeps its 49 samples, python's equal native's to 1e-6 N."""
    sc = pamsim.load_scenario(SHIPPED).with_changes({"simulation": {"sample_rate_Hz": 2.0}})
    py, native = simulate_length_drive(sc, "python"), simulate_length_drive(sc, "native")
    assert py.t_s.size == native.t_s.size == 49
    assert [k for _, k in py.events] == [k for _, k in native.events] and len(py.events) == 17
    assert np.max(np.abs(py.force_N - native.force_N)) < 1e-6


def test_elements_that_reach_their_limits_together_slip_together_on_python():
    """Two elements of equal slip displacement (1 mm, shares 0.3 and 0.3 of 2.5 N) reach their limits at the same
    instant. ``solve_ivp`` reports one crossing; the other must fire with it, or it starts the next piece below
    zero, is never found, and its deflection (and, unclipped, its force) grows past the limit (15 times it,
    11.25 N, before).  Every deflection stays on its limit to 1e-12 relative, each element's force within its
    slip force, both slips named at the same instants, and python's force within 1e-6 N of native's."""
    sc = _shipped_with({"model": "maxwell_slip", "slip_displacement_m": [1e-3, 1e-3, 4e-3], "share": [0.3, 0.3, 0.4]})
    py, native = simulate_length_drive(sc, "python"), simulate_length_drive(sc, "native")
    for i, (delta, share) in enumerate(((1e-3, 0.3), (1e-3, 0.3), (4e-3, 0.4)), start=1):
        assert np.max(np.abs(py.signals[f"hysteresis.z{i}_m"])) <= delta * (1.0 + 1e-12)
        assert np.max(np.abs(py.signals[f"hysteresis.F{i}_N"])) <= share * 2.5 * (1.0 + 1e-9)
    slips = {k: [t for t, name in py.events if name == k] for k in ("hysteresis.slip1", "hysteresis.slip2")}
    assert slips["hysteresis.slip1"] and slips["hysteresis.slip1"] == slips["hysteresis.slip2"]
    assert np.max(np.abs(py.force_N - native.force_N)) < 1e-6
