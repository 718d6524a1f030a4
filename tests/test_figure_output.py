"""Figures fit for a paper: every command that draws writes PNG, PDF or SVG (``--format``) at a chosen
resolution (``--dpi``), refuses a bad value in one line writing nothing, and the lines that share an axes
differ in style as well as in colour (grey print).  The commands run in this process, so the figures they
save can be inspected as matplotlib objects."""

from __future__ import annotations

import re
import struct

import pytest
from matplotlib.figure import Figure

import pamsim
from pamsim.errors import InputError
from pamsim.figure_style import LINE_STYLES, series
from pamsim.identification.columns import write_trace_csv
from pamsim.identification.synthetic import synthetic_trace
from pamsim.plotting import result_figure

from conftest import ROOT, SCENARIOS, run_cli, run_main

FIG4 = SCENARIOS / "acra2012_fig4.toml"
STATIC_DATA = ROOT / "pamsim" / "data" / "acra2012_steady_state.csv"
MAGIC = {"png": (b"\x89PNG\r\n\x1a\n",), "pdf": (b"%PDF-",), "svg": (b"<?xml", b"<svg")}

TINY_SWEEP = f"""
name = "tiny"
base_scenario = "{FIG4.as_posix()}"
friction_models = ["load_dependent", "constant"]
[axes]
pressure_bar = [3.6]
weight_N = [22.74]
[time_responses]
scenarios = ["{FIG4.as_posix()}"]
[frequency]
pressure_bar = 3.6
weight_N = [22.74, 32.74]
[uncertainty]
samples = 3
seed = 1
[uncertainty.parameters.valve_C_m3_per_s_Pa]
distribution = "uniform"
relative = true
lower = 0.9
upper = 1.1
"""


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """The files the commands read: a small sweep (cases, responses, frequency, uncertainty) and a step trace."""
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "tiny.toml").write_text(TINY_SWEEP)
    noisy, _ = synthetic_trace(pamsim.load_scenario(FIG4), {"N0_N_per_bar": 6.0}, 22.74, duration_s=2.0, seed=4)
    write_trace_csv(noisy, folder / "step.csv")
    return folder


def _commands(inputs) -> dict[str, tuple[list, list[str]]]:
    """``{command: (arguments before -o, figure stems it writes)}``; the sweep runs in this process."""
    return {
        "run": (["run", FIG4, "--no-progress"], ["acra2012_fig4"]),
        "atlas": (["atlas", "--muscle", "kothera2009_5a", "--pressures-bar", "2.0684"], ["atlas_2.0684bar", "atlas_all"]),
        "linearize": (["linearize", FIG4], ["acra2012_fig4_linear_bode", "acra2012_fig4_linear_pzmap"]),
        "sweep": (["sweep", inputs / "tiny.toml", "--workers", "1", "--no-progress"],
                  ["error_heatmap", "steady_state_vs_pressure", "time_responses", "frequency_vs_load",
                   "uncertainty_histograms", "uncertainty_ecdf"]),
        "fit static": (["fit", "static", STATIC_DATA, "--cv", "none", "--compare", "acra2012_polynomial"],
                       ["fit", "residuals", "correlation", "compare"]),
        "fit dynamic": (["fit", "dynamic", inputs / "step.csv", "--scenario", FIG4, "--free", "N0_N_per_bar",
                         "--window", "0.9:2.0", "--workers", "1", "--max-iterations", "2"], ["fit", "correlation"]),
    }


COMMANDS = ["run", "atlas", "linearize", "sweep", "fit static", "fit dynamic"]


def _same_style_lines(fig: Figure) -> list[str]:
    """Lines drawn as lines (not markers alone, not a reference line across the axes) that share an axes and
    a (line style, marker) with another: they would differ by colour only."""
    problems = []
    for ax in fig.axes:
        seen = {}
        for line in ax.get_lines():
            if line.get_linestyle() in ("None", "") or len(line.get_xdata()) <= 2:
                continue
            key = (line.get_linestyle(), line.get_marker())
            if key in seen:
                problems.append(f"{ax.get_title() or ax.get_ylabel()!r}: {seen[key]!r} and {line.get_label()!r}")
            seen[key] = line.get_label()
    return problems


