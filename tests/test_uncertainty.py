"""Uncertainty studies: sampling against the distributions, Latin hypercube strata, bounds, seeds, bad tables.

The sampling tests draw thousands of values without simulating; the tolerances come from the sample
size (a few standard errors, the Kolmogorov-Smirnov critical value).  Only a handful of samples are
simulated; the 10,000-sample study is a benchmark (benchmarks/bench_dask.py).
"""

from __future__ import annotations

import csv
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate, stats

import pamsim
from pamsim.sweep import SweepError, load_sweep, sweep_from_dict
from conftest import run_main as _cli

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
FIG4 = str(SCENARIOS / "acra2012_fig4.toml")
N = 4000
KS_CRITICAL = 1.95 / math.sqrt(N)  # Kolmogorov-Smirnov at the 0.1 % level (asymptotic 1.949/sqrt(n))

# Independent truncated distributions, written with scipy's own truncated normal and by quadrature.
NORMAL = {"distribution": "normal", "mean": 3e-9, "std": 1e-9, "lower": 1.5e-9, "upper": 5e-9}
UNIFORM = {"distribution": "uniform", "lower": 2.0, "upper": 3.0}
LOGNORMAL = {"distribution": "lognormal", "median": 0.3, "sigma": 0.25, "lower": 0.2, "upper": 0.6}


def _spec(params: dict, sampling: str = "random", samples: int = N, seed: int = 7):
    return sweep_from_dict({"base_scenario": FIG4, "uncertainty": {
        "samples": samples, "seed": seed, "sampling": sampling, "parameters": params}}).uncertainty


def _reference_cdf(entry: dict):
    """CDF of the truncated distribution, built without pamsim's code."""
    lo, hi = entry["lower"], entry["upper"]
    if entry["distribution"] == "normal":
        m, s = entry["mean"], entry["std"]
        return stats.truncnorm((lo - m) / s, (hi - m) / s, loc=m, scale=s).cdf
    if entry["distribution"] == "uniform":
        return lambda x: np.clip((np.asarray(x) - lo) / (hi - lo), 0, 1)
    mu, s = math.log(entry["median"]), entry["sigma"]

    def pdf(x):
        return math.exp(-(math.log(x) - mu) ** 2 / (2 * s * s)) / (x * s * math.sqrt(2 * math.pi))

    mass = integrate.quad(pdf, lo, hi)[0]
    return np.vectorize(lambda x: integrate.quad(pdf, lo, min(max(x, lo), hi))[0] / mass)


def _reference_mean_std(entry: dict) -> tuple[float, float]:
    cdf = _reference_cdf(entry)
    lo, hi = entry["lower"], entry["upper"]
    # E[X] = lo + int (1 - F), E[X^2] = lo^2 + int 2x (1 - F) over [lo, hi].
    m1 = lo + integrate.quad(lambda x: 1 - cdf(x), lo, hi, limit=200)[0]
    m2 = lo ** 2 + integrate.quad(lambda x: 2 * x * (1 - cdf(x)), lo, hi, limit=200)[0]
    return m1, math.sqrt(m2 - m1 ** 2)


@pytest.mark.parametrize("sampling", ["random", "latin_hypercube"])
@pytest.mark.parametrize("name,entry", [("valve_C_m3_per_s_Pa", NORMAL), ("N0_N_per_bar", UNIFORM),
                                        ("valve_b", LOGNORMAL)], ids=["normal", "uniform", "lognormal"])
def test_samples_follow_the_truncated_distribution(name, entry, sampling):
    x = _spec({name: entry}, sampling).draw().values[:, 0]
    mean, std = _reference_mean_std(entry)
    assert x.min() >= entry["lower"] and x.max() <= entry["upper"]
    assert abs(x.mean() - mean) < 4 * std / math.sqrt(N)
    # Standard error of a sample std: std sqrt((kurtosis - 1) / 4n); these truncated laws have kurtosis < 4.
    assert abs(x.std(ddof=1) - std) < 4 * std * math.sqrt(3 / (4 * N))
    assert stats.kstest(x, _reference_cdf(entry)).statistic < KS_CRITICAL
    for q in (0.05, 0.5, 0.95):  # sample quantiles: the reference CDF there is within the KS band of q
        assert abs(float(_reference_cdf(entry)(np.quantile(x, q))) - q) < KS_CRITICAL


