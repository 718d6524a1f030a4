"""A dynamic fit that never claims more than it found: seeded multistart and a wider global search
escape the local minima of eq. (13), a fit that misses the traces' noise says so, and the physics'
signs bound the coefficients.  Native backend (a local fit takes a few tenths of a second).

Synthetic truth of tests/synthetic_fit.py (three loads, 2.5 s, 0.05 mm noise); the fits start from
zero friction and damping, where a single local fit stalls (the known case), and the RMS at the truth
is the yardstick: a fit that found the optimum matches it.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import pamsim
from pamsim.errors import InputError
from pamsim.identification.dynamic_fit import DEFAULT_STARTS, fit_dynamic, make_problem, make_trials
from pamsim.identification.dynamic_starts import random_points
from pamsim.identification.fit_quality import noise_level_mm, quality_warnings
from pamsim.identification.columns import write_trace_csv
from pamsim.identification.synthetic import synthetic_trace

from conftest import SCENARIOS, run_main
from synthetic_fit import FREE, NOISE_M, traces, truth_vector

LOADS_N = (12.74, 22.74, 32.74)


@pytest.fixture(scope="module")
def scenario():
    return pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")


@pytest.fixture(scope="module")
def from_zero(scenario):
    """The scenario with no friction and no damping (a muscle file's defaults for friction), the three
    noisy traces of the truth, and the pooled RMS [mm] at the truth."""
    zero = scenario.with_changes({"parameters": dict.fromkeys(FREE, 0.0)})
    noisy = [n for n, _ in traces(scenario, LOADS_N)]
    prob = make_problem(zero, noisy, free=FREE)
    r = prob.residuals_from(make_trials(prob, "native")(truth_vector()))
    return zero, noisy, float(np.sqrt(np.mean(r ** 2)))


def test_a_single_start_from_zero_friction_stalls_and_says_so(from_zero):
    zero, noisy, rms_truth = from_zero
    fit = fit_dynamic(zero, noisy, free=FREE, backend="native", n_starts=0)
    assert fit.rms_pooled_mm > 5 * rms_truth  # the known local minimum
    assert not fit.success
    body = fit.to_json()
    assert body["success"] is False and body["n_starts"] == 0
    assert any("times the traces' noise" in w for w in body["warnings"])
    assert all(v == pytest.approx(NOISE_M * 1e3, rel=0.06) for v in body["noise_mm"].values())


def test_the_native_default_multistart_reaches_the_noise_from_zero_friction(from_zero):
    zero, noisy, rms_truth = from_zero
    assert DEFAULT_STARTS["native"] > 0
    fit = fit_dynamic(zero, noisy, free=FREE, backend="native")
    assert fit.n_starts == DEFAULT_STARTS["native"]
    assert fit.rms_pooled_mm <= 1.01 * rms_truth
    assert fit.success and fit.warnings == []
    assert fit.theta == pytest.approx(truth_vector(), rel=0.02)
    again = fit_dynamic(zero, noisy, free=FREE, backend="native")
    assert np.array_equal(again.theta, fit.theta)  # seeded: the same starts, the same numbers


def test_the_global_search_reaches_the_noise_from_zero_friction(scenario):
    """A parameter set where eight screened random starts from zero stop at 1.22 times the truth's RMS (a
    minimum behind a low ridge of the stick/slip events); differential evolution over the typical
    scales finds the truth."""
    truth = dict(zip(FREE, (0.8, 0.3, 50.0, -20.0, 3.0)))
    zero = scenario.with_changes({"parameters": dict.fromkeys(FREE, 0.0)})
    noisy = [synthetic_trace(scenario, truth, w, NOISE_M, seed=i, duration_s=2.5)[0] for i, w in enumerate(LOADS_N)]
    prob = make_problem(zero, noisy, free=FREE)
    theta_true = np.array([truth[n] for n in FREE])
    rms_truth = float(np.sqrt(np.mean(prob.residuals_from(make_trials(prob, "native")(theta_true)) ** 2)))
    fit = fit_dynamic(zero, noisy, free=FREE, backend="native", n_starts=0, global_search=True)
    assert fit.rms_pooled_mm <= 1.01 * rms_truth
    assert fit.theta == pytest.approx(theta_true, rel=0.05)


def test_noise_level_of_a_trace_from_its_second_differences(scenario):
    noisy, clean = synthetic_trace(scenario, {}, 22.74, NOISE_M, seed=3, duration_s=2.5)
    assert noise_level_mm(noisy.x_m) == pytest.approx(NOISE_M * 1e3, rel=0.06)
    assert noise_level_mm(clean.x_m) < 0.02 * NOISE_M * 1e3  # the motion itself is micrometres
    # A sensor coarser than its noise: most second differences are 0, the spread of all of them is used.
    step = np.round(noisy.x_m / 1e-4) * 1e-4
    assert 0 < noise_level_mm(step) < 0.1


def test_quality_warnings_against_hand_counts():
    names = ["a.csv", "b.csv"]
    # pooled sqrt((0.05^2 + 0.052^2) / 2) = 0.05101 mm: 1.02 times the noise, traces 1.0 and 1.04 x their noise
    assert quality_warnings(names, [0.05, 0.052], [0.05, 0.05], 0.05101) == []
    # pooled 0.36 mm against a pooled noise of 0.05 mm: 7.11 times; traces 10 x and 1 x their noise
    lines = quality_warnings(names, [0.5, 0.05], [0.05, 0.05], float(np.sqrt((0.25 + 0.0025) / 2)))
    assert len(lines) == 2
    assert "7.11 times" in lines[0] and "a.csv" in lines[0]
    assert "a.csv 0.5 mm (10.0 x its noise) against b.csv 0.05 mm (1.0 x)" in lines[1]
    # 1.10 times the noise in both traces: above the pooled threshold 1.08, evenly
    lines = quality_warnings(names, [0.055, 0.055], [0.05, 0.05], 0.055)
    assert len(lines) == 1 and "1.10 times" in lines[0]
    # pooled sqrt((0.056^2 + 0.045^2) / 2) = 0.0508 mm (1.016 times), but 1.12 x against 0.9 x: 1.24 > 1.2
    lines = quality_warnings(names, [0.056, 0.045], [0.05, 0.05], float(np.sqrt((0.056 ** 2 + 0.045 ** 2) / 2)))
    assert len(lines) == 1 and "unevenly" in lines[0]


def test_the_physics_signs_bound_the_coefficients(scenario):
    noisy = [n for n, _ in traces(scenario, LOADS_N[:1])]
    prob = make_problem(scenario, noisy, free=FREE)
    lower = dict(zip(FREE, prob.bounds[0]))
    assert lower["N0_N_per_bar"] == 0.0 and lower["D2_N_s2_per_m2"] == 0.0
    assert lower["D1_N_s_per_m"] == -math.inf and lower["N1_N_per_bar_m"] == -math.inf
    assert lower["N2_N_per_bar_m2"] == -math.inf
    # A negative start is moved onto the bound, and random starts stay inside.
    negative = scenario.with_changes({"parameters": {"N0_N_per_bar": -1.0}})
    fit = fit_dynamic(negative, noisy, free=["N0_N_per_bar"], backend="native", n_starts=2)
    assert fit.theta[0] >= 0.0
    pts = random_points(np.array([6.0, -1.0]), np.array([9.0, 50.0]), (np.array([0.0, -np.inf]), np.full(2, np.inf)),
                        500, 0)
    assert pts[:, 0].min() >= 0.0 and (pts[:, 1] > 0).any() and (pts[:, 1] < 0).any()


def test_negative_starts_are_refused(scenario):
    noisy = [n for n, _ in traces(scenario, LOADS_N[:1])]
    with pytest.raises(InputError, match="--starts = -1"):
        fit_dynamic(scenario, noisy, free=["N0_N_per_bar"], backend="native", n_starts=-1)


@pytest.fixture(scope="module")
def stalling_pair(tmp_path_factory, scenario):
    """Two traces (N0 = 6 N/bar, 12.74 and 22.74 N) whose single-start fit of N0 from the paper's 6.87
    stops at 6.15, in a local minimum 9 times the noise; written as CSV files."""
    folder = tmp_path_factory.mktemp("stall")
    paths = []
    for i, w in enumerate((12.74, 22.74)):
        noisy, _ = synthetic_trace(scenario, {"N0_N_per_bar": 6.0}, w, NOISE_M, seed=10 + i, duration_s=2.0)
        paths.append(folder / f"step_{i}.csv")
        write_trace_csv(noisy, paths[-1])
    return paths


def test_cli_warns_on_a_fit_far_above_the_noise(tmp_path, stalling_pair):
    out = tmp_path / "one"
    proc = run_main("fit", "dynamic", *stalling_pair, "--scenario", SCENARIOS / "acra2012_fig4.toml",
                    "--free", "N0_N_per_bar", "--backend", "native", "--starts", "0", "-o", out, "--json")
    assert proc.returncode == 0, proc.stderr
    body = json.loads(proc.stdout)
    assert body["success"] is False and body["warnings"]
    assert "warning: the pooled RMS" in proc.stderr and "times the traces' noise" in proc.stderr
    assert "**Warning:**" in (out / "report.md").read_text()


def test_cli_default_starts_on_native_find_the_truth(tmp_path, stalling_pair):
    out = tmp_path / "many"
    proc = run_main("fit", "dynamic", *stalling_pair, "--scenario", SCENARIOS / "acra2012_fig4.toml",
                    "--free", "N0_N_per_bar", "--backend", "native", "-o", out, "--json")
    assert proc.returncode == 0, proc.stderr
    body = json.loads(proc.stdout)
    assert body["success"] is True and body["warnings"] == [] and body["n_starts"] == DEFAULT_STARTS["native"]
    assert body["parameters"]["N0_N_per_bar"] == pytest.approx(6.0, rel=0.01)
    assert "warning" not in proc.stderr
