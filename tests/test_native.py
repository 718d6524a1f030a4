"""The native backend end to end: the paper scenarios against the Python backend, the Result it
returns, its batch entry point, refusals of what it cannot honour, the CLI and sweeps."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.errors import InputError, SolverFailure
from pamsim.native import simulate_batch
from pamsim.native.backend import hold_interval_s
from pamsim.sweep import sweep_from_dict
from pamsim.sweep.spec import SweepError

from conftest import PAPER_SCENARIOS, SCENARIOS, run_cli, run_main

# Both backends integrate to rtol 1e-6 (LSODA and Dormand-Prince 5(4), absolute tolerances rtol x
# 10 mm on the contraction), so they agree to a few multiples of 1e-8 m per unit error; 5 um is
# 1/10,000 of the paper's contractions and 1/40 of its 0.2 mm reading resolution.
X_TOL_M = 5e-6


@pytest.fixture(scope="module")
def native_results():
    scenarios = [pamsim.load_scenario(SCENARIOS / f"{name}.toml") for name in PAPER_SCENARIOS]
    return dict(zip(PAPER_SCENARIOS, simulate_batch(scenarios)))


@pytest.mark.parametrize("name", PAPER_SCENARIOS)
def test_paper_scenarios_match_the_python_backend(paper_results, native_results, name):
    _, py = paper_results[name]
    nat = native_results[name]
    assert abs(nat.x_m[-1] - py.x_m[-1]) < X_TOL_M
    assert abs(nat.x_m.max() - py.x_m.max()) < X_TOL_M
    assert np.max(np.abs(nat.x_m - py.x_m)) < 2 * X_TOL_M
    assert np.max(np.abs(nat.p_gauge_Pa - py.p_gauge_Pa)) < 1e-4 * 4e5  # 1e-4 of the supply
    assert nat.final_mode == py.final_mode
    # The same events, in the same order, at nearly the same times.
    assert [(e.kind, e.from_mode, e.to_mode) for e in nat.transitions] == \
        [(e.kind, e.from_mode, e.to_mode) for e in py.transitions]
    assert max(abs(a.t_s - b.t_s) for a, b in zip(nat.transitions, py.transitions)) < 1e-4


@pytest.mark.parametrize("name", PAPER_SCENARIOS)
def test_energy_balance_closes_and_matches_the_python_work(paper_results, native_results, name):
    """The work integrals (Gauss quadrature on the dense output) close the balance as the Python
    backend's (integrated as states) do, and agree with them term by term."""
    _, py = paper_results[name]
    nat, ref = native_results[name].energy_balance(), py.energy_balance()
    assert nat["relative"] < 1e-4
    for term in ("W_muscle_J", "E_friction_J", "E_damping_J", "E_impacts_J", "dPE_J"):
        assert abs(nat[term] - ref[term]) <= 1e-4 * max(abs(ref["W_muscle_J"]), 1e-3), term


def test_result_has_the_python_backends_columns_summary_and_event_records(paper_results, native_results):
    _, py = paper_results["acra2012_fig6b"]
    nat = native_results["acra2012_fig6b"]
    assert list(nat.columns()) == list(py.columns())
    assert np.array_equal(nat.t_s, py.t_s)
    assert set(nat.summary()) == set(py.summary())
    assert set(nat.stats) == set(py.stats) and nat.stats["method"] == "native DOPRI5(4), Rodas4 where stiff"
    assert nat.summary()["events"] == len(nat.transitions) == len(py.transitions) > 20
    for res in (py, nat):  # the solver's counts and settings, as the joint's and the muscle's summaries give them
        assert {k: res.summary()[k] for k in ("rhs_evaluations", "segments", "jacobians", "method", "rtol")} == \
            {k: res.stats[k] for k in ("rhs_evaluations", "segments", "jacobians", "method", "rtol")}
    # The modes on the sample grid are those of the Python run, except within a sample of an event.
    differ = np.flatnonzero(nat.mode != py.mode)
    times = np.array([e.t_s for e in py.transitions])
    assert all(np.min(np.abs(times - nat.t_s[k])) < 2e-3 for k in differ)


