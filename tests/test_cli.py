"""The command line end to end, through subprocess, as a user runs it."""

from __future__ import annotations

import json

import numpy as np
import pytest

import tomllib

from conftest import SCENARIOS
from conftest import run_cli as pamsim

def pamsim_load(path):
    import pamsim

    return pamsim.load_scenario(path)


def pamsim_toml(path):
    return tomllib.loads(path.read_text())


BASE = """
[load]
weight_N = 22.74

[pressure]
source = "valve"
supply_gauge_bar = 3.6
valve_open_time_s = 1.0

[simulation]
duration_s = 2.0
"""




def test_run_writes_csv_png_json(tmp_path):
    out = tmp_path / "out"
    r = pamsim("run", SCENARIOS / "acra2012_fig4.toml", "-o", out)
    assert r.returncode == 0, r.stderr
    files = sorted(p.name for p in out.iterdir())
    assert files == ["acra2012_fig4.csv", "acra2012_fig4.json", "acra2012_fig4.png"]
    summary = json.loads((out / "acra2012_fig4.json").read_text())
    for key in ("final_contraction_m", "peak_contraction_m", "final_pressure_gauge_Pa", "at_rest_at_end",
                "events", "rhs_evaluations", "wall_time_s"):
        assert key in summary
    assert summary["at_rest_at_end"] is True
    assert (out / "acra2012_fig4.csv").read_text().startswith("t_s,x_m,v_m_s,p_gauge_Pa,")
    csv = np.loadtxt(out / "acra2012_fig4.csv", delimiter=",", skiprows=1)
    assert csv[-1, 1] == pytest.approx(summary["final_contraction_m"], rel=1e-9)
    assert (out / "acra2012_fig4.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_run_warns_outside_the_fitted_range(tmp_path, cli):
    sc = tmp_path / "high.toml"
    sc.write_text(BASE.replace("3.6", "4.4"))
    r = cli("run", sc, "-o", tmp_path / "o", "--no-plot")
    assert r.returncode == 0, r.stderr
    assert "warning" in r.stderr and "fitted" in r.stderr


def test_static_json_matches_hand_values(cli):
    r = cli("static", "--pressure-bar", "2.8", "--load-N", "12.74", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    x = out["equilibrium_contraction_m"]
    F = (-476.95 * x * x - 188.39 * x + 23.90) * 2.8 + 2562.4 * x * x - 245.48 * x - 11.56
    assert F == pytest.approx(12.74, abs=1e-6)
    assert out["max_load_N"] == pytest.approx(23.90 * 2.8 - 11.56, rel=1e-9)
    text = cli("static", "--pressure-bar", "2.8", "--load-N", "12.74")
    assert text.returncode == 0 and f"{x * 1e3:.3f} mm" in text.stdout


BAD_SCENARIOS = [
    # (id, edit applied to BASE, words the one-line message must contain)
    ("unknown key", lambda s: s.replace("weight_N", "weigth_N"), ["weigth_N", "weight_N"]),
    ("unknown section", lambda s: s.replace("[simulation]", "[simulaton]"), ["simulaton", "simulation"]),
    ("missing key", lambda s: s.replace("duration_s = 2.0", "sample_rate_Hz = 100.0"), ["duration_s", "missing"]),
    ("missing section", lambda s: s.replace("[load]\nweight_N = 22.74", ""), ["[load]", "missing"]),
    ("wrong type", lambda s: s.replace("duration_s = 2.0", 'duration_s = "2 s"'), ["duration_s", "2 s", "number"]),
    ("negative mass", lambda s: s.replace("weight_N = 22.74", "weight_N = -22.74"), ["weight_N", "-22.74", "positive"]),
    ("zero mass", lambda s: s.replace("weight_N = 22.74", "mass_kg = 0.0"), ["mass_kg", "0.0", "positive"]),
    ("nan", lambda s: s.replace("supply_gauge_bar = 3.6", "supply_gauge_bar = nan"), ["supply_gauge_bar", "nan"]),
    ("above rating", lambda s: s.replace("supply_gauge_bar = 3.6", "supply_gauge_bar = 6.0"),
     ["supply_gauge_bar", "6.0", "rating"]),
    ("unknown parameter", lambda s: s + "\n[parameters]\nvalve_C = 1e-9\n", ["valve_C", "valve_C_m3_per_s_Pa"]),
    ("infinite parameter", lambda s: s + "\n[parameters]\nvalve_b = inf\n", ["valve_b", "inf"]),
    ("unknown friction", lambda s: s + '\n[model]\nfriction = "coulomb"\n', ["friction", "coulomb"]),
    ("command out of range", lambda s: s.replace("valve_open_time_s = 1.0",
                                                 '[pressure.command]\nkind = "step"\ntime_s = 1.0\nfinal = 2.0'),
     ["command", "[-1, 1]"]),
    ("rtol", lambda s: s + "\n[solver]\nrtol = 0.5\n", ["rtol", "0.5"]),
    ("unknown method", lambda s: s + '\n[solver]\nmethod = "Euler"\n', ["method", "Euler"]),
    ("not toml", lambda s: s + "\nthis is = = not toml\n", ["TOML"]),
    ("missing trace", lambda s: s.replace('source = "valve"\nsupply_gauge_bar = 3.6\nvalve_open_time_s = 1.0',
                                          'source = "prescribed"\n[pressure.prescribed]\nkind = "trace"\nfile = "nope.csv"'),
     ["nope.csv", "not found"]),
    ("parameter out of range", lambda s: s + "\n[parameters]\nr0_m = 0.0\n", ["r0_m", "0.0", "> 0"]),
    ("inconsistent parameters", lambda s: s + "\n[parameters]\nvalve_b = 0.9995\n", ["valve_b", "valve_laminar_ratio"]),
    ("key of another signal kind", lambda s: s.replace("valve_open_time_s = 1.0",
                                                       '[pressure.command]\nkind = "step"\ntime_s = 1.0\nfinal = 1.0\ntau_s = 0.5'),
     ["tau_s", "step"]),
    ("trace without file", lambda s: s.replace('source = "valve"\nsupply_gauge_bar = 3.6\nvalve_open_time_s = 1.0',
                                               'source = "prescribed"\n[pressure.prescribed]\nkind = "trace"'),
     ["file", "missing"]),
    ("bad external force", lambda s: s.replace("weight_N = 22.74", 'weight_N = 22.74\nexternal_force = { kind = "pulse" }'),
     ["external_force", "pulse"]),
    ("too many samples", lambda s: s.replace("duration_s = 2.0", "duration_s = 2.0\nsample_rate_Hz = 1e9"),
     ["sample_rate_Hz", "samples"]),
    ("initial pressure above rating", lambda s: s.replace("valve_open_time_s = 1.0", "valve_open_time_s = 1.0\ninitial_gauge_bar = 9.0"),
     ["initial_gauge_bar", "rating"]),
    ("non-monotonic trace", lambda s: s.replace('source = "valve"\nsupply_gauge_bar = 3.6\nvalve_open_time_s = 1.0',
                                                'source = "prescribed"\n[pressure.prescribed]\nkind = "trace"\nfile = "bad.csv"'),
     ["bad.csv", "increase", "line 4"]),
    ("name leaving the output folder", lambda s: 'name = "../../escaped"\n' + s, ["name", "../../escaped", "'..'"]),
    ("max_step below its bound", lambda s: s + "\n[solver]\nmax_step_s = 1e-12\n", ["max_step_s", "1e-12", "at least"]),
    ("output too large", lambda s: s.replace("duration_s = 2.0", "duration_s = 9000.0"),
     ["sample_rate_Hz", "MB", "--max-csv-MB"]),
    ("name with a separator", lambda s: 'name = "sub/dir"\n' + s, ["name", "sub/dir", "separator"]),
]


def _code_err(cli, *args) -> tuple[int, str]:
    """Exit code and stderr of ``pamsim ARGS`` run in this process (the ``cli`` fixture)."""
    r = cli(*args)
    return r.returncode, r.stderr


@pytest.mark.parametrize("case_id, edit, words", BAD_SCENARIOS, ids=[c[0] for c in BAD_SCENARIOS])
def test_bad_scenario_exits_2_with_one_clear_line(tmp_path, cli, case_id, edit, words):
    (tmp_path / "bad.csv").write_text("t_s,p_gauge_bar\n0,0\n1,2\n0.5,3\n")
    sc = tmp_path / "case.toml"
    sc.write_text(edit(BASE))
    out = tmp_path / "out"
    code, err = _code_err(cli, "run", sc, "-o", out)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert str(sc) in lines[0]
    for word in words:
        assert word in lines[0], lines[0]
    assert not out.exists()


@pytest.mark.parametrize("case_id", ["unknown key", "nan", "not toml"])
def test_bad_scenario_through_the_console_script(tmp_path, case_id):
    """A representative few of the table above, as a user runs them (a separate process)."""
    edit, words = next((e, w) for c, e, w in BAD_SCENARIOS if c == case_id)
    sc = tmp_path / "case.toml"
    sc.write_text(edit(BASE))
    r = pamsim("run", sc, "-o", tmp_path / "out")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and all(w in r.stderr for w in words)
    assert not (tmp_path / "out").exists()


BAD_ARGS = [
    (["run", "does_not_exist.toml"], "does_not_exist.toml"),
    (["static", "--pressure-bar", "9", "--load-N", "10"], "--pressure-bar"),
    (["static", "--pressure-bar", "3", "--load-N", "-3"], "--load-N"),
    (["static", "--pressure-bar", "abc", "--load-N", "10"], "abc"),
    (["static", "--pressure-bar", "nan", "--load-N", "10"], "nan"),
    (["static", "--pressure-bar", "3", "--load-N", "10", "--set", "festo"], "festo"),
    (["run", str(SCENARIOS / "acra2012_fig4.toml"), "--max-csv-MB", "0"], "--max-csv-MB"),
]


@pytest.mark.parametrize("args, word", BAD_ARGS, ids=[" ".join(a[:2]) + " " + w for a, w in BAD_ARGS])
def test_bad_arguments_exit_2(args, word, tmp_path, cli, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = cli(*args)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and word in r.stderr


@pytest.mark.parametrize("args, words", [
    (["fit", "hysteresis", "loop.csv", "--model", "foo"], ["pamsim fit hysteresis: error: argument --model",
                                                           "'foo'", "see pamsim fit hysteresis --help"]),
    (["fit", "hysteresis", "loop.csv", "--thresholds-mm", "-1,2"], ["is written --thresholds-mm=VALUE"]),
    (["run"], ["pamsim run: error:", "scenario"]),
    (["run", "x.toml", "--no-figure"], ["pamsim run: error: unrecognized arguments: --no-figure",
                                        "see pamsim run --help"]),
    (["bogus"], ["pamsim: error:", "'bogus'"]),
], ids=["invalid choice", "value like an option", "missing argument", "unknown option", "unknown command"])
def test_a_mistake_in_the_arguments_is_one_line(args, words):
    """argparse's mistakes print one line naming the argument (not the usage block first), exit code 2."""
    r = pamsim(*args)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert all(w in r.stderr for w in words), r.stderr


def test_solver_failure_exits_3_and_leaves_nothing(tmp_path, cli):
    sc = tmp_path / "few.toml"
    sc.write_text(BASE + "\n[solver]\nmax_events = 1\n")
    out = tmp_path / "new" / "out"
    code, err = _code_err(cli, "run", sc, "-o", out)
    assert code == 3
    assert "max_events" in err and "Traceback" not in err
    assert not (tmp_path / "new").exists()  # neither the folder nor the parent the command created


def test_an_lsoda_failure_is_reported_once_with_its_reason(tmp_path, cli, monkeypatch):
    """scipy warns of an LSODA failure before pamsim reports it: the command prints pamsim's line only,
    which carries ODEPACK's reason (here zero absolute tolerances on a state at zero: illegal input)."""
    import warnings

    import pamsim.simulator

    segment = pamsim.simulator.integrate_segment

    def without_atol(*args, **kwargs):
        return segment(*args, **{**kwargs, "atol": 0.0 * np.asarray(kwargs["atol"])})

    monkeypatch.setattr(pamsim.simulator, "integrate_segment", without_atol)
    sc = tmp_path / "s.toml"
    sc.write_text(BASE)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        code, err = _code_err(cli, "run", sc, "-o", tmp_path / "out")
    assert code == 3 and "Traceback" not in err
    assert "pamsim: solver failure:" in err and "LSODA: Illegal input detected" in err
    assert not [w for w in shown if "lsoda" in str(w.message)], [str(w.message) for w in shown]
    assert not (tmp_path / "out").exists()


def test_late_write_error_and_interrupt_leave_no_folder(tmp_path, cli, monkeypatch):
    import os

    import pamsim.api

    sc = tmp_path / "ok.toml"
    sc.write_text(BASE)
    real_replace = os.replace

    def refuse_final_move(src, dst):
        if str(dst).endswith(".json"):
            raise OSError(28, "No space left on device")
        return real_replace(src, dst)

    monkeypatch.setattr(os, "replace", refuse_final_move)
    code, err = _code_err(cli, "run", sc, "-o", tmp_path / "full", "--no-plot")
    assert code == 2 and "No space left" in err
    assert not (tmp_path / "full").exists()
    monkeypatch.setattr(os, "replace", real_replace)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(pamsim.api, "run", interrupted)
    code, err = _code_err(cli, "run", sc, "-o", tmp_path / "stopped")
    assert code == 130 and not (tmp_path / "stopped").exists()


def test_existing_output_folder_is_kept_after_a_failure(tmp_path, cli):
    sc = tmp_path / "few.toml"
    sc.write_text(BASE + "\n[solver]\nmax_events = 1\n")
    out = tmp_path / "mine"
    out.mkdir()
    assert _code_err(cli, "run", sc, "-o", out)[0] == 3
    assert out.is_dir() and not any(out.iterdir())


def test_run_a_folder_runs_every_scenario_and_the_controller(tmp_path, cli):
    """`pamsim run scenarios/` runs each scenario file (not the sweep file), closed_loop_position with its
    controller: it must reach the 40 mm target; open loop the load would drop onto the stop."""
    out = tmp_path / "all"
    code, err = _code_err(cli, "run", SCENARIOS, "-o", out, "--no-plot")
    assert code == 0, err
    files = [p for p in SCENARIOS.glob("*.toml") if "base_scenario" not in p.read_text()]
    # A [compensation] study also writes its identification loop.
    stems = sorted([p.stem for p in files] + [f"{p.stem}_identification" for p in files
                                              if "[compensation]" in p.read_text()])
    assert sorted({p.stem for p in out.iterdir()}) == stems
    summary = json.loads((out / "closed_loop_position.json").read_text())
    controller = pamsim_toml(SCENARIOS / "closed_loop_position.toml")["controller"]
    target_m = controller["target_contraction_mm"] * 1e-3
    tolerance_m = controller["spec"]["steady_state_error_max_mm"] * 1e-3
    assert abs(summary["final_contraction_m"] - target_m) <= tolerance_m
    assert summary["controller"]["meets_spec"] is True
    csv = np.loadtxt(out / "closed_loop_position.csv", delimiter=",", skiprows=1, max_rows=3)
    assert csv[0, 1] == pytest.approx(0.020)  # held at the initial contraction, not dropped


def test_two_scenarios_with_one_name_are_refused(tmp_path, cli):
    for stem in ("a", "b"):
        (tmp_path / f"{stem}.toml").write_text('name = "same"\n' + BASE)
    code, err = _code_err(cli, "run", tmp_path / "a.toml", tmp_path / "b.toml", "-o", tmp_path / "o")
    assert code == 2 and "same" in err and not (tmp_path / "o").exists()


HEAVY_MODULES = ("scipy.integrate", "scipy.optimize", "matplotlib", "control", "fmpy")


@pytest.mark.parametrize("argv, heavy", [(["--help"], HEAVY_MODULES + ("numpy",)),
                                         (["static", "--pressure-bar", "3", "--load-N", "10"], HEAVY_MODULES)],
                         ids=["help", "static"])
def test_quick_commands_do_not_import_heavy_modules(argv, heavy):
    """`pamsim --help` and `pamsim static` must start fast: no integrators, optimizers, plotting,
    python-control or fmpy (and for --help not even numpy).  Counted in a fresh interpreter, not timed."""
    import subprocess
    import sys

    probe = ("import runpy, sys\n"
             f"sys.argv = ['pamsim', *{argv!r}]\n"
             "try:\n    runpy.run_module('pamsim', run_name='__main__')\nexcept SystemExit:\n    pass\n"
             f"heavy = sorted(m for m in sys.modules if m.startswith({heavy!r}))\n"
             "sys.stderr.write('HEAVY=' + ','.join(heavy) + '\\n')\n")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    line = next(ln for ln in r.stderr.splitlines() if ln.startswith("HEAVY="))
    assert line == "HEAVY=", line
    assert "usage" in r.stdout or "equilibrium" in r.stdout


def test_importing_the_main_module_runs_nothing():
    """The API reference's build imports every module of the package, ``pamsim.__main__`` among them."""
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-c", "import pamsim.__main__", "run"], capture_output=True, text=True,
                       timeout=120)
    assert (r.returncode, r.stdout, r.stderr) == (0, "", "")


@pytest.mark.parametrize("command", [
    ["run", SCENARIOS / "acra2012_fig4.toml", "-o"],
    ["sweep", SCENARIOS / "acra2012_grid.toml", "-o"],
    ["linearize", SCENARIOS / "acra2012_fig4.toml", "-o"],
], ids=["run", "sweep", "linearize"])
def test_output_folder_that_is_a_file_exits_2_before_running(tmp_path, cli, command):
    blocker = tmp_path / "taken"
    blocker.write_text("not a folder")
    for target in (blocker, blocker / "sub"):
        r = cli(*command, target)
        assert r.returncode == 2, r.stderr
        assert "Traceback" not in r.stderr and str(blocker) in r.stderr
        assert len(r.stderr.strip().splitlines()) == 1
    assert blocker.read_text() == "not a folder"


def test_output_files_get_ordinary_permissions(tmp_path, cli):
    import os
    import stat

    r = cli("run", SCENARIOS / "acra2012_fig4.toml", "-o", tmp_path / "o")
    assert r.returncode == 0
    umask = os.umask(0)
    os.umask(umask)
    for f in (tmp_path / "o").iterdir():
        assert stat.S_IMODE(f.stat().st_mode) == 0o666 & ~umask, f.name


def test_csv_size_limit_can_be_raised_and_its_estimate_bounds_the_file(tmp_path, cli):
    """A run refused for its output size runs with a higher --max-csv-MB; the estimate is an upper bound of
    the file written, and not a loose one (within a factor of three)."""
    from pamsim.result import Result
    from pamsim.simulator import n_samples

    sc = tmp_path / "small.toml"
    sc.write_text(BASE)
    code, err = _code_err(cli, "run", sc, "-o", tmp_path / "o", "--no-plot", "--max-csv-MB", "0.1")
    assert code == 2 and "--max-csv-MB" in err and not (tmp_path / "o").exists()
    code, err = _code_err(cli, "run", sc, "-o", tmp_path / "o", "--no-plot", "--max-csv-MB", "10")
    assert code == 0, err
    scenario = pamsim_load(sc)
    estimate = Result.csv_bytes_estimate(scenario.build_model(), n_samples(scenario.duration_s, 1000.0))
    actual = (tmp_path / "o" / "small.csv").stat().st_size
    assert actual <= estimate <= 3 * actual


def test_a_key_typed_with_a_newline_still_gives_one_line(tmp_path, cli):
    """Found by the fuzzing: unknown keys were quoted raw, so a key with a newline split the message."""
    sc = tmp_path / "nl.toml"
    sc.write_text(BASE.replace("valve_open_time_s = 1.0",
                               '[pressure.command]\nkind = "constant"\nvalue = 1.0\n"tau\\ns" = 1.0'))
    code, err = _code_err(cli, "run", sc, "-o", tmp_path / "o")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "tau\\ns" in err, err


def test_run_help_describes_every_backend(cli):
    """In the option's own help text, not only in argparse's list of choices."""
    from pamsim.backends import BACKENDS
    from pamsim.cli import build_parser

    run = build_parser()._subparsers._group_actions[0].choices["run"]
    backend = next(a for a in run._actions if "--backend" in a.option_strings)
    for name in BACKENDS:
        assert name in backend.help, name
    text = " ".join(cli("run", "--help").stdout.split())
    assert "native: the C core" in text


def test_version_prints_the_package_version():
    """``pamsim --version`` as a user runs it: the console script (where installed) and ``python -m pamsim``."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    from pamsim import __version__

    script = shutil.which("pamsim", path=str(Path(sys.executable).parent))
    runs = [pamsim("--version")]
    if script is not None:
        runs.append(subprocess.run([script, "--version"], capture_output=True, text=True, timeout=60))
    for r in runs:
        assert (r.returncode, r.stdout, r.stderr) == (0, f"pamsim {__version__}\n", ""), r.args
