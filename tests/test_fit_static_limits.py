"""``pamsim fit static`` on the README's own example muscle: geometry stays physical, the fitted
muscle file loads back, and the result claims no more than the data show."""

from __future__ import annotations

import json
import re
import tomllib

import numpy as np
import pytest

import pamsim
from pamsim.parameter_schema import LOCK_DEG

from conftest import ROOT
from conftest import run_main as pamsim_cli

README_MUSCLE = re.search(r"`my_muscle.toml`:\n\n```toml\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)

THIN_WALL_TESTS = """# seven tests of the README muscle, loads beyond what a 1 mm wall allows: the fit drives the wall to zero
pressure_bar,contraction_mm,weight_N
2.12,19.7,70.6
3.66,32.2,86.3
4.37,22.6,112.2
3.39,52.4,10.5
2.97,26.7,97.4
3.93,27.0,110.7
3.72,38.3,60.4
"""


@pytest.fixture
def readme_muscle(tmp_path):
    path = tmp_path / "my_muscle.toml"
    path.write_text(README_MUSCLE)
    return path


def check_fitted_muscle_loads(out, source=None):
    """Every fit output loads back as a muscle, with only independent values written, and with the upper stop
    of the ``source`` muscle it was fitted from (its ``[upper_stop]`` table, or none)."""
    muscle = pamsim.muscles.load_muscle(out / "muscle.toml")
    written = tomllib.loads((out / "muscle.toml").read_text())["parameters"]
    assert not [k for k, v in written.items() if v["source"].startswith("derived")]
    if source is not None:
        assert (muscle.upper_stop, muscle.upper_stop_source) == (source.upper_stop, source.upper_stop_source)
    return muscle


def test_readme_muscle_fit_keeps_its_geometry_physical(tmp_path, readme_muscle):
    data = tmp_path / "static.csv"
    data.write_text(THIN_WALL_TESTS)
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", readme_muscle, "-o", out)
    assert proc.returncode == 0, proc.stderr
    muscle = check_fitted_muscle_loads(out, pamsim.load_muscle(readme_muscle))
    v = muscle.parameters
    assert 0.0 < v["wall_thickness_m"] < v["r0_m"] < v["L0_m"]
    assert 0.0 < v["theta0_deg"] < LOCK_DEG


@pytest.mark.parametrize("free", ["r0_m,theta0_deg", "ri0_m,theta0_deg", "r0_m,wall_thickness_m,theta0_deg"])
def test_fitted_muscle_with_wall_loads_back(tmp_path, readme_muscle, free):
    # Tests the starting muscle itself would give: the fit moves the radii a little.
    muscle = pamsim.load_muscle(readme_muscle)
    force = muscle.static_force().force_N
    p_bar = np.repeat([2.0, 3.0, 4.0], 3)
    w = np.tile([10.0, 30.0, 60.0], 3)
    x = np.array([muscle.static_force().free_contraction_m(pi * 1e5, wi) for pi, wi in zip(p_bar, w)])
    assert np.all(np.abs(force(x, p_bar * 1e5) - w) < 1e-6)
    rows = "\n".join(f"{a:g},{b * 1e3 + 0.3 * (-1) ** i:.3f},{c:g}" for i, (a, b, c) in enumerate(zip(p_bar, x, w)))
    data = tmp_path / "static.csv"
    data.write_text("pressure_bar,contraction_mm,weight_N\n" + rows + "\n")
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", readme_muscle, "--free", free, "-o", out)
    assert proc.returncode == 0, proc.stderr
    fitted = check_fitted_muscle_loads(out, pamsim.load_muscle(readme_muscle)).parameters
    assert fitted["r0_m"] - fitted["ri0_m"] == pytest.approx(fitted["wall_thickness_m"], rel=1e-9)


def test_freeing_both_wall_values_is_refused(tmp_path, readme_muscle):
    data = tmp_path / "static.csv"
    data.write_text(THIN_WALL_TESTS)
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", readme_muscle, "--free", "ri0_m,wall_thickness_m", "-o", out)
    assert proc.returncode == 2 and "at most one of ri0_m and wall_thickness_m" in proc.stderr
    assert proc.stderr.count("\n") == 1 and not out.exists()


def test_a_blind_direction_is_not_identified_never_a_zero_error():
    from pamsim.identification.uncertainty import linearised_uncertainty

    rng = np.random.default_rng(0)
    a, b = rng.normal(size=20), rng.normal(size=20)
    r = rng.normal(0.0, 0.1, 20)
    zero = linearised_uncertainty(("a", "b", "c"), np.column_stack([a, b, np.zeros(20)]), r)
    assert zero.not_identified() == ("c",) and np.isnan(zero.standard_errors[2])
    assert np.all(np.isfinite(zero.standard_errors[:2]) & (zero.standard_errors[:2] > 0))
    twins = linearised_uncertainty(("a", "b", "c"), np.column_stack([a, b, 3.0 * b]), r)
    assert twins.not_identified() == ("b", "c") and np.all(np.isnan(twins.standard_errors[1:]))


FORCE_AT_REST = "pressure_bar,contraction_mm,force_N\n" + "".join(
    f"{p:g},0,{23.9 * p - 11.56 + 0.05 * (-1) ** i:.4f}\n" for i, p in enumerate(np.linspace(0.5, 4.0, 12)))
"""A force gauge holding the Shadow muscle at rest only: the terms in x and x^2 are never seen."""


def test_coefficients_the_data_do_not_see_are_reported_as_not_identified(tmp_path):
    data = tmp_path / "at_rest.csv"
    data.write_text(FORCE_AT_REST)
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "-o", out, "--json")
    assert proc.returncode == 0, proc.stderr
    body = json.loads(proc.stdout)
    blind = {"K1_N_per_bar_m2", "K2_N_per_bar_m", "S1_N_per_m2", "S2_N_per_m"}
    assert set(body["not_identified"]) == blind
    assert all(body["standard_errors"][n] is None for n in blind)
    assert body["standard_errors"]["C1_N_per_bar"] > 0 and body["standard_errors"]["S3_N"] > 0
    report = (out / "report.md").read_text()
    assert "the data separate them" not in report
    assert report.count("| not identified |") == 4 and "**Not identified:**" in report