def test_batch_gives_the_single_runs_results_bit_for_bit():
    a = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    b = a.with_changes({"load": {"weight_N": 42.74}, "model": {"friction": "constant", "damping": "linear"}})
    c = a.with_changes({"pressure": {"source": "prescribed", "prescribed": {"kind": "step", "time_s": 0.5,
                                                                             "final_gauge_bar": 3.0}}})
    batch = simulate_batch([a, b, c])
    for scenario, res in zip((a, b, c), batch):
        alone = pamsim.simulate(scenario, backend="native")
        assert np.array_equal(res.x_m, alone.x_m) and np.array_equal(res.p_gauge_Pa, alone.p_gauge_Pa)
        assert res.transitions == alone.transitions


def test_other_element_choices_and_initial_state_match_the_python_backend():
    base = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    variants = [{"model": {"friction": "constant", "damping": "linear"}},
                {"model": {"friction": "none", "damping": "none"}, "load": {"weight_N": 12.74}},
                {"model": {"friction_negative_level": "abs"}, "load": {"weight_N": 52.74}},
                {"pressure": {"initial_gauge_bar": 1.0}, "simulation": {"initial_contraction_m": 0.01}},
                {"parameters": {"stop_restitution": 0.5}, "load": {"weight_N": 2.74}}]
    scenarios = [base.with_changes(v) for v in variants]
    for scenario, nat in zip(scenarios, simulate_batch(scenarios)):
        py = pamsim.simulate(scenario)
        assert abs(nat.x_m[-1] - py.x_m[-1]) < X_TOL_M, scenario.spec
        assert nat.energy_balance()["relative"] < 1e-3


def test_exact_segments_against_a_hand_calculation():
    """Every knot and lag start inside the run cuts it; each input's value at a piece's start and its change
    over the piece (slope, lag amplitude, lag time constant) by hand; an input without a signal is zero."""
    import math

    from pamsim.native.backend import exact_segments
    from pamsim.signals import FirstOrderLag, PiecewiseConstant, Ramp, Step

    signals = (Step(1.0, 0.0, 1.0), None, Ramp(0.5, 1.5, 2.0, 4.0), FirstOrderLag(0.25, 1.0, 3.0, 0.1),
               PiecewiseConstant((0.0, 0.75, 9.0), (5.0, -1.0, 7.0)))
    starts, u, du = exact_segments(signals, 2.0)
    assert starts.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0, 1.5]  # 9 s is after the end
    lag = [1.0, 1.0] + [3.0 - 2.0 * math.exp(-(t - 0.25) / 0.1) for t in (0.5, 0.75, 1.0, 1.5)]
    ramp = [2.0, 2.0, 2.0, 2.5, 3.0, 4.0]
    want_u = [[0.0, 0.0, 0.0, 0.0, 1.0, 1.0], [0.0] * 6, ramp, lag, [5.0, 5.0, 5.0, -1.0, -1.0, -1.0]]
    assert u.dtype == float and u.shape == (6, 5)
    for k, column in enumerate(want_u):
        np.testing.assert_allclose(u[:, k], column, rtol=1e-15, atol=0.0)
    amplitude = [0.0, -2.0] + [-2.0 * math.exp(-(t - 0.25) / 0.1) for t in (0.5, 0.75, 1.0, 1.5)]
    np.testing.assert_allclose(du[:, 3, 1], amplitude, rtol=1e-15, atol=0.0)
    assert du[:, 3, 2].tolist() == [0.0] + [0.1] * 5
    assert du[:, 2, 0].tolist() == [0.0, 0.0, 2.0, 2.0, 2.0, 0.0]  # the ramp's slope over its pieces
    assert not du[:, [0, 1, 4]].any() and not du[:, 2, 1:].any() and not du[:, 3, 0].any()
    assert exact_segments((lambda t: t,), 1.0) is None  # a callable is held piecewise instead


