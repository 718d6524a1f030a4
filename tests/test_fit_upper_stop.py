"""The fits search equilibria up to the muscle's own upper stop (the braid's jam angle, the end of the static
model's domain), as its simulations and ``pamsim static`` do, not up to the braid lock at 54.7 deg; a test
predicted on the stop is reported; the fitted muscle file carries the source muscle's ``[upper_stop]``.

The muscle is the survey's 45 mm one (braid lock at 12.886 mm) with wider strands, so that its braid jams at
13.80 mm, inside the domain of its static model (31.9 mm): tests at low pressure rest freely below the lock,
some between the lock and the jam, and at high pressure on the jam.  Its data are ``pamsim static``'s
equilibria (:func:`pamsim.static.static_report`, a scalar bisection of its own) of the same muscle.
"""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

import pamsim
from pamsim.identification.columns import StaticData, TraceData
from pamsim.identification.dynamic_fit import check_data as check_trace_data
from pamsim.identification.muscle_file import load_muscle_parameters, load_upper_stop, scenario_upper_stop
from pamsim.identification.static_fit import fit_static
from pamsim.muscle_setup import end_stops, prepare
from pamsim.static import static_report
from pamsim.static_models.geometry import Braid

from conftest import ROOT
from conftest import run_main as pamsim_cli
from test_fit_static_limits import check_fitted_muscle_loads

SURVEY_FILE = ROOT / "pamsim" / "muscles" / "mpam_survey_45mm.toml"
FIBRE_RADIUS_M = 9.1e-5  # the survey's strands are 0.04 mm; these jam the braid before its model's domain ends
JAM_SOURCE = "test: strands widened until the braid jams inside the model's domain"
E_TRUE_PA = 0.2e6  # softer than the survey's 0.345 MPa, so that high pressures pull the muscle onto the jam
P_BAR = np.array([3.0, 4.0, 5.0, 5.5, 6.0, 6.5, 7.0, 7.58])
LOAD_N = np.array([0.05, 0.05, 0.1, 0.05, 0.2, 0.05, 0.1, 0.05])
BRAID_LOCK_M = 0.012886


@pytest.fixture(scope="module")
def jam_muscle(tmp_path_factory):
    """The survey muscle with wider strands and ``[upper_stop] at = "jam"``, as a muscle file."""
    text = SURVEY_FILE.read_text().split("[data]")[0]
    text = text.replace("value = 4e-05\nsource = \"MPAM survey, captions: r_n = 0.04 mm",
                        f"value = {FIBRE_RADIUS_M!r}\nsource = \"test, widened from: r_n = 0.04 mm")
    text = text.replace('name = "mpam_survey_45mm"', 'name = "survey_jammed"', 1)
    text += f'\n[upper_stop]\nat = "jam"\nsource = "{JAM_SOURCE}"\n'
    path = tmp_path_factory.mktemp("jam") / "jammed.toml"
    path.write_text(text)
    return path


def static_answers(muscle: str, E_Pa: float):
    """``pamsim static``'s equilibrium [m] and ``on_stop`` of each test, with the modulus ``E_Pa``."""
    m, params, model = prepare(muscle, overrides={"E_bladder_Pa": E_Pa})
    stops = end_stops(m, params, model)
    reports = [static_report(params, model, p * 1e5, w, stops) for p, w in zip(P_BAR, LOAD_N)]
    return np.array([r["equilibrium_contraction_m"] for r in reports]), [r["on_stop"] for r in reports], stops


def test_the_jam_stands_between_the_braid_lock_and_the_domain_end(jam_muscle):
    """By hand (:meth:`Braid.x_jam_m`' formula): 30 strands 0.182 mm wide jam where sin(2 theta) = n w / (2 pi r_max)."""
    p = pamsim.load_muscle(jam_muscle).parameters
    braid = Braid.from_parameters(p)
    r_max = braid.b / (2 * np.pi * braid.N)
    theta_jam = 0.5 * (np.pi - np.arcsin(30 * 2 * FIBRE_RADIUS_M / (2 * np.pi * r_max)))
    x_jam = p["L0_m"] - braid.b * np.cos(theta_jam)
    _, _, stops = static_answers(str(jam_muscle), E_TRUE_PA)
    assert stops.upper_basis == "jam" and stops.x_high_m == pytest.approx(x_jam, rel=1e-12)
    assert BRAID_LOCK_M < x_jam < 0.0319


