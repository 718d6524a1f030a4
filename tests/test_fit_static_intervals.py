"""Profile-likelihood intervals of static fits, beside the Wald ones: the same where the residuals are
linear in the coefficients, and, where they are not, the interval a second, brute-force profile (a
one-dimensional refit by bounded scalar minimisation, roots by bisection) finds.  Their coverage over
200 synthetic fits per setting is measured by ``python benchmarks/coverage_static.py`` (too slow for
the suite)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar
from scipy.stats import t as student_t

import pamsim
from pamsim.elements.static_force import Acra2012Polynomial
from pamsim.identification import fit_static, read_static_data
from pamsim.identification.columns import StaticData
from pamsim.identification.report import static_report_md

from conftest import ROOT

DATA = ROOT / "pamsim" / "data" / "acra2012_steady_state.csv"
PAPER = pamsim.get_parameter_set("shadow_6x300_acra2012")
PRINTED = (-476.95, -188.39, 23.90, 2562.4, -245.48, -11.56)


def gauge_data(seed=0):
    """A force gauge at fixed lengths: the force objective is linear in the six coefficients."""
    p_bar = np.repeat(np.linspace(0.5, 4.0, 6), 6)
    x = np.tile(np.linspace(0.0, 0.05, 6), 6)
    force = Acra2012Polynomial(*PRINTED).force_N(x, p_bar * 1e5)
    noise = np.random.default_rng(seed).normal(0.0, 0.05, x.size)
    return StaticData(p_bar * 1e5, x, force + noise, "force", "gauge")


def test_profile_intervals_are_the_wald_ones_for_linear_residuals():
    fit = fit_static(gauge_data(), PAPER, cv=None)
    half = fit.wald_95[:, 1] - fit.theta
    t = student_t.ppf(0.975, len(fit.problem.data) - 6)
    assert half == pytest.approx(t * fit.uncertainty.standard_errors, rel=1e-12)
    assert fit.profile_95 == pytest.approx(fit.wald_95, abs=1e-3 * half.min())


@pytest.fixture(scope="module")
def two_free():
    """K1 and C1 of the paper's polynomial refitted to the 66 ACRA tests by their equilibria (nonlinear,
    censored)."""
    return fit_static(read_static_data(DATA), PAPER, free=["K1_N_per_bar_m2", "C1_N_per_bar"], cv=None)


def brute_force_profile(fit, j):
    """The profile interval of coefficient j, written apart from pamsim.identification.profile: the other
    coefficient refitted by bounded scalar minimisation of the sum of squares over +-30 standard errors."""
    prob, theta, se = fit.problem, fit.theta, fit.uncertainty.standard_errors
    k = 1 - j
    ssr0 = float(np.sum(prob.residuals(theta) ** 2))
    allowed = student_t.ppf(0.975, fit.uncertainty.dof) ** 2 * ssr0 / fit.uncertainty.dof

    def excess(v):
        def ssr(u):
            th = theta.copy()
            th[j], th[k] = v, u
            return float(np.sum(prob.residuals(th) ** 2))
        best = minimize_scalar(ssr, bounds=(theta[k] - 30 * se[k], theta[k] + 30 * se[k]), method="bounded",
                               options={"xatol": 1e-9 * max(abs(theta[k]), 1.0)})
        return min(best.fun, ssr0 + 10 * allowed) - ssr0 - allowed

    return [brentq(excess, theta[j] - 20 * se[j], theta[j], xtol=1e-6 * se[j]),
            brentq(excess, theta[j], theta[j] + 20 * se[j], xtol=1e-6 * se[j])]


def test_profile_intervals_match_a_brute_force_profile(two_free):
    fit = two_free
    for j in range(2):
        half = fit.profile_95[j, 1] - fit.profile_95[j, 0]
        assert fit.profile_95[j] == pytest.approx(brute_force_profile(fit, j), abs=2e-3 * half)
    # the equilibrium bends: the profile interval is not the Wald one
    assert np.max(np.abs(fit.profile_95 - fit.wald_95) / fit.uncertainty.standard_errors[:, None]) > 0.1


def test_intervals_in_fit_json_and_report(two_free):
    body = json.loads(json.dumps(two_free.to_json()))
    for i, name in enumerate(("K1_N_per_bar_m2", "C1_N_per_bar")):
        assert body["intervals_95"][name]["wald"] == pytest.approx(list(two_free.wald_95[i]))
        assert body["intervals_95"][name]["profile"] == pytest.approx(list(two_free.profile_95[i]))
    md = static_report_md(two_free, None)
    assert "| 95 % Wald | 95 % profile |" in md
    lo, hi = two_free.profile_95[0]
    assert f"[{lo:.4g}, {hi:.4g}]" in md


def test_no_profile_with_a_robust_loss_and_none_where_not_identified():
    fit = fit_static(read_static_data(DATA), PAPER, free=["C1_N_per_bar", "S3_N"], loss="soft_l1", cv=None)
    assert fit.profile_95 is None
    assert all(v["profile"] is None and v["wald"] is not None for v in fit.to_json()["intervals_95"].values())
    # a coefficient the data do not see (the force objective at x = 0 never sees K1 and K2): no interval
    d = gauge_data()
    at_rest = d.subset(d.contraction_m == 0.0)
    blind = fit_static(at_rest, PAPER, free=["K1_N_per_bar_m2", "C1_N_per_bar"], cv=None)
    assert blind.to_json()["intervals_95"]["K1_N_per_bar_m2"] == {"wald": None, "profile": None}
    assert blind.to_json()["intervals_95"]["C1_N_per_bar"]["profile"] is not None