def test_a_scenario_run_again_reuses_its_case_by_the_object_not_by_equality(monkeypatch):
    """The case of a scenario's own model is kept for the scenario object: the same object finds it (its
    arrays read-only), an equal scenario (another object) or a run with a model given builds its own, a
    kept case whose scenario is gone is never handed to another that took its id, and the kept cases
    are bounded."""
    import weakref

    from pamsim.native import backend
    from pamsim.native.engine import engine_library

    fig4 = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    case = backend.case_inputs(fig4)
    assert backend.case_inputs(fig4) is case
    assert not case.segment_u.flags.writeable and not case.reals.flags.writeable
    twin = fig4.with_changes({})
    assert twin == fig4 and backend.case_inputs(twin) is not case
    assert backend.case_inputs(fig4, fig4.build_model()) is not case
    other = fig4.with_changes({"load": {"weight_N": 30.0}})
    backend._cases._kept[id(other)] = (weakref.ref(twin), case)  # as if `other` took a dead scenario's id
    assert backend.case_inputs(other) is not case
    assert backend.case_inputs(other).model.load.mass_kg == pytest.approx(30.0 / 9.81, rel=1e-12)
    monkeypatch.setattr(backend._cases, "size", 2)
    for weight in (10.0, 11.0, 12.0):
        backend.case_inputs(fig4.with_changes({"load": {"weight_N": weight}}))
    assert len(backend._cases._kept) == 2
    assert backend.simulate(fig4).x_m[-1] == simulate_batch([fig4.with_changes({})])[0].x_m[-1]
    library = engine_library(case.assembly)
    engine_case = case.engine_case(library, 64)  # kept with the case too, read-only
    assert case.engine_case(library, 64) is engine_case and case.engine_case(library, 65) is not engine_case
    assert not engine_case.params.flags.writeable and not engine_case.segment_u.flags.writeable


def test_hold_interval_of_the_piecewise_path():
    """Where inputs are held (a signal given as a Python callable), a 10 ms lag is held over pieces of at most tau / 10 and at most one output sample."""
    sc = pamsim.Scenario.from_dict({"load": {"weight_N": 22.74}, "simulation": {"duration_s": 4.0},
                                    "pressure": {"source": "prescribed", "prescribed": {
                                        "kind": "lag", "time_s": 1.0, "tau_s": 0.01, "final_gauge_bar": 3.6}}})
    model = sc.build_model()
    assert hold_interval_s([model.source.p_gauge_Pa], 1e-3) == pytest.approx(1e-3)
    assert hold_interval_s([model.source.p_gauge_Pa], 1.0) == pytest.approx(1e-3)


SMOOTH_INPUTS = {
    "command ramp": {"source": "valve", "supply_gauge_bar": 3.6, "command": {"kind": "ramp", "start_s": 0.5, "end_s": 1.0, "final": 1.0}},
    "command lag": {"source": "valve", "supply_gauge_bar": 3.6, "command": {"kind": "lag", "time_s": 0.5, "tau_s": 0.2, "final": 1.0}},
    "prescribed ramp": {"source": "prescribed",
                        "prescribed": {"kind": "ramp", "start_s": 0.0, "end_s": 0.5, "final_gauge_bar": 3.6}},
    "prescribed 10 ms lag": {"source": "prescribed",
                             "prescribed": {"kind": "lag", "time_s": 1.0, "tau_s": 0.01, "final_gauge_bar": 3.6}},
    "prescribed trace": {"source": "prescribed", "prescribed": {"kind": "trace", "file": "TRACE"}},
}