@pytest.mark.parametrize("rows, message", [
    ("2,10,20\n3,20,20\n", "2 tests for 3 free coefficients"),
    ("2,10,20\n3,20,20\n4,25,30\n", "3 tests for 3 free coefficients"),
    ("1,0,90\n2,0.2,120\n3,0,150\n4,0.5,160\n", "every one of the 4 tests is censored"),
])
def test_data_that_cannot_fix_the_coefficients_are_refused(tmp_path, readme_muscle, rows, message):
    data = tmp_path / "few.csv"
    data.write_text("pressure_bar,contraction_mm,weight_N\n" + rows)
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", readme_muscle, "-o", out)
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr and not out.exists()


def test_censored_tests_the_model_does_not_lift_are_no_observations():
    from pamsim.identification.uncertainty import linearised_uncertainty

    rng = np.random.default_rng(1)
    J, r = rng.normal(size=(12, 3)), rng.normal(0.0, 0.5, 12)
    alone = linearised_uncertainty("abc", J, r)
    # Ten censored tests the model does not lift: residual 0, derivatives 0.
    padded = linearised_uncertainty("abc", np.vstack([J, np.zeros((10, 3))]), np.concatenate([r, np.zeros(10)]))
    np.testing.assert_allclose(padded.standard_errors, alone.standard_errors, rtol=1e-12)
    assert padded.dof == alone.dof == 9 and padded.sigma == pytest.approx(np.sqrt(r @ r / 9))


def test_a_long_trace_costs_no_square_matrix_of_its_samples():
    """A dynamic fit's Jacobian has a row per sample: 200,000 rows would be a 298 GiB square matrix,
    which the decomposition must not form.  Fewer rows than coefficients still find the blind ones."""
    from pamsim.identification.uncertainty import linearised_uncertainty

    rng = np.random.default_rng(2)
    J, r = rng.normal(size=(200_000, 3)), rng.normal(0.0, 0.1, 200_000)
    u = linearised_uncertainty("abc", J, r)
    np.testing.assert_allclose(u.standard_errors, 0.1 / np.sqrt(200_000), rtol=0.02)
    wide = linearised_uncertainty("abc", J[:2], r[:2])
    assert len(wide.not_identified()) >= 1 and np.isnan(wide.sigma)


