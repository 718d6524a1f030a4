"""Step responses are checked against the scenario's muscle as static tests are: the impossible refused
(one line naming the file, column, data row and value; exit 2, nothing written), the implausible one
warning line each, the fit going on."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import pamsim
from pamsim.identification.columns import DataError, read_trace
from pamsim.identification.dynamic_fit import check_data

from conftest import SCENARIOS, run_main

FIG4 = SCENARIOS / "acra2012_fig4.toml"


def write_trace(path, header, x, p, **columns):
    """A 2 s trace at 1 kHz: ``x`` and ``p`` in the units the header names, any extra columns constant."""
    t = np.linspace(0.0, 2.0, 2001)
    xs = np.broadcast_to(np.asarray(x, dtype=float), t.shape)
    ps = np.broadcast_to(np.asarray(p, dtype=float), t.shape)
    extra = list(columns.values())
    lines = [",".join([header[0], header[1], header[2], *columns])]
    lines += [",".join(f"{v:.10g}" for v in (a, b, c, *extra)) for a, b, c in zip(t, xs, ps)]
    path.write_text("\n".join(lines) + "\n")
    return path


def ramp(top, n=2001):
    return np.linspace(0.0, top, n)


X_MAX_MM = 300.0 - 300.0 / math.cos(math.radians(20.0)) / math.sqrt(3.0)
"""The Shadow muscle's braid lock, L0 (1 - 1 / (sqrt(3) cos theta0)), written apart from the code."""
STOP_ROW = int(np.argmax(ramp(120.0) > X_MAX_MM))


@pytest.fixture(scope="module")
def scenario():
    return pamsim.load_scenario(FIG4)


@pytest.mark.parametrize("header, x, p, message", [
    (("t_s", "x_mm", "p_gauge_bar"), ramp(20.0), np.where(np.arange(2001) == 2, -1.5, 3.6),
     "column p_gauge_bar, data row 3: value -1.5: a gauge pressure below -1 atm"),
    (("t_s", "x_mm", "p_gauge_bar"), ramp(20.0), ramp(360000.0),
     "column p_gauge_bar, data row 2: value 180: above 100 bar gauge"),
    (("t_s", "x_m", "p_gauge_Pa"), ramp(20.0), ramp(3.6e5),
     "column x_m, data row 31: value 0.3: a contraction of at least the muscle's rest length 300 mm (mm labelled _m?)"),
])
def test_impossible_traces_are_refused_by_column_row_and_value(tmp_path, scenario, header, x, p, message):
    path = write_trace(tmp_path / "step.csv", header, x, p)
    with pytest.raises(DataError, match=re.escape(message)):
        check_data(scenario, [read_trace(path)])
    out = tmp_path / "never"
    proc = run_main("fit", "dynamic", path, "--scenario", FIG4, "--free", "N0_N_per_bar", "--backend", "native",
                    "-o", out)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and message in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and not out.exists()


@pytest.mark.parametrize("header, x, p, loads, message", [
    (("t_s", "x_mm", "p_gauge_Pa"), ramp(20.0), ramp(3.6), None,
     "column p_gauge_Pa, data row 2001: value 3.6: every pressure is below 1 kPa gauge (bar labelled _Pa?)"),
    (("t_s", "x_mm", "p_gauge_bar"), ramp(20.0), ramp(6.0), None,
     "column p_gauge_bar, data row 1502: value 4.503: above the muscle's rated pressure 4.5 bar"),
    (("t_s", "x_mm", "p_gauge_bar"), ramp(20.0) - 1.5, ramp(3.6), None,
     "column x_mm, data row 1: value -1.5: the muscle lengthened by more than 1 mm"),
    (("t_s", "x_mm", "p_gauge_bar"), ramp(0.02), ramp(3.6), None,
     "column x_mm, data row 2001: value 0.02: every contraction is below 1 mm (m labelled _mm?)"),
    (("t_s", "x_mm", "p_gauge_bar"), ramp(120.0), ramp(3.6), None,
     f"column x_mm, data row {STOP_ROW + 1}: value {0.06 * STOP_ROW:g}: beyond the muscle's upper stop 115.7 mm"),
    (("t_s", "x_mm", "p_gauge_bar"), ramp(20.0), ramp(3.6), [1000.0],
     "load 1000 N: more than twice the starting muscle's blocked force"),
])
def test_implausible_traces_give_one_warning_each(tmp_path, scenario, header, x, p, loads, message):
    path = write_trace(tmp_path / "step.csv", header, x, p)
    lines = check_data(scenario, [read_trace(path)], loads)
    assert len(lines) == 1 and message in lines[0] and str(path) in lines[0], lines


def test_a_plausible_trace_gives_no_warning_and_the_cli_prints_warnings(tmp_path, scenario):
    good = write_trace(tmp_path / "good.csv", ("t_s", "x_mm", "p_gauge_bar"), ramp(20.0), ramp(3.6))
    assert check_data(scenario, [read_trace(good)]) == []
    out = tmp_path / "fit"
    proc = run_main("fit", "dynamic", good, "--scenario", FIG4, "--free", "N0_N_per_bar", "--backend", "native",
                    "--starts", "0", "--max-iterations", "1", "--load-N", "1000", "-o", out)
    assert proc.returncode == 0, proc.stderr
    assert "warning: " in proc.stderr and "load 1000 N: more than twice" in proc.stderr