def test_relative_distribution_scales_the_base_value_also_when_it_is_negative():
    nominal = pamsim.load_scenario(FIG4).parameters["N1_N_per_bar_m"]
    x = _spec({"N1_N_per_bar_m": {"distribution": "uniform", "relative": True, "lower": 0.9,
                                  "upper": 1.1}}).draw().values[:, 0]
    assert nominal < 0
    assert x.min() >= 1.1 * nominal and x.max() <= 0.9 * nominal
    assert abs(x.mean() - nominal) < 4 * (0.2 * abs(nominal) / math.sqrt(12)) / math.sqrt(N)


def test_latin_hypercube_puts_one_sample_in_each_equal_probability_stratum():
    n = 200
    entries = {"valve_C_m3_per_s_Pa": NORMAL, "N0_N_per_bar": UNIFORM, "valve_b": LOGNORMAL}
    values = _spec(entries, "latin_hypercube", samples=n).draw().values
    for j, entry in enumerate(entries.values()):
        strata = np.floor(_reference_cdf(entry)(values[:, j]) * n).astype(int)
        assert sorted(np.minimum(strata, n - 1)) == list(range(n))
    # Plain random sampling leaves strata empty (the chance that 200 draws fill 200 strata is ~1e-85).
    rand = _spec(entries, "random", samples=n).draw().values
    assert len(set(np.floor(_reference_cdf(NORMAL)(rand[:, 0]) * n).astype(int))) < n


def test_tight_bounds_truncate_and_never_leave_the_bounds():
    # Bounds one tenth of a standard deviation wide about the mean: nearly uniform inside them.
    entry = {"distribution": "normal", "mean": 2e-9, "std": 1e-9, "lower": 1.95e-9, "upper": 2.05e-9}
    x = _spec({"valve_C_m3_per_s_Pa": entry}).draw().values[:, 0]
    assert x.min() >= 1.95e-9 and x.max() <= 2.05e-9
    assert stats.kstest(x, stats.uniform(1.95e-9, 1e-10).cdf).statistic < KS_CRITICAL
    # A bound in the far tail: every sample lies beyond the mean + 3 std cut.
    tail = {"distribution": "normal", "mean": 2e-9, "std": 1e-9, "lower": 5e-9, "upper": 9e-9}
    y = _spec({"valve_C_m3_per_s_Pa": tail}).draw().values[:, 0]
    assert y.min() >= 5e-9 and y.max() <= 9e-9
    assert abs(y.mean() - _reference_mean_std(tail)[0]) < 4 * _reference_mean_std(tail)[1] / math.sqrt(N)


def test_same_seed_same_samples_other_seed_other_samples():
    entries = {"valve_C_m3_per_s_Pa": NORMAL, "N0_N_per_bar": UNIFORM}
    for sampling in ("random", "latin_hypercube"):
        a = _spec(entries, sampling, samples=50, seed=3).draw().values
        b = _spec(entries, sampling, samples=50, seed=3).draw().values
        c = _spec(entries, sampling, samples=50, seed=4).draw().values
        assert np.array_equal(a, b)
        assert not np.any(a == c)


@pytest.fixture(scope="module")
def small_study():
    """The Figure 4 example reduced to 4 samples, run twice from the same seed."""
    spec = load_sweep(SCENARIOS / "acra2012_fig4_uncertainty.toml")
    spec = dataclasses.replace(spec, uncertainty=dataclasses.replace(spec.uncertainty, samples=4))
    return spec, pamsim.sweep(spec), pamsim.sweep(spec)