def test_censored_fit_counts_only_the_tests_that_observe(readme_muscle):
    # The README muscle's own tests, half of them too heavy to lift: sigma from the lifted half only.
    from pamsim.identification import fit_static
    from pamsim.identification.muscle_file import load_muscle_parameters
    from pamsim.elements.stops import EndStops
    from pamsim.identification.synthetic import synthetic_static

    params, model = load_muscle_parameters(str(readme_muscle))
    p = np.repeat([1e5, 2e5, 3e5, 4e5], 6)
    w = np.tile([5.0, 15.0, 30.0, 400.0, 500.0, 600.0], 4)
    force = pamsim.load_muscle(readme_muscle).static_force().force_N
    data = synthetic_static(force, p, w, EndStops.from_parameters(params).x_high_m, 0.3e-3, seed=2)
    fit = fit_static(data, params, model=model, cv=None)
    lifted = ~fit.problem.censored
    assert fit.n_censored == 12 and fit.uncertainty.dof == lifted.sum() - 3
    assert fit.uncertainty.sigma == pytest.approx(np.sqrt(fit.residuals @ fit.residuals / (lifted.sum() - 3)))


GOOD_ROWS = ["3.0,20.1,30", "3.5,25.3,30", "4.0,27.9,40", "2.5,12.2,30", "3.0,18.0,40", "4.0,30.5,20", "2.0,6.1,30"]


def fit_rows(tmp_path, muscle, header, change, out):
    """``pamsim fit static`` on GOOD_ROWS under ``header``, with row ``change[0]`` replaced by ``change[1]``."""
    rows = list(GOOD_ROWS)
    if change:
        rows[change[0]] = change[1]
    data = tmp_path / "rig.csv"
    data.write_text(header + "\n" + "\n".join(rows) + "\n")
    return pamsim_cli("fit", "static", data, "--muscle", muscle, "-o", out)


@pytest.mark.parametrize("header, change, message", [
    ("pressure_bar,contraction_mm,weight_N", (2, "-1.5,20.0,30"), "column pressure_bar, data row 3: value -1.5"),
    ("pressure_bar,contraction_mm,weight_N", (5, "3.0,180,40"), "column contraction_mm, data row 6: value 180"),
    ("pressure_bar,contraction_m,weight_N", None, "column contraction_m, data row 1: value 20.1"),
    ("pressure_bar,contraction_mm,weight_N", (0, "300000,20.1,30"), "column pressure_bar, data row 1: value 300000"),
])
def test_impossible_values_are_refused_by_column_row_and_value(tmp_path, readme_muscle, header, change, message):
    out = tmp_path / "fit"
    proc = fit_rows(tmp_path, readme_muscle, header, change, out)
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr and not out.exists()


@pytest.mark.parametrize("header, change, message", [
    ("pressure_Pa,contraction_mm,weight_N", None, "column pressure_Pa, data row 3: value 4: every pressure is below 1 kPa"),
    ("pressure_bar,contraction_mm,weight_N", (1, "3.5,25.3,3000"), "column weight_N, data row 2: value 3000: more than twice"),
    ("pressure_bar,contraction_mm,weight_N", (3, "2.5,-4,30"), "column contraction_mm, data row 4: value -4"),
    ("pressure_bar,contraction_mm,weight_N", (4, "3.5,25.3,30"), "data rows 2, 5: repeated tests"),
    ("pressure_bar,contraction_mm,weight_N", (4, "7,25.3,30"), "column pressure_bar, data row 5: value 7: above the muscle's rated"),
])
def test_implausible_values_are_one_warning_line(tmp_path, readme_muscle, header, change, message):
    proc = fit_rows(tmp_path, readme_muscle, header, change, tmp_path / "fit")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: ") and message in lines[0], proc.stderr
    assert "RuntimeWarning" not in proc.stderr


def test_repeated_tests_stay_in_one_fold():
    from pamsim.identification.crossval import folds

    groups = np.array([0, 1, 2, 1, 3, 2, 4])
    _, loo = folds(7, "loo", 0, 0, groups)
    assert sorted(map(tuple, loo)) == [(0,), (1, 3), (2, 5), (4,), (6,)]
    _, kfold = folds(7, "kfold", 3, 5, groups)
    assert sorted(np.concatenate(kfold)) == list(range(7))
    for part in kfold:
        assert all(set(np.flatnonzero(groups == groups[i])) <= set(part) for i in part)


def test_overflow_at_trial_points_does_not_reach_the_user():
    import warnings

    from pamsim.identification import fit_static, read_static_data

    data = read_static_data(ROOT / "pamsim" / "data" / "acra2012_steady_state.csv")
    start = pamsim.get_parameter_set("shadow_6x300_acra2012").with_overrides(
        {"S1_N_per_m2": 1e306, "K1_N_per_bar_m2": 1e306})  # squares overflow to inf
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit_static(data, start, cv=None)
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)]
