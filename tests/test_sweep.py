"""The sweep: the 66 ACRA 2012 tests, the oscillation estimator, parallel runs, bad sweep files.

The 66-case grid is run once serially and once on two worker processes per
session (module fixtures); everything else reads those results.
"""

from __future__ import annotations

import csv
import subprocess
import sys
import textwrap
import math
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.oscillation import estimate_oscillation
from pamsim.sweep import SweepError, load_sweep, sweep_from_dict
from conftest import run_main as _cli

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
GRID = SCENARIOS / "acra2012_grid.toml"
DATA = ROOT / "pamsim" / "data" / "acra2012_steady_state.csv"
# The paper's static polynomial, eq. (11), written out here so the equilibrium is checked independently.
K1, K2, C1, S1, S2, S3 = -476.95, -188.39, 23.90, 2562.4, -245.48, -11.56


@pytest.fixture(scope="module")
def grid_spec():
    return load_sweep(GRID)


@pytest.fixture(scope="module")
def serial(grid_spec):
    return pamsim.sweep(grid_spec)


@pytest.fixture(scope="module")
def parallel(grid_spec):
    """Every seventh case and three of the frequency loads, on two worker processes (the serial fixture
    has run them all; comparing a subset keeps the suite fast)."""
    import dataclasses

    subset = dataclasses.replace(grid_spec, cases=grid_spec.cases[::7], time_responses=(),
                                 frequency=dataclasses.replace(grid_spec.frequency,
                                                               weights_N=grid_spec.frequency.weights_N[::3]))
    with ProcessPoolExecutor(max_workers=2) as pool:
        return pamsim.sweep(subset, pool)


@pytest.fixture(scope="module")
def written(serial, tmp_path_factory):
    out = tmp_path_factory.mktemp("grid")
    serial.write(out)
    return out


def _equilibrium_mm(pressure_bar: float, weight_N: float) -> float:
    """Smallest root of F_static(x, P) = W where the force falls through the load (0 if it cannot lift)."""
    a, b, c = K1 * pressure_bar + S1, K2 * pressure_bar + S2, C1 * pressure_bar + S3 - weight_N
    if c <= 0:
        return 0.0
    roots = sorted(r.real for r in np.roots([a, b, c]) if abs(r.imag) < 1e-12 and r.real > 0)
    return roots[0] * 1e3


def _within(rows, threshold_mm=5.0):
    return [r for r in rows if r["equilibrium_contraction_m"] * 1e3 >= threshold_mm]


def _rms_mm(values_m) -> float:
    return float(np.sqrt(np.mean(np.square(values_m)))) * 1e3