def test_example_study_gives_the_same_numbers_twice_and_they_follow_the_samples(small_study, tmp_path):
    spec, first, second = small_study
    assert first.failures == [] and first.rows == []
    assert first.uncertainty.quantile_rows() == second.uncertainty.quantile_rows()
    outs = [first.uncertainty.output("load_dependent", k) for k in range(4)]
    samples = first.uncertainty.samples
    # Each run used its sample: re-simulating sample 2 by hand gives the same final contraction.
    overrides = dict(zip(samples.names, map(float, samples.values[2])))
    by_hand = pamsim.simulate(spec.base.with_changes({"parameters": overrides}))
    assert outs[2]["final_contraction_m"] == float(by_hand.x_m[-1])
    assert outs[2]["peak_contraction_m"] == by_hand.peak_contraction_m
    # Quantiles of the table equal numpy's quantiles of the per-run values.
    rows = {r["quantity"]: r for r in first.uncertainty.quantile_rows()}
    finals = np.array([o["final_contraction_m"] for o in outs])
    assert rows["final_contraction_m"]["q0.5"] == np.quantile(finals, 0.5)
    assert rows["final_contraction_m"]["runs"] == 4
    # Settling: after the settling time the contraction stays within 5 % of its change of the final value.
    x, t = by_hand.x_m, by_hand.t_s
    after = t >= outs[2]["contraction_settled_time_s"]
    assert np.all(np.abs(x[after] - x[-1]) <= 0.05 * abs(x[-1] - x[0]))
    assert np.any(np.abs(x[~after] - x[-1]) > 0.05 * abs(x[-1] - x[0]))
    names = first.write(tmp_path)
    assert set(names) == {"uncertainty_samples.csv", "uncertainty_summary.csv", "uncertainty.md",
                          "uncertainty_histograms.png", "uncertainty_ecdf.png"}
    with open(tmp_path / "uncertainty_samples.csv") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == 4 and float(table[2]["valve_C_m3_per_s_Pa"]) == pytest.approx(overrides["valve_C_m3_per_s_Pa"])
    assert "| load_dependent | final contraction [mm] | 4 | 0 |" in (tmp_path / "uncertainty.md").read_text()


def test_example_file_is_the_issue_study():
    u = load_sweep(SCENARIOS / "acra2012_fig4_uncertainty.toml").uncertainty
    assert u.samples == 10000 and u.sampling == "latin_hypercube"
    assert {p.name for p in u.parameters} == {"valve_C_m3_per_s_Pa", "N0_N_per_bar", "N1_N_per_bar_m",
                                              "N2_N_per_bar_m2"}
    assert all(p.relative and (p.lower, p.upper) == (0.9, 1.1) for p in u.parameters)


BAD_TABLES = {
    "unknown key": ({"samples": 5, "seed": 1, "sampels": 5}, "uncertainty.sampels"),
    "unknown parameter": ({"parameters": {"valve_D": UNIFORM}}, "uncertainty.parameters.valve_D"),
    "bad distribution": ({"parameters": {"N0_N_per_bar": {**UNIFORM, "distribution": "gamma"}}},
                         "'gamma'"),
    "key of another distribution": ({"parameters": {"N0_N_per_bar": {**UNIFORM, "mean": 2.5}}},
                                    "uncertainty.parameters.N0_N_per_bar.mean"),
    "bounds exclude": ({"parameters": {"valve_C_m3_per_s_Pa": {**NORMAL, "lower": 2e-8, "upper": 3e-8}}},
                       "exclude the normal distribution"),
    "bounds reversed": ({"parameters": {"N0_N_per_bar": {**UNIFORM, "lower": 3.0, "upper": 2.0}}},
                        "uncertainty.parameters.N0_N_per_bar.upper = 2.0"),
    "bound outside the parameter's range": (
        {"parameters": {"valve_b": {**LOGNORMAL, "upper": 1.5}}}, "uncertainty.parameters.valve_b.upper = 1.5"),
    "negative std": ({"parameters": {"valve_C_m3_per_s_Pa": {**NORMAL, "std": -1e-9}}}, "std = -1e-09"),
    "bad sampling": ({"sampling": "sobol"}, "uncertainty.sampling = 'sobol'"),
    "zero samples": ({"samples": 0}, "uncertainty.samples = 0"),
    "missing seed": ({"seed": None}, "missing key uncertainty.seed"),
    "no parameters": ({"parameters": {}}, "uncertainty.parameters is empty"),
}