@pytest.mark.parametrize("name", SMOOTH_INPUTS)
def test_smooth_inputs_are_exact_whatever_the_output_sampling(tmp_path, name):
    """Ramps, lags and traces enter the engine's integrator in closed form, cut at their knots: the
    output sample rate changes nothing (it once did, by 3.9 mm at 10 Hz for a ramp or a trace), and
    the run meets the python backend's, which evaluates the signals exactly too, within the two
    integrators' tolerances (a 10 ms lag's fast transient differs most: 8 um, the final 0.5 um)."""
    t = np.linspace(0.0, 2.0, 41)
    p_bar = 3.6 * (1.0 - np.exp(-t / 0.3)) * (t > 0.2)
    (tmp_path / "trace.csv").write_text("t_s,p_gauge_bar\n" + "\n".join(f"{a:.17g},{b:.17g}" for a, b in zip(t, p_bar)))
    runs = {}
    for rate in (10.0, 1000.0):
        pressure = json.loads(json.dumps(SMOOTH_INPUTS[name]).replace("TRACE", str(tmp_path / "trace.csv")))
        spec = {"load": {"weight_N": 22.74}, "simulation": {"duration_s": 4.0, "sample_rate_Hz": rate},
                "pressure": pressure}
        sc = pamsim.Scenario.from_dict(spec, name="smooth", origin=str(tmp_path / "smooth.toml"))
        runs[rate] = (pamsim.simulate(sc, backend="native"), pamsim.simulate(sc))
    (coarse, _), (fine, py) = runs[10.0], runs[1000.0]
    assert abs(coarse.x_m[-1] - fine.x_m[-1]) < 1e-12
    assert np.max(np.abs(fine.x_m[::100] - coarse.x_m)) < 1e-12
    assert abs(fine.x_m[-1] - py.x_m[-1]) < 1e-6
    assert np.max(np.abs(fine.x_m - py.x_m)) < 1e-5  # in a 10 ms lag's transient: the tolerances
    assert fine.energy_balance()["relative"] < 1e-3


def test_too_many_events_is_a_solver_failure_on_both_backends():
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig6b.toml").with_changes({"solver": {"max_events": 5}})
    for backend in ("python", "native"):
        with pytest.raises(SolverFailure, match="more than 5 events"):
            pamsim.simulate(sc, backend=backend)


def test_too_many_events_message_counts_in_the_singular_for_one():
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig6b.toml").with_changes({"solver": {"max_events": 1}})
    for backend in ("python", "native"):
        with pytest.raises(SolverFailure, match="more than 1 event ") as err:
            pamsim.simulate(sc, backend=backend)
        assert "1 events" not in str(err.value)


def test_a_case_that_outgrows_the_batch_event_room_runs_again_alone(monkeypatch):
    """With room for 3 events per case, cases with more are run again alone with room for their own
    max_events, and give the numbers of a batch with room enough; a case over its own limit still
    fails as on its own."""
    from pamsim.native import backend, simulate_batch

    fig6b = pamsim.load_scenario(SCENARIOS / "acra2012_fig6b.toml")
    fig4 = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    few = fig6b.with_changes({"solver": {"max_events": 2}})
    reference = simulate_batch([fig6b, fig4])
    assert len(reference[0].transitions) > 3
    calls = []
    run = backend._run
    monkeypatch.setattr(backend, "_run", lambda cases, capacity, engines=None:
                        calls.append(list(capacity)) or run(cases, capacity, engines))
    monkeypatch.setattr(backend, "BATCH_EVENT_CAPACITY", 3)
    again = simulate_batch([fig6b, fig4, few], return_exceptions=True)
    # fig6b (34 events) and fig4 (4) outgrow the room; `few` stops on its own limit of 2, not run again
    assert calls[0] == [3, 3, 3] and calls[1:] == [[fig6b.solver.max_events + 1], [fig4.solver.max_events + 1]]
    for a, r in zip(again, reference):
        assert np.array_equal(a.x_m, r.x_m) and a.transitions == r.transitions
    assert isinstance(again[2], SolverFailure) and "more than 2 events" in str(again[2])


@pytest.mark.parametrize("changes, key", [
    ({"solver": {"method": "Radau"}}, "solver.method"),
    ({"solver": {"method": "DOP853"}}, "solver.method"),
])
def test_settings_it_cannot_honour_are_refused_naming_the_key(changes, key):
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes(changes)
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        pamsim.simulate(sc, backend="native")


def test_unknown_backend_is_an_input_error():
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    with pytest.raises(InputError, match="unknown backend 'c'"):
        pamsim.simulate(sc, backend="c")


def test_cli_run_native_writes_the_python_backends_files(tmp_path):
    proc = run_main("run", SCENARIOS / "acra2012_fig4.toml", "--backend", "native", "-o", tmp_path, "--no-plot")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((tmp_path / "acra2012_fig4.json").read_text())
    assert summary["backend"] == "native"
    header = (tmp_path / "acra2012_fig4.csv").read_text().splitlines()[0]
    assert header.startswith("t_s,x_m,v_m_s,p_gauge_Pa,mode,")