@pytest.fixture(scope="module")
def jam_fit(jam_muscle):
    x, on_stop, _ = static_answers(str(jam_muscle), E_TRUE_PA)
    data = StaticData(P_BAR * 1e5, x, LOAD_N, "weight", "static answers")
    params, model = load_muscle_parameters(str(jam_muscle))
    start = params.with_overrides({"E_bladder_Pa": 0.5e6}, source="test start")
    fit = fit_static(data, start, model=model, free=["E_bladder_Pa"], cv=None, intervals=False,
                     upper_stop=load_upper_stop(str(jam_muscle)))
    return x, on_stop, fit


def test_a_static_fit_finds_equilibria_up_to_the_jam(jam_muscle, jam_fit):
    """Noise-free equilibria beyond the braid lock: the fit recovers the modulus and predicts every test where
    ``pamsim static`` puts it (up to the lock, as before, it could not: the tests beyond it were clipped)."""
    x, on_stop, fit = jam_fit
    assert np.sum(x > BRAID_LOCK_M + 1e-4) >= 4  # the data reach past the braid lock
    assert fit.parameters["E_bladder_Pa"] == pytest.approx(E_TRUE_PA, rel=1e-6)
    x_fit, on_fit, stops = static_answers(str(jam_muscle), fit.parameters["E_bladder_Pa"])
    np.testing.assert_allclose(fit.predicted_m, x_fit, rtol=0, atol=1e-9)
    assert fit.rms_contraction_mm < 1e-5


def test_a_fitted_test_on_the_stop_is_reported(jam_muscle, jam_fit):
    """The tests ``pamsim static`` says rest on the upper stop are those the fit reports on it."""
    _, on_stop, fit = jam_fit
    assert "upper" in on_stop and None in on_stop
    stop = fit.to_json()["upper_stop"]
    assert stop["tests_on_stop"] == [i for i, s in enumerate(on_stop) if s == "upper"]
    assert stop["at"] == "jam" and stop["basis"] == "jam"
    assert stop["x_m"] == pytest.approx(static_answers(str(jam_muscle), E_TRUE_PA)[2].x_high_m, rel=1e-12)


def test_the_cli_fit_reports_the_stop_and_writes_it_into_the_muscle_file(jam_muscle, jam_fit, tmp_path):
    x, on_stop, _ = jam_fit
    data = tmp_path / "static.csv"
    data.write_text("pressure_bar,contraction_mm,weight_N\n"
                    + "".join(f"{float(p)!r},{float(xi) * 1e3!r},{float(w)!r}\n" for p, xi, w in zip(P_BAR, x, LOAD_N)))
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", jam_muscle, "--free", "E_bladder_Pa", "--cv", "none", "-o", out)
    assert proc.returncode == 0, proc.stderr
    on = [i for i, s in enumerate(on_stop) if s == "upper"]
    assert f"{len(on)} test(s) predicted on the upper stop" in proc.stdout
    assert json.loads((out / "fit.json").read_text())["upper_stop"]["tests_on_stop"] == on
    assert "predicted on it" in (out / "report.md").read_text()
    fitted = check_fitted_muscle_loads(out, pamsim.load_muscle(jam_muscle))
    assert (fitted.upper_stop, fitted.upper_stop_source) == ("jam", JAM_SOURCE)
    assert tomllib.loads((out / "muscle.toml").read_text())["upper_stop"] == {"at": "jam", "source": JAM_SOURCE}


def _trace_to(x_top_m: float) -> TraceData:
    t = np.linspace(0.0, 1.0, 101)
    return TraceData(t, x_top_m * np.minimum(t / 0.5, 1.0), None, 0.05, "rise")