@pytest.mark.parametrize("change,expected", BAD_TABLES.values(), ids=BAD_TABLES.keys())
def test_bad_uncertainty_tables_name_file_key_and_value(change, expected):
    table = {"samples": 5, "seed": 1, "parameters": {"N0_N_per_bar": UNIFORM}, **change}
    table = {k: v for k, v in table.items() if v is not None}
    with pytest.raises(SweepError) as err:
        sweep_from_dict({"base_scenario": FIG4, "uncertainty": table}, origin="study.toml")
    msg = str(err.value)
    assert msg.startswith("study.toml: ") and expected in msg and "\n" not in msg


def test_cli_refuses_a_bad_table_with_one_line_and_writes_nothing(tmp_path):
    (tmp_path / "s.toml").write_text(
        f'base_scenario = "{FIG4}"\n[uncertainty]\nsamples = 3\nseed = 1\n'
        '[uncertainty.parameters.N0_N_per_bar]\ndistribution = "lognormal"\nmedian = 6.87\nsigma = 0.1\n'
        'lower = 100.0\nupper = 200.0\n')
    proc = _cli("sweep", tmp_path / "s.toml", "-o", tmp_path / "out", "--workers", "1")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "s.toml" in lines[0] and "uncertainty.parameters.N0_N_per_bar.lower = 100.0" in lines[0]
    assert not (tmp_path / "out").exists()


def test_a_decimal_sample_count_is_named_in_plain_words(tmp_path):
    spec = {"base_scenario": str(FIG4), "uncertainty": {"samples": 1e12, "seed": 1, "parameters": {
        "N0_N_per_bar": {"distribution": "uniform", "lower": 6.0, "upper": 7.0}}}}
    with pytest.raises(SweepError, match=r"uncertainty.samples = 1000000000000.0: must be an integer, not a "
                                         r"decimal number"):
        sweep_from_dict(spec)


def test_a_study_too_large_for_the_memory_is_refused_before_anything_runs(tmp_path, capsys):
    """``samples = 10**12`` drew its Latin hypercube first and ended in a traceback (a 29 TiB array)."""
    from pamsim.cli import main

    (tmp_path / "huge.toml").write_text(
        f'base_scenario = "{FIG4}"\n[uncertainty]\nsamples = 1000000000000\nseed = 1\n'
        '[uncertainty.parameters.N0_N_per_bar]\ndistribution = "uniform"\nlower = 6.0\nupper = 7.0\n')
    code = main(["sweep", str(tmp_path / "huge.toml"), "-o", str(tmp_path / "out"), "--no-progress"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    # 1e12 x (40 B of its one parameter and 64 B while drawn + 3 quantities x 8 B of its one friction model's
    # run)
    assert "uncertainty.samples = 1000000000000: the study needs about 128 TB of memory" in err[0], err
    assert not (tmp_path / "out").exists()


def test_the_memory_check_counts_parameters_and_friction_models(monkeypatch):
    from pamsim.sweep import run

    spec = load_sweep(SCENARIOS / "acra2012_fig4_uncertainty.toml")  # 4 parameters, 1 friction model
    assert run.sample_memory_bytes(spec) == 10_000 * (4 * run.BYTES_PER_SAMPLE_VALUE + run.BYTES_PER_SAMPLE_DRAW
                                                      + run.BYTES_PER_SAMPLE_RUN)
    monkeypatch.setattr(run, "available_memory_bytes", lambda: 2_000_000)  # 1.6 MB of it usable
    # 10,000 x (4 x 40 + 64 + 3 x 8) = 2.48 MB; 1.6 MB / 248 B = 6,451 samples
    with pytest.raises(pamsim.errors.InputError, match=r"needs about 2.48 MB of memory and 2 MB is available; "
                                                      r"take at most 6,451 samples"):
        run.check_memory(spec)
