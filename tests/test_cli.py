"""The command line end to end, through subprocess, as a user runs it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import SCENARIOS
from conftest import run_cli as pamsim

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


def test_run_warns_outside_the_fitted_range(tmp_path):
    sc = tmp_path / "high.toml"
    sc.write_text(BASE.replace("3.6", "4.4"))
    r = pamsim("run", sc, "-o", tmp_path / "o", "--no-plot")
    assert r.returncode == 0, r.stderr
    assert "warning" in r.stderr and "fitted" in r.stderr


def test_static_json_matches_hand_values():
    r = pamsim("static", "--pressure-bar", "2.8", "--load-N", "12.74", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    x = out["equilibrium_contraction_m"]
    F = (-476.95 * x * x - 188.39 * x + 23.90) * 2.8 + 2562.4 * x * x - 245.48 * x - 11.56
    assert F == pytest.approx(12.74, abs=1e-6)
    assert out["max_load_N"] == pytest.approx(23.90 * 2.8 - 11.56, rel=1e-9)
    text = pamsim("static", "--pressure-bar", "2.8", "--load-N", "12.74")
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
]


@pytest.mark.parametrize("case_id, edit, words", BAD_SCENARIOS, ids=[c[0] for c in BAD_SCENARIOS])
def test_bad_scenario_exits_2_with_one_clear_line(tmp_path, case_id, edit, words):
    (tmp_path / "bad.csv").write_text("t_s,p_gauge_bar\n0,0\n1,2\n0.5,3\n")
    sc = tmp_path / "case.toml"
    sc.write_text(edit(BASE))
    out = tmp_path / "out"
    r = pamsim("run", sc, "-o", out)
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr
    assert str(sc) in lines[0]
    for word in words:
        assert word in lines[0], lines[0]
    assert not out.exists() or not any(out.iterdir())


BAD_ARGS = [
    (["run", "does_not_exist.toml"], "does_not_exist.toml"),
    (["static", "--pressure-bar", "9", "--load-N", "10"], "--pressure-bar"),
    (["static", "--pressure-bar", "3", "--load-N", "-3"], "--load-N"),
    (["static", "--pressure-bar", "abc", "--load-N", "10"], "abc"),
    (["static", "--pressure-bar", "nan", "--load-N", "10"], "nan"),
    (["static", "--pressure-bar", "3", "--load-N", "10", "--set", "festo"], "festo"),
]


@pytest.mark.parametrize("args, word", BAD_ARGS, ids=[" ".join(a[:2]) + " " + w for a, w in BAD_ARGS])
def test_bad_arguments_exit_2(args, word, tmp_path):
    r = pamsim(*args, cwd=tmp_path)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and word in r.stderr


def test_solver_failure_exits_3_and_leaves_nothing(tmp_path):
    sc = tmp_path / "few.toml"
    sc.write_text(BASE + "\n[solver]\nmax_events = 1\n")
    out = tmp_path / "out"
    r = pamsim("run", sc, "-o", out)
    assert r.returncode == 3
    assert "max_events" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("command", [
    ["run", SCENARIOS / "acra2012_fig4.toml", "-o"],
    ["sweep", SCENARIOS / "acra2012_grid.toml", "-o"],
    ["linearize", SCENARIOS / "acra2012_fig4.toml", "-o"],
], ids=["run", "sweep", "linearize"])
def test_output_folder_that_is_a_file_exits_2_before_running(tmp_path, command):
    blocker = tmp_path / "taken"
    blocker.write_text("not a folder")
    for target in (blocker, blocker / "sub"):
        r = pamsim(*command, target)
        assert r.returncode == 2, r.stderr
        assert "Traceback" not in r.stderr and str(blocker) in r.stderr
        assert len(r.stderr.strip().splitlines()) == 1
    assert blocker.read_text() == "not a folder"


def test_output_files_get_ordinary_permissions(tmp_path):
    import os
    import stat

    r = pamsim("run", SCENARIOS / "acra2012_fig4.toml", "-o", tmp_path / "o")
    assert r.returncode == 0
    umask = os.umask(0)
    os.umask(umask)
    for f in (tmp_path / "o").iterdir():
        assert stat.S_IMODE(f.stat().st_mode) == 0o666 & ~umask, f.name
