"""Model comparison ranked by AIC with Akaike weights, and per-test standard deviations (a ``sigma``
column) in static fits: weighted least squares against its closed form, bad values refused by column,
row and value."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

import pamsim
from pamsim.elements.static_force import Acra2012Polynomial
from pamsim.errors import InputError
from pamsim.identification import fit_static, read_static_data
from pamsim.identification.columns import DataError
from pamsim.identification.compare import akaike_weights, comparison_rows, compare_models

from conftest import ROOT, run_main

DATA = ROOT / "pamsim" / "data" / "acra2012_steady_state.csv"
PAPER = pamsim.get_parameter_set("shadow_6x300_acra2012")
PRINTED = (-476.95, -188.39, 23.90, 2562.4, -245.48, -11.56)
COEFFS = ("K1_N_per_bar_m2", "K2_N_per_bar_m", "C1_N_per_bar", "S1_N_per_m2", "S2_N_per_m", "S3_N")


def test_akaike_weights_against_hand_values():
    delta, w = akaike_weights([12.0, 10.0, math.inf])
    assert delta[:2] == [2.0, 0.0] and math.isnan(delta[2])
    e = math.exp(-1.0)
    assert w[0] == pytest.approx(e / (1 + e)) and w[1] == pytest.approx(1 / (1 + e)) and math.isnan(w[2])
    assert all(math.isnan(v) for v in akaike_weights([math.nan, -math.inf])[1])


@pytest.fixture(scope="module")
def compared():
    data = read_static_data(DATA)
    fits = compare_models(data, PAPER, ["gaylord", "acra2012_polynomial"], cv=None, intervals=False)
    return fits, comparison_rows(fits)


def test_compare_ranks_by_aic_with_akaike_weights(compared):
    fits, rows = compared
    aic = {f.problem.model: f.aic for f in fits}
    best = min(aic.values())
    rel = {m: math.exp(-(a - best) / 2) for m, a in aic.items()}
    assert [r["model"] for r in rows] == sorted(aic, key=aic.get)
    assert [r["rank"] for r in rows] == [1, 2]
    for r in rows:
        assert r["delta_aic"] == pytest.approx(aic[r["model"]] - best)
        assert r["akaike_weight"] == pytest.approx(rel[r["model"]] / sum(rel.values()))
    assert rows[0]["model"] == "acra2012_polynomial" and rows[0]["delta_aic"] == 0.0


def test_cli_compare_writes_the_ranking(tmp_path):
    out = tmp_path / "cmp"
    proc = run_main("fit", "static", DATA, "--cv", "none", "--compare", "gaylord,acra2012_polynomial", "-o", out,
                    "--json")
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.DictReader((out / "compare.csv").open()))
    assert [r["rank"] for r in rows] == ["1", "2"] and rows[0]["model"] == "acra2012_polynomial"
    assert float(rows[0]["delta_aic"]) == 0.0 and float(rows[1]["delta_aic"]) > 0
    assert sum(float(r["akaike_weight"]) for r in rows) == pytest.approx(1.0, abs=1e-5)
    assert [r["model"] for r in json.loads(proc.stdout)["compare"]] == ["acra2012_polynomial", "gaylord"]
    report = (out / "report.md").read_text()
    assert "| rank | model |" in report and "ΔAIC" in report and "Akaike weight" in report


def gauge_file(tmp_path, sigma, name="sigma_N", seed=1):
    """Force-gauge tests of the paper's polynomial with noise of the given per-test standard deviation."""
    p_bar = np.repeat(np.linspace(0.5, 4.0, 5), 6)
    x = np.tile(np.linspace(0.0, 0.05, 6), 5)
    sigma = np.broadcast_to(np.asarray(sigma, dtype=float), x.shape)
    f = Acra2012Polynomial(*PRINTED).force_N(x, p_bar * 1e5)
    f = f + np.random.default_rng(seed).normal(0.0, 1.0, x.size) * np.where(np.isfinite(sigma), np.abs(sigma), 0.1)
    path = tmp_path / "gauge.csv"
    rows = "\n".join(f"{a:.6g},{b * 1e3:.6g},{c:.9g},{s:g}" for a, b, c, s in zip(p_bar, x, f, sigma))
    path.write_text(f"pressure_bar,contraction_mm,force_N,{name}\n{rows}\n")
    return path


def test_sigma_weights_the_fit_as_closed_form_weighted_least_squares(tmp_path):
    sigma = np.where(np.arange(30) % 3 == 0, 0.5, 0.02)  # a third of the tests 25 times noisier
    data = read_static_data(gauge_file(tmp_path, sigma))
    fit = fit_static(data, PAPER, cv=None)
    # the closed form, written apart from the fit: the polynomial is linear in its six coefficients
    p, x = data.pressure_gauge_Pa / 1e5, data.contraction_m
    X = np.column_stack([x ** 2 * p, x * p, p, x ** 2, x, np.ones_like(x)]) / sigma[:, None]
    y = data.load_N / sigma
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ beta
    cov = (r @ r) / (len(y) - 6) * np.linalg.inv(X.T @ X)
    assert fit.theta == pytest.approx(beta, rel=1e-6)
    assert fit.uncertainty.standard_errors == pytest.approx(np.sqrt(np.diag(cov)), rel=1e-4)
    unweighted = fit_static(read_static_data(gauge_file(tmp_path, sigma, name="note_N")), PAPER, cv=None)
    assert not np.allclose(unweighted.theta, fit.theta, rtol=1e-3)


@pytest.mark.parametrize("bad, shown", [(0.0, "value 0 must be positive"), (-0.1, "value -0.1 must be positive"),
                                        (math.nan, "value nan is not finite"), (math.inf, "value inf is not finite")])
def test_bad_sigma_is_refused_by_column_row_and_value(tmp_path, bad, shown):
    sigma = np.full(30, 0.05)
    sigma[7] = bad
    path = gauge_file(tmp_path, sigma)
    with pytest.raises(DataError, match="column sigma_N, data row 8: " + shown):
        read_static_data(path)
    out = tmp_path / "never"
    proc = run_main("fit", "static", path, "-o", out)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "sigma_N, data row 8" in proc.stderr
    assert "Traceback" not in proc.stderr and not out.exists()


def test_a_sigma_of_the_other_objectives_quantity_is_refused(tmp_path):
    data = read_static_data(gauge_file(tmp_path, 0.05, name="sigma_mm"))
    assert data.sigma_kind == "contraction" and data.sigma == pytest.approx(np.full(30, 0.05e-3))
    with pytest.raises(InputError, match="column sigma_mm is the standard deviation of each test's contraction, "
                                         "but the force objective's residuals are forces: give sigma_N"):
        fit_static(data, PAPER, cv=None)
