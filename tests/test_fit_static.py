"""Static identification against the ACRA 2012 paper's numbers and independent solutions.

The equilibrium check solves the paper's polynomial in closed form here (the smaller root of a
quadratic), independently of the grid-and-bisection code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import pamsim
from pamsim.elements.static_force import Acra2012Polynomial
from pamsim.errors import InputError
from pamsim.identification import fit_static, read_static_data
from pamsim.identification.columns import DataError, StaticData
from pamsim.identification.equilibrium import equilibrium_m
from pamsim.identification.muscle_file import load_muscle_parameters, muscle_toml
from pamsim.muscles import MuscleError
from pamsim.identification.static_fit import make_problem
from pamsim.paperdata import acra2012_steady_state

from conftest import ROOT

DATA = ROOT / "pamsim" / "data" / "acra2012_steady_state.csv"
PAPER = pamsim.get_parameter_set("shadow_6x300_acra2012")
COEFFS = ("K1_N_per_bar_m2", "K2_N_per_bar_m", "C1_N_per_bar", "S1_N_per_m2", "S2_N_per_m", "S3_N")
PRINTED = (-476.95, -188.39, 23.90, 2562.4, -245.48, -11.56)  # paper eq. (11)
TRAINING = [(2.8, 12.74), (2.0, 22.74), (3.6, 22.74), (3.6, 32.74), (4.0, 42.74), (4.0, 52.74)]
"""The paper's six training tests (its text, sec. 3.2; weights with the 2.74 N holder)."""
X_MAX_M = 0.300 - 0.300 / math.cos(math.radians(20.0)) / math.sqrt(3.0)  # braid lock of the Shadow muscle


def quadratic_equilibrium_m(c, p_bar, w_N, x_max=X_MAX_M):
    """Smallest x in [0, x_max] where (K1 x^2 + K2 x + C1) P + S1 x^2 + S2 x + S3 falls through W.

    With a = K1 P + S1 > 0 (true for the paper's coefficients and the fits below) the force is a
    convex parabola: it falls through W at its smaller root, if F(0) > W and the root exists.
    """
    K1, K2, C1, S1, S2, S3 = c
    a = K1 * p_bar + S1
    b = K2 * p_bar + S2
    c0 = C1 * p_bar + S3 - w_N
    assert np.all(a > 0)
    disc = b * b - 4 * a * c0
    root = np.where(disc >= 0, 2 * c0 / (-b + np.sqrt(np.maximum(disc, 0.0))), np.inf)  # stable form of the smaller root
    x = np.where(c0 <= 0, 0.0, np.where(disc < 0, x_max, np.minimum(root, x_max)))
    return x


@pytest.fixture(scope="module")
def data():
    return read_static_data(DATA)


@pytest.fixture(scope="module")
def measured():
    raw = acra2012_steady_state()
    return raw["pressure_stable_bar"], raw["weight_N"], raw["contraction_stable_mm"] * 1e-3


@pytest.fixture(scope="module")
def within(measured):
    """The 28 within-capability tests: equilibrium of the paper's coefficients at least 5 mm
    (the definition of docs/validation.md)."""
    p, w, _ = measured
    return quadratic_equilibrium_m(PRINTED, p, w) >= 5e-3


def _rms_mm(c, measured, rows=slice(None)):
    p, w, x = measured
    return float(np.sqrt(np.mean(((quadratic_equilibrium_m(c, p, w) - x)[rows] * 1e3) ** 2)))


def test_reference_figures_of_the_printed_coefficients(measured, within):
    # The targets 3.21 mm and 1.65 mm of the issue, recomputed from the printed coefficients.
    assert within.sum() == 28
    assert _rms_mm(PRINTED, measured) == pytest.approx(3.21, abs=0.005)
    assert _rms_mm(PRINTED, measured, within) == pytest.approx(1.65, abs=0.005)


def test_vectorised_equilibrium_matches_the_closed_form(measured):
    rng = np.random.default_rng(1)
    p_bar = rng.uniform(0.3, 4.1, 500)
    w = rng.uniform(5.0, 80.0, 500)
    force = Acra2012Polynomial(*PRINTED).force_N
    got = equilibrium_m(force, p_bar * 1e5, w, X_MAX_M)
    np.testing.assert_allclose(got, quadratic_equilibrium_m(PRINTED, p_bar, w), atol=1e-12)
    assert (got == 0).any() and (got > 0).any()