@pytest.fixture(scope="module")
def written(inputs, tmp_path_factory):
    """Each command run once per vector format: ``{(command, format): (folder, stdout, figures saved)}``."""
    out = {}
    saved: list[Figure] = []
    original = Figure.savefig

    def recording(fig, *args, **kwargs):
        saved.append(fig)
        return original(fig, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", recording)
        for name, (args, _) in _commands(inputs).items():
            for fmt in ("pdf", "svg"):
                folder = tmp_path_factory.mktemp(name.replace(" ", "_")) / fmt
                saved.clear()
                r = run_main(*args, "-o", folder, "--format", fmt)
                assert r.returncode == 0, (name, fmt, r.stderr)
                out[name, fmt] = folder, r.stdout, list(saved)
    return out


@pytest.mark.parametrize("fmt", ["pdf", "svg"])
@pytest.mark.parametrize("command", COMMANDS)
def test_each_command_writes_its_figures_in_the_format_asked(written, inputs, command, fmt):
    folder, stdout, _ = written[command, fmt]
    stems = _commands(inputs)[command][1]
    figures = sorted(p.name for p in folder.iterdir() if p.suffix in (".png", ".pdf", ".svg"))
    assert figures == sorted(f"{stem}.{fmt}" for stem in stems)
    for name in figures:
        head = (folder / name).read_bytes()[:64].lstrip()
        assert head.startswith(MAGIC[fmt]), (name, head)
        assert name in stdout  # the "wrote ..." line names it
    for report in folder.glob("*.md"):  # the reports link the files written
        for link in re.findall(r"!\[[^]]*\]\(([^)]+)\)", report.read_text()):
            assert (folder / link).is_file() and link.endswith(f".{fmt}"), (report.name, link)


@pytest.mark.parametrize("command", COMMANDS)
def test_lines_on_one_axes_differ_in_style_not_only_in_colour(written, command):
    figures = written[command, "pdf"][2]
    assert figures
    for fig in figures:
        assert _same_style_lines(fig) == [], fig._suptitle.get_text() if fig._suptitle else command


def test_a_figure_with_several_lines_on_one_axes_uses_several_line_styles():
    res = pamsim.simulate(FIG4)
    ax_f = result_figure(res).axes[2]
    forces = [line for line in ax_f.get_lines() if not line.get_label().startswith("_")]
    assert len(forces) >= 3
    assert len({line.get_linestyle() for line in forces}) > 1
    assert len({(line.get_linestyle(), line.get_marker()) for line in forces}) == len(forces)
    assert len({line.get_color() for line in forces}) == len(forces)


def test_series_styles_stay_distinct_for_forty_lines():
    keys = {(series(k)["linestyle"], series(k).get("marker")) for k in range(40)}
    assert len(keys) == 40
    assert [series(k)["linestyle"] for k in range(4)] == list(LINE_STYLES)
    assert all("marker" not in series(k) for k in range(4))  # a few lines: plain line styles
    points = {(series(k, points=True)["linestyle"], series(k, points=True)["marker"]) for k in range(36)}
    assert len(points) == 36


def _png_size(path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == MAGIC["png"][0] and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_dpi_sets_the_pixel_size_of_a_png(tmp_path):
    """fig4's figure is 9 x 9 inches: 990 pixels at the default 110 dots per inch, 495 at 55."""
    assert run_main("run", FIG4, "-o", tmp_path / "default", "--no-progress").returncode == 0
    assert run_main("run", FIG4, "-o", tmp_path / "low", "--dpi", "55", "--no-progress").returncode == 0
    assert _png_size(tmp_path / "default" / "acra2012_fig4.png") == (990, 990)
    assert _png_size(tmp_path / "low" / "acra2012_fig4.png") == (495, 495)


def test_atlas_keeps_its_own_default_resolution_until_dpi_is_given(tmp_path):
    args = ["atlas", "--muscle", "kothera2009_5a", "--pressures-bar", "2.0684"]
    assert run_main(*args, "-o", tmp_path / "a").returncode == 0
    assert run_main(*args, "-o", tmp_path / "b", "--dpi", "50").returncode == 0
    assert _png_size(tmp_path / "a" / "atlas_2.0684bar.png") == (880, 605)  # 8 x 5.5 in at 110
    # one 4.2 x 3.4 in panel and a legend as wide as its longest entry, "gaylord = ... = tondu_lopez" (54
    # characters: 0.6 + 0.055 x 54 in): 7.77 x 3.4 in, at 100 dots per inch unless --dpi says otherwise
    assert _png_size(tmp_path / "a" / "atlas_all.png") == (777, 340)
    assert _png_size(tmp_path / "b" / "atlas_2.0684bar.png") == (400, 275)
    assert _png_size(tmp_path / "b" / "atlas_all.png") == (388, 170)


BAD = [("--format", "bmp", "not a figure format (choose png, pdf or svg)"),
       ("--dpi", "0", "must be a whole number of dots per inch from 1 to 1200"),
       ("--dpi", "-5", "must be a whole number of dots per inch from 1 to 1200"),
       ("--dpi", "abc", "must be a whole number of dots per inch from 1 to 1200")]


@pytest.mark.parametrize("flag, value, why", BAD, ids=[f"{f} {v}" for f, v, _ in BAD])
@pytest.mark.parametrize("command", COMMANDS)
def test_bad_format_or_dpi_is_one_line_exit_2_and_writes_nothing(inputs, tmp_path, command, flag, value, why):
    args = _commands(inputs)[command][0]
    out = tmp_path / "never"
    r = run_main(*args, "-o", out, flag, value)
    assert r.returncode == 2, r.stderr
    assert r.stderr == f"pamsim: error: {flag} {value}: {why}\n" and r.stdout == ""
    assert not out.exists()


def test_bad_format_as_the_user_sees_it(tmp_path):
    r = run_cli("run", FIG4, "-o", tmp_path / "never", "--format", "bmp")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr == "pamsim: error: --format bmp: not a figure format (choose png, pdf or svg)\n"
    assert not (tmp_path / "never").exists()


def test_result_plot_takes_the_format_from_the_suffix_and_a_dpi(tmp_path):
    res = pamsim.simulate(FIG4)
    for fmt in ("png", "pdf", "svg"):
        res.plot(tmp_path / f"fig4.{fmt}", dpi=40)
        assert (tmp_path / f"fig4.{fmt}").read_bytes()[:64].lstrip().startswith(MAGIC[fmt])
    assert _png_size(tmp_path / "fig4.png") == (360, 360)
    with pytest.raises(InputError, match=r"fig4\.bmp: suffix bmp: not a figure format"):
        res.plot(tmp_path / "fig4.bmp")
    with pytest.raises(InputError, match="dpi 0: must be a whole number"):
        res.plot(tmp_path / "zero.png", dpi=0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig4.pdf", "fig4.png", "fig4.svg"]
