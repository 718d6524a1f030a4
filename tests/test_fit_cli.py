"""``pamsim fit static`` and ``pamsim fit dynamic`` as a user runs them.

The commands run in this process (``main(argv)``); one bad-input case of ``fit static`` goes
through a real ``python -m pamsim`` subprocess, for the exit code and the absence of a traceback as
a user sees them.
"""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

import pamsim
from pamsim.identification.columns import write_trace_csv
from pamsim.identification.synthetic import synthetic_trace

from conftest import ROOT, SCENARIOS
from conftest import run_cli, run_main as pamsim_cli
from test_fit_static_limits import check_fitted_muscle_loads

DATA = ROOT / "pamsim" / "data" / "acra2012_steady_state.csv"
FIT_KEYS = {"model", "muscle", "objective", "parameters", "standard_errors", "correlation", "rms_force_N",
            "rms_contraction_mm", "cv_rms_contraction_mm", "cv_kind", "n_points", "n_censored"}


@pytest.fixture(scope="module")
def static_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("fit") / "static"
    proc = pamsim_cli("fit", "static", DATA, "--loss", "soft_l1", "--cv", "kfold", "--folds", "6",
                      "--compare", "acra2012_polynomial", "-o", out, "--json")
    assert proc.returncode == 0, proc.stderr
    return out, json.loads(proc.stdout)


def test_fit_static_writes_the_issue_outputs(static_out):
    out, body = static_out
    assert FIT_KEYS <= set(body)
    assert body["n_points"] == 66 and body["n_censored"] == 6 and body["objective"] == "contraction"
    assert body["cv_kind"] == "6-fold" and body["rms_contraction_mm"] < body["cv_rms_contraction_mm"]
    assert json.loads((out / "fit.json").read_text())["parameters"] == body["parameters"]
    for name in ("muscle.toml", "data.csv", "report.md", "fit.png", "residuals.png", "correlation.png",
                 "compare.csv", "compare.png"):
        assert (out / name).stat().st_size > 0, name
    corr = body["correlation"]
    assert len(corr["names"]) == 6 and np.allclose(np.diag(corr["matrix"]), 1.0)
    assert "acra2012_polynomial" in (out / "compare.csv").read_text()


def test_fitted_muscle_file_carries_provenance_and_is_reusable(static_out, tmp_path):
    out, body = static_out
    text = (out / "muscle.toml").read_text()
    spec = tomllib.loads(text)
    assert spec["default_static_force"] == "acra2012_polynomial"
    assert spec["parameters"]["C1_N_per_bar"]["value"] == body["parameters"]["C1_N_per_bar"]
    assert "sha256" in text and body["data_sha256"] in text and "objective: contraction" in text
    assert (out / "data.csv").read_bytes() == DATA.read_bytes()
    # Used as the starting muscle of another fit: it starts at the optimum and stays there.
    proc = pamsim_cli("fit", "static", DATA, "--muscle", out / "muscle.toml", "--loss", "soft_l1", "--cv", "none",
                      "-o", tmp_path / "again", "--json")
    assert proc.returncode == 0, proc.stderr
    again = json.loads(proc.stdout)
    for k, v in body["parameters"].items():
        assert again["parameters"][k] == pytest.approx(v, rel=1e-4)


@pytest.mark.parametrize("args, message, run", [
    (["--columns", "pressure=nope_bar"], "--columns pressure=nope_bar: no such column", run_cli),
    (["--model", "acra2012_polynomal"], "did you mean 'acra2012_polynomial'", pamsim_cli),
    (["--muscle", "no/such/muscle.toml"], "no/such/muscle.toml: no such muscle file", pamsim_cli),
], ids=["columns-subprocess", "model", "muscle"])
def test_fit_static_bad_input_is_one_line_and_leaves_nothing(tmp_path, args, message, run):
    out = tmp_path / "never"
    proc = run("fit", "static", DATA, *args, "-o", out)
    assert proc.returncode == 2
    assert message in proc.stderr and proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert not out.exists()