def test_force_objective_reproduces_the_six_training_weights(data):
    raw = acra2012_steady_state()
    rows = np.array([int(np.flatnonzero((raw["pressure_step_bar"] == p) & (raw["weight_N"] == w))[0])
                     for p, w in TRAINING])
    train = data.subset(rows)
    fit = fit_static(train, PAPER, objective="force", cv="loo", exact=True)
    c = [fit.parameters[n] for n in COEFFS]
    x, p, W = train.contraction_m, train.pressure_gauge_Pa / 1e5, train.load_N
    F = (c[0] * x ** 2 + c[1] * x + c[2]) * p + c[3] * x ** 2 + c[4] * x + c[5]
    assert np.max(np.abs(F - W)) < 1e-6
    # A second implementation: the 6 x 6 linear system of eq. (10).
    A = np.column_stack([x ** 2 * p, x * p, p, x ** 2, x, np.ones_like(x)])
    np.testing.assert_allclose(c, np.linalg.solve(A, W), rtol=1e-6)
    # The printed coefficients hold the same six tests only to about 0.02 N (they were rounded).
    F_printed = A @ np.array(PRINTED)
    assert 1e-3 < np.max(np.abs(F_printed - W)) < 0.05
    assert fit.cv_kind.startswith("none")  # five tests cannot fix six coefficients
    assert math.isnan(fit.uncertainty.standard_errors[0])  # no degrees of freedom left


@pytest.fixture(scope="module")
def robust_fit(data):
    return fit_static(data, PAPER, objective="contraction", loss="soft_l1", f_scale=1.0, cv="kfold", k_folds=11)


def test_contraction_objective_beats_the_printed_coefficients(robust_fit, measured, within):
    c = [robust_fit.parameters[n] for n in COEFFS]
    rms_all = _rms_mm(c, measured)
    rms_within = _rms_mm(c, measured, within)
    assert rms_all < 3.21
    assert rms_within < 1.65
    # The fit reports the same RMS as the independent solution.
    assert robust_fit.rms_contraction_mm == pytest.approx(rms_all, abs=1e-6)
    # Cross-validated error: worse than the fit's own, but still better than the printed coefficients.
    assert rms_all < robust_fit.cv_rms_contraction_mm < 3.21
    assert robust_fit.cv_kind == "11-fold"
    assert robust_fit.n_censored == 6 and robust_fit.n_points == 66


def test_plain_least_squares_beats_the_66_rms(data, measured):
    fit = fit_static(data, PAPER, cv=None)
    assert _rms_mm([fit.parameters[n] for n in COEFFS], measured) < 3.21


@pytest.mark.xfail(strict=True, reason="plain least squares (linear loss) over all 66 gives 1.73 mm on the 28 "
                                       "within-capability tests; the robust soft_l1 loss meets 1.65 mm")
def test_plain_least_squares_beats_the_28_rms(data, measured, within):
    fit = fit_static(data, PAPER, cv=None)
    assert _rms_mm([fit.parameters[n] for n in COEFFS], measured, within) < 1.65


def test_standard_errors_match_linear_regression(data):
    # The force objective is linear in the coefficients: ordinary least squares gives the covariance.
    lifted = data.subset(data.contraction_m > 0.5e-3)
    fit = fit_static(lifted, PAPER, objective="force", cv=None)
    x, p, W = lifted.contraction_m, lifted.pressure_gauge_Pa / 1e5, lifted.load_N
    A = np.column_stack([x ** 2 * p, x * p, p, x ** 2, x, np.ones_like(x)])
    beta, *_ = np.linalg.lstsq(A, W, rcond=None)
    r = W - A @ beta
    cov = (r @ r) / (len(W) - 6) * np.linalg.inv(A.T @ A)
    np.testing.assert_allclose([fit.parameters[n] for n in COEFFS], beta, rtol=1e-6)
    np.testing.assert_allclose(fit.uncertainty.standard_errors, np.sqrt(np.diag(cov)), rtol=1e-4)
    corr = cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    np.testing.assert_allclose(fit.uncertainty.correlation, corr, atol=1e-4)
    assert fit.rms_force_N == pytest.approx(np.sqrt(np.mean(r ** 2)), rel=1e-6)