# ---------------------------------------------------------------- the 66-case grid
def test_the_written_figures_are_the_named_ones(written):
    from pamsim.sweep.figures import SWEEP_FIGURES

    assert sorted(pamsim.sweep.FIGURES) == sorted(SWEEP_FIGURES)
    for stem in pamsim.sweep.FIGURES:
        assert (written / f"{stem}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", stem


def test_grid_has_one_row_per_measured_test(serial, written):
    with open(DATA) as fh:
        measured = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    assert len(serial.rows) == len(measured) == 66
    assert serial.failures == []
    with open(written / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 66
    for col in ("weight_N", "pressure_stable_bar", "final_contraction_m", "peak_contraction_m",
                "equilibrium_contraction_m", "measured_contraction_m", "error_m", "within_capability", "at_rest",
                "frequency_Hz", "damping_ratio", "constant_final_contraction_m", "constant_error_m"):
        assert col in rows[0], col
    # Each case is stepped to the stable pressure measured for it (Table 1).
    for row, m in zip(serial.rows, measured):
        assert row["weight_N"] == float(m["weight_N"])
        assert row["pressure_bar"] == float(m["pressure_stable_bar"])
        assert row["measured_contraction_m"] == pytest.approx(float(m["contraction_stable_mm"]) * 1e-3)


def test_static_equilibrium_matches_the_polynomial(serial):
    for r in serial.rows:
        assert r["equilibrium_contraction_m"] * 1e3 == pytest.approx(
            _equilibrium_mm(r["pressure_bar"], r["weight_N"]), abs=1e-6)


def _measured_rows() -> list[dict]:
    with open(DATA) as fh:
        return [{k: float(v) for k, v in row.items()}
                for row in csv.DictReader(line for line in fh if not line.startswith("#"))]


def _independent_errors_mm(threshold_mm: float) -> dict[tuple[float, float], float]:
    """(weight, stable pressure) -> equilibrium minus measured [mm], from the data file and the written-out
    polynomial alone, for the cases whose equilibrium is at least ``threshold_mm``."""
    out = {}
    for m in _measured_rows():
        x = _equilibrium_mm(m["pressure_stable_bar"], m["weight_N"])
        if x >= threshold_mm:
            out[(m["weight_N"], m["pressure_stable_bar"])] = x - m["contraction_stable_mm"]
    return out


def test_within_capability_static_rms_is_what_the_paper_polynomial_gives(serial, written):
    """The sweep's within-capability cases, RMS and worst case are those of the paper's polynomial applied
    to the measured data directly.  The issue's target (<= 1.5 mm over equilibrium >= 5 mm) is not met
    by those coefficients; past 7 mm it is (docs/validation.md)."""
    expected = _independent_errors_mm(5.0)
    within = _within(serial.rows)
    assert {(r["weight_N"], r["pressure_bar"]) for r in within} == set(expected)
    rms = _rms_mm([r["equilibrium_error_m"] for r in within])
    assert rms == pytest.approx(float(np.sqrt(np.mean(np.square(list(expected.values()))))), rel=1e-6)
    worst = max(within, key=lambda r: abs(r["equilibrium_error_m"]))
    assert (worst["weight_N"], worst["pressure_bar"]) == max(expected, key=lambda k: abs(expected[k]))
    past7 = _independent_errors_mm(7.0)
    assert _rms_mm([r["equilibrium_error_m"] for r in _within(serial.rows, 7.0)]) == pytest.approx(
        float(np.sqrt(np.mean(np.square(list(past7.values()))))), rel=1e-6)
    assert f"| {len(expected)} | {rms:.2f} |" in (written / "report.md").read_text()


@pytest.mark.xfail(strict=True, reason="issue 3 target not met by the paper's polynomial: RMS 1.65 mm > 1.5 mm "
                                       "over the 28 cases with equilibrium >= 5 mm (docs/validation.md)")
def test_issue_target_within_capability_rms_at_most_1p5_mm(serial):
    assert _rms_mm([r["equilibrium_error_m"] for r in _within(serial.rows)]) <= 1.5


def test_report_gives_both_friction_models(serial, written):
    report = (written / "report.md").read_text()
    for f in ("load_dependent", "constant"):
        vals = [r[("" if f == "load_dependent" else "constant_") + "error_m"] for r in _within(serial.rows)]
        assert f"{f} friction, within capability | {len(vals)} | {_rms_mm(vals):.2f} |" in report


def test_rest_at_the_end(serial):
    """Constant friction: every case at rest.  Load-dependent friction: exactly the cases whose friction
    level (P_bar - m_kg)(...) is clamped to zero keep ringing, and they are reported as not at rest."""
    assert all(r["constant_at_rest"] for r in serial.rows)
    for r in serial.rows:
        mass_kg = r["weight_N"] / 9.81
        clamped = r["pressure_bar"] <= mass_kg
        lifted = r["final_contraction_m"] > 0.0 or r["peak_contraction_m"] > 0.0
        if not r["at_rest"]:
            assert clamped and lifted, r["case"]
        if not clamped:
            assert r["at_rest"], r["case"]
    not_at_rest = [r for r in serial.rows if not r["at_rest"]]
    assert len(not_at_rest) > 0  # honest: the issue's "every case ends at rest" fails, see below
    # The motion left in the last second: a load still moving covers some distance; a load held
    # still since before the last second covers none (its contraction is frozen while stuck).
    assert all(r["last_second_peak_to_peak_m"] > 1e-6 for r in not_at_rest)
    for r in serial.rows:
        assert 0.0 <= r["constant_last_second_peak_to_peak_m"] <= r["constant_peak_contraction_m"]


@pytest.mark.xfail(strict=True, reason="with the paper's load-dependent friction clamped to zero for P_bar < m_kg "
                                       "and D1 < 0, 20 heavy-load cases still ring at 8 s (docs/validation.md)")
def test_issue_target_every_case_ends_at_rest(serial):
    assert all(r["at_rest"] for r in serial.rows)


def test_frequency_falls_with_load_at_3p6_bar(serial):
    rows = {r["weight_N"]: r for r in serial.frequency_rows}
    assert serial.spec.frequency.pressure_bar == 3.6
    f12, f22 = rows[12.74]["load_dependent_frequency_Hz"], rows[22.74]["load_dependent_frequency_Hz"]
    assert math.isfinite(f12) and math.isfinite(f22)
    assert f12 > f22


def test_parallel_gives_the_serial_numbers(serial, parallel):
    by_case = {r["case"]: r for r in serial.rows}
    assert len(parallel.rows) == len(serial.rows[::7]) >= 9
    for b in parallel.rows:
        a = by_case[b["case"]]
        assert a.keys() == b.keys()
        for k in a:
            if isinstance(a[k], float):
                assert (a[k] == b[k]) or (math.isnan(a[k]) and math.isnan(b[k])), (a["case"], k)
            else:
                assert a[k] == b[k], (a["case"], k)
    freq = {r["weight_N"]: r["load_dependent_frequency_Hz"] for r in serial.frequency_rows}
    assert len(parallel.frequency_rows) >= 3
    for r in parallel.frequency_rows:
        a, b = freq[r["weight_N"]], r["load_dependent_frequency_Hz"]
        assert a == b or (math.isnan(a) and math.isnan(b)), r["weight_N"]


def test_outputs_are_complete(written):
    names = {p.name for p in written.iterdir()}
    assert names == {"summary.csv", "report.md", "error_heatmap.png", "steady_state_vs_pressure.png",
                     "time_responses.png", "frequency_vs_load.png"}
    for name in names:
        if name.endswith(".png"):
            assert (written / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- the estimator
@pytest.mark.parametrize("freq_Hz, zeta, phase, rate_Hz", [
    (1.0, 0.05, 0.0, 1000.0), (3.3, 0.2, 1.1, 1000.0), (7.7, 0.02, -0.4, 500.0), (0.6, 0.4, 2.0, 1000.0),
    (12.0, 0.1, 0.3, 200.0)])
def test_estimator_on_damped_sines(freq_Hz, zeta, phase, rate_Hz):
    t = np.arange(0.0, 8.0, 1.0 / rate_Hz)
    wn = 2 * math.pi * freq_Hz / math.sqrt(1 - zeta ** 2)
    x = 0.05 + 0.01 * np.exp(-zeta * wn * t) * np.cos(2 * math.pi * freq_Hz * t + phase)
    osc = estimate_oscillation(t, x)
    assert osc.n_half_cycles >= 3
    assert osc.frequency_Hz == pytest.approx(freq_Hz, rel=0.02)
    assert osc.damping_ratio == pytest.approx(zeta, rel=0.05)


def test_estimator_says_nan_without_oscillation():
    t = np.linspace(0.0, 4.0, 4001)
    osc = estimate_oscillation(t, 0.06 * (1 - np.exp(-t / 0.3)))  # first-order creep, no turning point
    assert math.isnan(osc.frequency_Hz) and math.isnan(osc.damping_ratio) and osc.n_half_cycles == 0


def test_estimator_counts_a_stick_as_a_turning_point():
    # A swing down and back up, then the load sticks at t = 0.5 s on its turning point (Coulomb friction):
    # the turning points at 0.25 s and 0.5 s are half a period of 2 Hz apart.
    t = np.arange(0.0, 3.0, 1e-3)
    x = 0.01 * np.cos(2 * math.pi * 2.0 * np.minimum(t, 0.5))
    osc = estimate_oscillation(t, x, t_start_s=0.1, min_half_cycles=1)
    assert math.isnan(estimate_oscillation(t, x, t_start_s=0.1).frequency_Hz)  # default needs two
    assert osc.n_half_cycles == 1
    assert osc.frequency_Hz == pytest.approx(2.0, rel=0.02)
    assert math.isnan(osc.damping_ratio)


# ---------------------------------------------------------------- API and failures
def test_any_executor_and_failed_cases_do_not_stop_the_sweep(tmp_path):
    base = (SCENARIOS / "acra2012_fig6b.toml").read_text().replace("rtol = 1e-6", "rtol = 1e-6\nmax_events = 8")
    (tmp_path / "base.toml").write_text(base)
    spec = sweep_from_dict({"base_scenario": "base.toml", "friction_models": ["load_dependent"],
                            "axes": {"pressure_bar": [2.0, 3.6], "weight_N": [22.74]}}, base_dir=tmp_path)
    with ThreadPoolExecutor(max_workers=2) as pool:
        result = pamsim.sweep(spec, pool)
    by_case = {r["case"]: r for r in result.rows}
    assert "SolverFailure" in by_case["2bar_22.74N"]["failure"]  # 2.0 bar rings: more than 8 events
    assert math.isnan(by_case["2bar_22.74N"]["final_contraction_m"])
    assert by_case["3.6bar_22.74N"]["failure"] == ""
    assert by_case["3.6bar_22.74N"]["final_contraction_m"] > 0.04
    assert len(result.failures) == 1
    result.write(tmp_path / "out")
    assert "## Failed runs" in (tmp_path / "out" / "report.md").read_text()




def test_cli_runs_a_small_sweep_with_progress(tmp_path):
    (tmp_path / "s.toml").write_text(
        f'base_scenario = "{SCENARIOS / "acra2012_fig5.toml"}"\n'
        '[axes]\npressure_bar = [2.8, 3.6]\nweight_N = [12.74, 22.74]\n')
    proc = _cli("sweep", tmp_path / "s.toml", "-o", tmp_path / "out", "--workers", "2")
    assert proc.returncode == 0, proc.stderr
    assert "4/4" in proc.stderr and "failed=0" in proc.stderr  # the tqdm bar
    with open(tmp_path / "out" / "summary.csv") as fh:
        assert len(list(csv.DictReader(fh))) == 4


BAD_FILES = {
    "unknown axis": ('[axes]\npressure_bar = [3.6]\nweight_N = [12.74]\nvolume_m3 = [1.0]\n', "axes.volume_m3"),
    "empty axis": ('[axes]\npressure_bar = []\nweight_N = [12.74]\n', "axes.pressure_bar"),
    "data columns": ('[measured]\nfile = "bad.csv"\n[cases]\nfrom_measured = true\n', "contraction_stable_mm"),
    "unknown key": ('frictions = ["constant"]\n[axes]\npressure_bar = [3.6]\nweight_N = [12.74]\n', "frictions"),
    "unknown friction": ('friction_models = ["viscous"]\n[axes]\npressure_bar = [3.6]\nweight_N = [12.74]\n',
                         "viscous"),
    "friction not a list": ('friction_models = "constant"\n[axes]\npressure_bar = [3.6]\nweight_N = [12.74]\n',
                            "must be a list"),
    "no cases": ('name = "x"\n', "exactly one of"),
    "over rating": ('[axes]\npressure_bar = [9.0]\nweight_N = [12.74]\n', "rating"),
}


@pytest.mark.parametrize("label", sorted(BAD_FILES))
def test_bad_sweep_files_exit_2_naming_the_problem(tmp_path, cli, label):
    body, needle = BAD_FILES[label]
    (tmp_path / "bad.csv").write_text("weight_N,pressure_stable_bar,contraction_mm\n12.74,3.6,70\n")
    path = tmp_path / "sweep.toml"
    path.write_text(f'base_scenario = "{SCENARIOS / "acra2012_fig4.toml"}"\n' + body)
    with pytest.raises(pamsim.errors.InputError) as err:
        load_sweep(path)
    assert needle in str(err.value) and str(path) in str(err.value)
    if label in ("unknown axis", "empty axis", "data columns"):  # the issue's three, end to end
        proc = cli("sweep", path, "-o", tmp_path / "out")
        assert proc.returncode == 2
        assert needle in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
        assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_sweep_error_is_an_input_error():
    assert issubclass(SweepError, pamsim.errors.InputError)


def test_pamsim_sweep_is_the_package_and_runs_a_sweep(tmp_path):
    """``pamsim.sweep`` must be both: ``pamsim.sweep.load_sweep`` (the package) and ``pamsim.sweep(spec)``."""
    import importlib
    import subprocess
    import sys

    mod = importlib.import_module("pamsim.sweep")
    assert mod is pamsim.sweep and mod.load_sweep is load_sweep
    spec = sweep_from_dict({"base_scenario": "acra2012_fig5.toml", "case": [{"weight_N": 12.74, "pressure_bar": 3.6}]},
                           base_dir=Path(__file__).resolve().parents[1] / "scenarios")
    direct = pamsim.sweep.run_sweep(spec)
    via_call = pamsim.sweep(spec)
    assert via_call.rows[0]["final_contraction_m"] == direct.rows[0]["final_contraction_m"]
    # A fresh interpreter that imports the submodule by name sees the package, not a function.
    code = "import pamsim.sweep; print(pamsim.sweep.load_sweep.__module__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "pamsim.sweep.spec"


@pytest.mark.parametrize("n_half", [4, 5, 6, 7])
def test_estimator_uses_whole_periods_when_up_and_down_swings_differ(n_half):
    """A swing up of 0.15 s and a swing down of 0.10 s: the period is 0.25 s (4 Hz) whatever the
    number of half-periods; averaging half-periods would give 4.17 Hz for 5 of them (three short)."""
    t_up, t_down = 0.15, 0.10
    knots_t, knots_x, now = [0.0], [0.0], 0.0
    for i in range(n_half + 1):  # the first swing up leaves the start, which is not a turning point
        now += t_up if i % 2 == 0 else t_down
        knots_t.append(now)
        knots_x.append(0.01 if i % 2 == 0 else 0.0)
    t = np.arange(0.0, now + 0.5, 1e-4)
    phase = np.interp(t, knots_t, np.arange(len(knots_t)))  # half-cosine swings between the knots
    x = 0.005 * (1 - np.cos(np.pi * phase))
    osc = estimate_oscillation(t, x)
    assert osc.n_half_cycles == n_half
    assert osc.frequency_Hz == pytest.approx(1.0 / (t_up + t_down), rel=1e-3)
    mean_half = (t_up + t_down) / 2
    assert osc.half_period_asymmetry == pytest.approx((t_up - t_down) / mean_half, rel=0.05)


def _alive(pid: int) -> bool:
    """The process exists and is not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def _children(pid: int) -> list[int]:
    with open(f"/proc/{pid}/task/{pid}/children") as fh:
        return [int(p) for p in fh.read().split()]


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="reads the process tree from /proc (Linux)")
def test_sigterm_stops_the_pool_workers_and_leaves_no_output_folder(tmp_path):
    """SIGTERM killed the command alone: its pool workers ran on, holding its stdout open, and the empty
    output folder stayed."""
    import signal

    from conftest import slow_study, start_until_progress

    sweep, _ = start_until_progress("sweep", slow_study(tmp_path), "-o", tmp_path / "out", "--workers", "2",
                                    "--chunk-size", "10")
    try:
        workers = _children(sweep.pid)
        sweep.send_signal(signal.SIGTERM)
        _, err = sweep.communicate(timeout=30)  # returns once nothing holds the pipes any more
    finally:
        sweep.kill()
    assert sweep.returncode == 143 and err.rstrip().endswith("pamsim: terminated"), err
    assert workers and not any(_alive(pid) for pid in workers), workers
    # No output folder, and not the samples table's temporary file either (made beside it, the folder not
    # made yet, while the study ran).
    assert sorted(p.name for p in tmp_path.iterdir()) == ["slow.toml"]


def test_an_interrupt_while_a_worker_sends_its_results_does_not_hang_the_pool(tmp_path):
    """A worker killed in the middle of sending its results left half a message in the pool's results pipe;
    the pool's manager thread waited for the rest for ever, and the command with it (a SIGTERM sweep that
    never ended). Here each worker returns 100 MB, and the block is interrupted at several delays after the
    first result is made, so that some interrupt falls while it is being sent (the pool before the fix hung
    at 0.15 s and later on the machine this was written on)."""
    script = tmp_path / "pool.py"
    script.write_text(textwrap.dedent(f"""
        import time
        from pathlib import Path
        from pamsim.cli.pool import process_pool

        def big(marker):
            result = b"x" * 100_000_000
            Path(marker).touch()
            return result

        for delay_s in (0.0, 0.05, 0.1, 0.2, 0.3, 0.5):
            marker = Path({str(tmp_path)!r}, f"made{{delay_s}}")
            try:
                with process_pool(2) as pool:
                    futures = [pool.submit(big, marker) for i in range(3)]
                    while not marker.exists():
                        time.sleep(0.001)
                    time.sleep(delay_s)
                    raise KeyboardInterrupt
            except KeyboardInterrupt:
                print(delay_s, flush=True)
        """))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.split() == ["0.0", "0.05", "0.1", "0.2", "0.3", "0.5"], \
        (done.stdout, done.stderr)


def test_a_killed_sweep_leaves_no_empty_output_folder(tmp_path):
    """The output folder is made when the results are written, not when the command starts."""
    from conftest import slow_study, start_until_progress

    sweep, _ = start_until_progress("sweep", slow_study(tmp_path), "-o", tmp_path / "out" / "deep", "--workers",
                                    "1")
    sweep.kill()
    sweep.communicate(timeout=30)
    assert not (tmp_path / "out").exists()


def test_the_static_equilibrium_stands_at_the_muscles_own_stop(tmp_path):
    """A sweep over the survey's 45 mm muscle at 7.58 bar and 0.05 N: its static equilibrium is the
    muscle's own (the rest of eq. 33, 13.255 mm with the muscle file's bladder), past the 54.7 deg braid
    lock at 12.886 mm, where the sweep once stopped it; the run ends there too."""
    from pamsim.sweep import run_sweep

    base = tmp_path / "survey.toml"
    base.write_text('[model]\nmuscle = "mpam_survey_45mm"\n[load]\nweight_N = 0.05\n'
                    '[pressure]\nsource = "valve"\nsupply_gauge_bar = 7.58\nvalve_open_time_s = 0.1\n'
                    '[simulation]\nduration_s = 3.0\n')
    spec = sweep_from_dict({"base_scenario": str(base), "friction_models": ["load_dependent"],
                            "case": [{"weight_N": 0.05, "pressure_bar": 7.58}]}, base_dir=tmp_path)
    (row,) = run_sweep(spec).rows
    lock = pamsim.load_scenario(base).with_changes({"model": {"upper_stop": "braid_lock"}}).build_model().stops.x_high_m
    assert row["equilibrium_contraction_m"] * 1e3 == pytest.approx(13.255, abs=0.001)
    assert lock * 1e3 == pytest.approx(12.886, abs=0.001)
    assert row["final_contraction_m"] == pytest.approx(row["equilibrium_contraction_m"], abs=2e-5)