@pytest.mark.parametrize("workers", ["1", "2"])  # in this process, and on a pool of worker processes
def test_fit_dynamic_cli_recovers_friction_from_a_recorded_trace(tmp_path, workers):
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    noisy, clean = synthetic_trace(sc, {"N0_N_per_bar": 6.0}, 22.74, duration_s=2.0, seed=4)
    trace = tmp_path / "step.csv"
    write_trace_csv(noisy, trace)
    out = tmp_path / "dyn"
    proc = pamsim_cli("fit", "dynamic", trace, "--scenario", SCENARIOS / "acra2012_fig4.toml", "--free",
                      "N0_N_per_bar", "--window", "0.9:2.0", "--workers", workers, "-o", out, "--json")
    assert proc.returncode == 0, proc.stderr
    body = json.loads(proc.stdout)
    assert {"parameters", "standard_errors", "correlation", "rms_contraction_mm", "n_simulations",
            "wall_time_s"} <= set(body)
    assert body["parameters"]["N0_N_per_bar"] == pytest.approx(6.0, rel=0.02)
    assert set(body["rms_contraction_mm"]) == {"per_trace", "pooled"}
    assert body["rms_contraction_mm"]["pooled"] == pytest.approx(0.05, rel=0.15)
    for name in ("fit.json", "muscle.toml", "scenario.toml", "report.md", "fit.png", "correlation.png"):
        assert (out / name).stat().st_size > 0, name
    # The written scenario runs, and with the fitted coefficient reproduces the clean trace.
    res = pamsim.simulate(pamsim.load_scenario(out / "scenario.toml").with_changes({"simulation": {"duration_s": 2.0}}))
    assert np.sqrt(np.mean((res.x_m - clean.x_m) ** 2)) < 0.1e-3


@pytest.mark.parametrize("args, message", [
    (["--load-N", "1,2"], "--load-N: 2 values for 1 traces"),
    (["--free", "N9"], "--free: 'N9'"),
])
def test_fit_dynamic_bad_input(tmp_path, args, message):
    trace = tmp_path / "t.csv"
    trace.write_text("t_s,x_mm\n0,0\n0.1,1\n0.2,2\n")
    out = tmp_path / "never"
    proc = pamsim_cli("fit", "dynamic", trace, "--scenario", SCENARIOS / "acra2012_fig4.toml", *args, "-o", out)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr and "Traceback" not in proc.stderr
    assert not out.exists()


def test_fitted_muscle_works_as_muscle_everywhere(static_out):
    out, body = static_out
    c = body["parameters"]
    p_bar, w = 3.6, 22.74
    a = c["K1_N_per_bar_m2"] * p_bar + c["S1_N_per_m2"]
    b = c["K2_N_per_bar_m"] * p_bar + c["S2_N_per_m"]
    c0 = c["C1_N_per_bar"] * p_bar + c["S3_N"] - w
    x_expected = 2 * c0 / (-b + np.sqrt(b * b - 4 * a * c0))  # smaller root of the fitted quadratic
    proc = pamsim_cli("static", "--muscle", out / "muscle.toml", "--pressure-bar", p_bar, "--load-N", w, "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["equilibrium_contraction_m"] == pytest.approx(x_expected, abs=1e-9)
    sc = pamsim.Scenario.from_dict({"model": {"muscle": str(out / "muscle.toml")}, "load": {"weight_N": w},
                                    "pressure": {"source": "valve", "supply_gauge_bar": p_bar, "valve_open_time_s": 1.0},
                                    "simulation": {"duration_s": 1.0}})
    assert sc.parameters["C1_N_per_bar"] == c["C1_N_per_bar"]
    # ...with the source muscle's upper stop, the braid lock its file names (not the default it would get
    # without the table: the end of the polynomial's fitted range).
    check_fitted_muscle_loads(out, pamsim.load_muscle("shadow_6x300_acra2012"))
    assert sc.build_model().stops.upper_basis == "braid_lock"


def test_the_fit_command_module_imports_no_numerical_code():
    import subprocess
    import sys

    probe = ("import sys, pamsim.atomic\nbefore = set(sys.modules)\nimport pamsim.cli.fit\n"
             "new = [m for m in set(sys.modules) - before if m.startswith(('numpy', 'scipy', 'matplotlib'))]\n"
             "print(sorted(new))")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert r.stdout.strip() == "[]", r.stdout + r.stderr