def test_censored_rows_only_penalise_a_predicted_lift():
    # Three tests; the third was not lifted (0.2 mm <= 0.5 mm).
    c = np.array(PRINTED)
    p_bar = np.array([3.6, 4.0, 1.0])
    w = np.array([22.74, 42.74, 40.0])
    x = quadratic_equilibrium_m(c, p_bar, w)
    x[2] = 0.2e-3
    d = StaticData(p_bar * 1e5, x, w, "weight")
    prob = make_problem(d, PAPER, objective="contraction")
    r = prob.residuals(c)
    assert r[2] == 0.0  # the model cannot lift 40 N at 1 bar: no penalty
    np.testing.assert_allclose(r[:2], 0.0, atol=1e-9)
    d_lifting = StaticData(np.array([4.0]) * 1e5, np.array([0.1e-3]), np.array([12.74]), "weight")
    r2 = make_problem(d_lifting, PAPER, objective="contraction").residuals(c)
    x_pred = quadratic_equilibrium_m(c, np.array([4.0]), np.array([12.74]))[0]
    assert r2[0] == pytest.approx((x_pred - 0.5e-3) * 1e3, rel=1e-9)


def test_implicit_jacobian_matches_differences_of_the_equilibrium(data):
    prob = make_problem(data, PAPER, objective="contraction")
    theta = np.array(PRINTED)
    J = prob.jacobian(theta)
    for j in range(6):
        h = 1e-4 * abs(theta[j])
        tp, tm = theta.copy(), theta.copy()
        tp[j] += h
        tm[j] -= h
        fd = (prob.residuals(tp) - prob.residuals(tm)) / (2 * h)
        np.testing.assert_allclose(J[:, j], fd, rtol=1e-4, atol=1e-9 * np.abs(fd).max())


def test_multistart_and_robust_options_are_checked(data):
    with pytest.raises(InputError, match="--loss"):
        fit_static(data, PAPER, loss="l3")
    with pytest.raises(InputError, match="--free"):
        fit_static(data, PAPER, free=["K9"])
    with pytest.raises(InputError, match="--model"):
        fit_static(data, PAPER, model="acra2012_polynomal")
    fit = fit_static(data, PAPER, n_starts=2, seed=3, cv=None)
    again = fit_static(data, PAPER, n_starts=2, seed=3, cv=None)
    np.testing.assert_array_equal(fit.theta, again.theta)  # seeded: reproducible


def test_readers_convert_units_and_map_columns(tmp_path):
    f = tmp_path / "rig.csv"
    f.write_text("# my rig\nload_weight_N,p_meas_kPa,x_mm\n# comment\n20,300,10\n30,350.5,12\n")
    d = read_static_data(f, {"pressure": "p_meas_kPa", "weight": "load_weight_N", "contraction": "x_mm"})
    np.testing.assert_allclose(d.pressure_gauge_Pa, [3e5, 3.505e5])
    np.testing.assert_allclose(d.contraction_m, [0.010, 0.012])
    assert d.kind == "weight" and len(d.sha256) == 64
    g = tmp_path / "psi.csv"
    g.write_text("pressure_psi,contraction_m,force_N\n50,0.01,20\n")
    d = read_static_data(g)
    assert d.pressure_gauge_Pa[0] == pytest.approx(50 * 0.45359237 * 9.80665 / 0.0254 ** 2)
    assert d.kind == "force"


@pytest.mark.parametrize("text, match", [
    ("pressure_bar,contraction_mm\n1,2\n", "need exactly one of a force_N"),
    ("pressure_bar,contraction_mm,weight_N\n1,abc,3\n", "line 2, column 'contraction_mm': value 'abc' is not a number"),
    ("pressure_bar,contraction_mm,weight_N\n1,2\n", "line 2 has 2 fields"),
    ("pressure_bar,contraction_mm,weight_N\n1,2,-3\n", "weight_N, data row 1: value -3"),
    ("pressure_atm,contraction_mm,weight_N\n1,2,3\n", "no pressure column"),
])
def test_reader_errors_name_file_column_and_value(tmp_path, text, match):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(DataError, match=match) as info:
        read_static_data(f)
    assert str(f) in str(info.value)