def test_cli_run_native_refuses_with_one_line_and_exit_2(tmp_path):
    scenario = tmp_path / "radau.toml"
    scenario.write_text((SCENARIOS / "acra2012_fig4.toml").read_text().replace('"LSODA"', '"Radau"'))
    out = tmp_path / "out"
    proc = run_cli("run", scenario, "--backend", "native", "-o", out)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "solver.method" in lines[0] and "Radau" in lines[0] and "radau.toml" in lines[0]
    assert not out.exists()


def test_sweep_backend_key_runs_natively_and_matches_python():
    spec = {"base_scenario": "acra2012_fig5.toml", "friction_models": ["load_dependent", "constant"],
            "case": [{"weight_N": 12.74, "pressure_bar": 3.6}, {"weight_N": 32.74, "pressure_bar": 2.4}]}
    native = pamsim.sweep(sweep_from_dict({**spec, "backend": "native"}, base_dir=SCENARIOS))
    python = pamsim.sweep(sweep_from_dict(spec, base_dir=SCENARIOS))
    for a, b in zip(native.rows, python.rows):
        assert a["failure"] == "" and abs(a["final_contraction_m"] - b["final_contraction_m"]) < X_TOL_M
        assert abs(a["constant_final_contraction_m"] - b["constant_final_contraction_m"]) < X_TOL_M


def test_sweep_refuses_unknown_backend_and_unsupported_settings_before_running(tmp_path):
    with pytest.raises(SweepError, match="backend = 'cuda'"):
        sweep_from_dict({"base_scenario": "acra2012_fig5.toml", "backend": "cuda",
                         "case": [{"weight_N": 12.74, "pressure_bar": 3.6}]}, base_dir=SCENARIOS)
    base = tmp_path / "base.toml"
    base.write_text((SCENARIOS / "acra2012_fig5.toml").read_text().replace('"LSODA"', '"BDF"'))
    spec = sweep_from_dict({"base_scenario": str(base), "case": [{"weight_N": 12.74, "pressure_bar": 3.6}]})
    with pytest.raises(InputError, match="solver.method"):
        pamsim.sweep(spec, backend="native")
    proc = run_main("sweep", _write_sweep(tmp_path, base), "--backend", "native", "--workers", "1", "-o",
                   tmp_path / "out")
    assert proc.returncode == 2 and "solver.method" in proc.stderr and not (tmp_path / "out").exists()


def _write_sweep(folder: Path, base: Path) -> Path:
    path = folder / "sweep.toml"
    path.write_text(f'base_scenario = "{base.name}"\n[[case]]\nweight_N = 12.74\npressure_bar = 3.6\n')
    return path


def test_a_force_table_case_takes_its_inputs_exactly_too():
    """The implicit two-phase model runs natively as its spline table's B-spline on the engine: a pressure
    ramp there is exact as well, so 10 Hz and 1 kHz output give the same run (they differed before by
    the midpoint hold), within the integrators' difference of the python backend's run of the same table."""
    spec = {"model": {"muscle": "mpam_survey_45mm", "static_force": "mpam_two_phase"}, "parameters": {"E_nylon_Pa": 3e9},
            "load": {"weight_N": 0.05}, "simulation": {"duration_s": 2.0},
            "pressure": {"source": "prescribed",
                         "prescribed": {"kind": "ramp", "start_s": 0.2, "end_s": 1.2, "final_gauge_bar": 7.0}}}
    runs = {}
    for rate in (10.0, 1000.0):
        sc = pamsim.Scenario.from_dict({**spec, "simulation": {"duration_s": 2.0, "sample_rate_Hz": rate}})
        runs[rate] = pamsim.simulate(sc, backend="native")
    assert runs[10.0].x_m[-1] == runs[1000.0].x_m[-1]
    assert np.max(np.abs(runs[1000.0].x_m[::100] - runs[10.0].x_m)) < 1e-12
    py = pamsim.simulate(pamsim.Scenario.from_dict(spec))
    assert abs(runs[1000.0].x_m[-1] - py.x_m[-1]) < 1e-7