def test_a_dynamic_fit_checks_its_traces_against_the_scenarios_stop():
    """The survey muscle's scenario stops at its model's domain end (31.9 mm): a trace rising to 13.3 mm, where
    the muscle rests at 7.58 bar, is no contraction beyond the stop (the braid lock said it was)."""
    sc = pamsim.Scenario.from_dict({
        "model": {"muscle": "mpam_survey_45mm"}, "parameters": {"E_bladder_Pa": 0.345e6},
        "load": {"weight_N": 0.05}, "pressure": {"source": "valve", "supply_gauge_bar": 7.58, "valve_open_time_s": 0.1},
        "simulation": {"duration_s": 1.0}})
    assert not [w for w in check_trace_data(sc, [_trace_to(0.0133)]) if "upper stop" in w]
    assert [w for w in check_trace_data(sc, [_trace_to(0.0330)]) if "upper stop 31.95 mm" in w]


def test_a_dynamic_fit_muscle_carries_the_stop_it_was_fitted_with(jam_muscle):
    """The scenario's ``[model] upper_stop`` if it sets one, else its muscle's table."""
    base = {"model": {"muscle": str(jam_muscle)}, "load": {"weight_N": 0.05},
            "pressure": {"source": "valve", "supply_gauge_bar": 7.0, "valve_open_time_s": 0.1},
            "simulation": {"duration_s": 1.0}}
    assert scenario_upper_stop(pamsim.Scenario.from_dict(base)) == ("jam", JAM_SOURCE)
    chosen = pamsim.Scenario.from_dict({**base, "model": {**base["model"], "upper_stop": "braid_lock"}}, name="mine")
    at, source = scenario_upper_stop(chosen)
    assert at == "braid_lock" and "'mine'" in source
    assert scenario_upper_stop(pamsim.Scenario.from_dict({**base, "model": {"muscle": "mpam_survey_45mm"}})) is None


def test_a_fit_of_a_muscle_whose_stop_cannot_stand_is_refused_in_one_line(tmp_path):
    """Strands so wide they would cover the braid: no jam angle, so no upper stop; as ``pamsim static`` says."""
    path = tmp_path / "covered.toml"
    path.write_text(SURVEY_FILE.read_text().split("[data]")[0].replace("value = 4e-05\n", "value = 2e-04\n", 1))
    data = tmp_path / "static.csv"
    data.write_text("pressure_bar,contraction_mm,weight_N\n3,10,0.05\n4,11,0.05\n5,12,0.05\n6,12.5,0.05\n7,13,0.05\n")
    out = tmp_path / "never"
    proc = pamsim_cli("fit", "static", data, "--muscle", path, "--free", "E_bladder_Pa", "-o", out)
    assert proc.returncode == 2 and not out.exists()
    assert proc.stderr.strip().splitlines() == [
        "pamsim: error: muscle 'mpam_survey_45mm': its upper stop 'auto': fibre_radius_m = 0.0002 with "
        "n_fibres = 30: the fibres would cover the braid at every angle: the braid could not move"]


def test_the_jacobian_of_a_test_on_the_stop_is_the_stops_own_derivative(jam_muscle, jam_fit):
    """With the rest length free the jam moves with it: each row of the analytic Jacobian, a test resting
    freely or on the jam, is the central difference of the residuals (equilibria found again each time)."""
    from pamsim.identification.static_fit import make_problem

    x, on_stop, fit = jam_fit
    params, model = load_muscle_parameters(str(jam_muscle))
    problem = make_problem(fit.problem.data, params.with_overrides({"E_bladder_Pa": E_TRUE_PA}, source="test"), model,
                           free=["E_bladder_Pa", "L0_m"], upper_stop=load_upper_stop(str(jam_muscle)))
    theta = problem.start
    J = problem.jacobian(theta)
    h = 1e-6 * np.abs(theta)
    numeric = np.column_stack([(problem.residuals(theta + e) - problem.residuals(theta - e)) / (2 * e @ np.ones(2))
                               for e in np.diag(h)])
    on = np.array([s == "upper" for s in on_stop])
    assert on.any() and np.all(np.abs(J[on, 1]) > 100.0)  # the jam moves with L0 [mm per m]
    np.testing.assert_allclose(J, numeric, rtol=1e-4, atol=1e-6 * np.abs(numeric).max())