def test_muscle_file_round_trip(tmp_path, robust_fit):
    text = muscle_toml(robust_fit.fitted, "fitted", "d", "c", "acra2012_polynomial", {"objective": "contraction"})
    path = tmp_path / "muscle.toml"
    path.write_text(text)
    params, model = load_muscle_parameters(str(path))
    assert model == "acra2012_polynomial"
    for n in COEFFS:
        assert params[n] == robust_fit.parameters[n]
        assert params.entries[n].source.startswith("fitted:")
    assert params["L0_m"] == PAPER["L0_m"]
    # The library loader reads it: the muscle's own model built from it gives the fitted force.
    muscle = pamsim.load_muscle(path)
    x, p = np.array([0.0, 0.03]), np.array([2e5, 4e5])
    np.testing.assert_allclose(muscle.static_force().force_N(x, p),
                               robust_fit.problem.force(robust_fit.theta).force_N(x, p), rtol=1e-12)
    path.write_text(text.replace("[parameters.S3_N]", "[parameters.S3_Nx]"))
    with pytest.raises(MuscleError, match="S3_Nx"):
        load_muscle_parameters(str(path))


def test_a_muscle_files_own_parameters_fit_as_the_command_fits_them():
    """``fit_static(data, pamsim.load_muscle(name).parameters, ...)``, the Python path the docs give, stopped
    with a KeyError ('stop_restitution', a dynamics value a muscle file leaves to pamsim's defaults); it now
    fits as ``pamsim fit static --muscle name`` does, to the same coefficients."""
    from pamsim.identification.synthetic import synthetic_static

    muscle = pamsim.load_muscle("kothera2009_5a")
    own = muscle.parameters
    assert "stop_restitution" not in own
    p, w = np.meshgrid([1.0e5, 2.0e5, 3.0e5, 4.0e5], [10.0, 20.0, 30.0])
    tests = synthetic_static(muscle.static_force().force_N, p.ravel(), w.ravel(), 0.02, noise_m=0.1e-3, seed=3)
    direct = fit_static(tests, own, model=muscle.default_static_force, free=["r0_m", "theta0_deg"], cv="none")
    params, model = load_muscle_parameters("kothera2009_5a")
    command = fit_static(tests, params, model=model, free=["r0_m", "theta0_deg"], cv="none")
    assert direct.parameters == command.parameters
    assert direct.rms_contraction_mm == command.rms_contraction_mm < 0.2


def test_a_failed_write_leaves_no_folder(tmp_path, robust_fit, monkeypatch):
    from pamsim.identification import report

    def broken(*args, **kwargs):
        raise RuntimeError("plotting failed")

    monkeypatch.setattr(report, "plot_correlation", broken)
    out = tmp_path / "new"
    with pytest.raises(RuntimeError):
        report.write_static_fit(robust_fit, out)
    assert not out.exists()


def test_force_gauge_data_fit_by_the_force_objective():
    # A force gauge at fixed lengths: the paper's polynomial plus 0.05 N of seeded noise.
    rng = np.random.default_rng(7)
    p_bar = np.repeat(np.linspace(0.5, 4.0, 8), 10)
    x = np.tile(np.linspace(0.0, 0.05, 10), 8)
    K1, K2, C1, S1, S2, S3 = PRINTED
    F = (K1 * x ** 2 + K2 * x + C1) * p_bar + S1 * x ** 2 + S2 * x + S3 + rng.normal(0.0, 0.05, x.size)
    data = StaticData(p_bar * 1e5, x, F, "force")
    start = PAPER.with_overrides({n: 0.8 * v for n, v in zip(COEFFS, PRINTED)})
    fit = fit_static(data, start, cv="loo")
    assert fit.problem.objective == "force" and fit.n_censored == 0
    assert fit.uncertainty.sigma == pytest.approx(0.05, rel=0.2)
    for n, true, se in zip(COEFFS, PRINTED, fit.uncertainty.standard_errors):
        assert abs(fit.parameters[n] - true) < 4 * se, n
    assert fit.cv_kind == "leave-one-out" and np.isfinite(fit.cv_rms_contraction_mm)
