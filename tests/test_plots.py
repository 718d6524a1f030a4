"""Figures: sign conventions, held-time shading, one colour per force, backend in the title, and labels that
stay off the data.  Checked on the matplotlib objects (and their rendered positions), not on pixels."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

import pamsim
from pamsim.api import ScenarioRun
from pamsim.paperdata import acra2012_steady_state
from pamsim.plotting import result_figure
from pamsim.sweep.plots import frequency_figure

from conftest import PAPER_SCENARIOS, SCENARIOS, run_main


@pytest.fixture(scope="module")
def fig4_and_pulled():
    """fig4, and the same run without friction and with an external pull: one force line fewer in the
    middle of the legend and one more at its end."""
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    pulled = sc.with_changes({"model": {"friction": "none"},
                              "load": {"external_force": {"kind": "step", "time_s": 4.0, "final_N": -3.0}}})
    return pamsim.simulate(sc), pamsim.simulate(pulled)


def _force_colours(fig) -> dict[str, str]:
    ax_f = fig.axes[2]
    return {line.get_label(): line.get_color() for line in ax_f.get_lines() if not line.get_label().startswith("_")}


def test_each_force_keeps_its_colour_whichever_others_are_drawn(fig4_and_pulled):
    plain, pulled = (_force_colours(result_figure(r)) for r in fig4_and_pulled)
    assert "external" in pulled and "external" not in plain and "friction" not in pulled
    shared = set(plain) & set(pulled)
    assert {"static", "gravity", "damping", "stop contact"} <= shared
    for label in shared:
        assert plain[label] == pulled[label], label
    assert len(set(pulled.values())) == len(pulled)  # and no two forces share one


def test_axes_state_the_sign_conventions(fig4_and_pulled):
    fig = result_figure(fig4_and_pulled[0])
    x_label, f_label = fig.axes[0].get_ylabel(), fig.axes[2].get_ylabel()
    assert "positive" in x_label and "lifts the load" in x_label
    assert "positive lifts" in f_label


def test_time_on_the_lower_stop_is_shaded_like_stuck_time(fig4_and_pulled):
    """fig4 rests on its lower stop until the valve opens at 1 s, and sticks at the end."""
    res = fig4_and_pulled[0]
    ax_x = result_figure(res).axes[0]
    shades = {c.get_label(): c for c in ax_x.collections}
    assert {"on the lower stop", "stuck (friction)"} <= set(shades)
    xs = np.concatenate([p.vertices[:, 0] for p in shades["on the lower stop"].get_paths()])
    on_stop = res.t_s[res.mode == pamsim.Mode.STOP_LOW]
    assert xs.min() == pytest.approx(on_stop.min()) and xs.max() == pytest.approx(on_stop.max())
    assert on_stop.max() >= 1.0 - 1e-3  # the valve opens at 1 s


def test_backend_is_named_in_the_title_of_non_python_runs(fig4_and_pulled):
    res = fig4_and_pulled[0]
    assert "fmu-me backend (the exported FMU)" in ScenarioRun(res, "fmu-me").figure()._suptitle.get_text()
    assert "native backend (compiled C)" in ScenarioRun(res, "native").figure()._suptitle.get_text()
    assert "backend" not in ScenarioRun(res, "python").figure()._suptitle.get_text()


@pytest.fixture(scope="module")
def short_runs():
    """fig4 (a valve: the run has a supply pressure) cut to 2 s, the same with a prescribed pressure (no supply),
    and the parallel spring (a component added to the rig)."""
    fig4 = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes({"simulation": {"duration_s": 2.0}})
    spec = dict(fig4.spec)
    spec["pressure"] = {"source": "prescribed", "prescribed": {"kind": "lag", "time_s": 1.0, "tau_s": 0.05,
                                                               "final_gauge_bar": 3.0}}
    prescribed = pamsim.Scenario.from_dict(spec, name="prescribed", origin="test")
    spring = pamsim.load_scenario(SCENARIOS / "parallel_spring.toml").with_changes({"simulation": {"duration_s": 2.0}})
    return pamsim.simulate(fig4), pamsim.simulate(prescribed), pamsim.simulate(spring)


def _labelled(ax) -> dict:
    return {line.get_label(): line for line in ax.get_lines() if not line.get_label().startswith("_")}


def test_the_supply_pressure_is_drawn_only_for_a_run_that_has_one(short_runs):
    valve, prescribed, _ = short_runs
    lines = _labelled(result_figure(valve).axes[1])
    assert list(lines) == ["muscle", "supply"]
    assert np.array_equal(lines["supply"].get_ydata(), valve.signals["supply_gauge_Pa"] / 1e5)
    assert np.array_equal(lines["muscle"].get_ydata(), valve.p_gauge_Pa / 1e5)
    assert "supply_gauge_Pa" not in prescribed.signals
    assert list(_labelled(result_figure(prescribed).axes[1])) == ["muscle"]


def test_an_added_components_force_is_drawn_under_its_name_after_the_rigs(short_runs):
    spring = short_runs[2]
    lines = _labelled(result_figure(spring).axes[2])
    assert list(lines)[-1] == "spring" and "spring" not in _labelled(result_figure(short_runs[0]).axes[2])
    assert np.array_equal(lines["spring"].get_ydata(), spring.signals["spring.F_spring_N"])
    rig = {(ln.get_color(), ln.get_linestyle()) for label, ln in lines.items() if label != "spring"}
    assert (lines["spring"].get_color(), lines["spring"].get_linestyle()) not in rig


def test_compared_runs_are_overlaid_by_name_and_a_title_replaces_only_the_first_line(short_runs):
    valve, prescribed, spring = short_runs
    fig = result_figure(valve, title="my title", compare=[prescribed, spring])
    lines = _labelled(fig.axes[0])
    assert list(lines) == [valve.name, "prescribed", spring.name]
    assert np.array_equal(lines["prescribed"].get_ydata(), prescribed.x_m * 1e3)
    caption = fig._suptitle.get_text()
    assert caption.startswith("my title\n") and "damping added" in caption  # the damping note is kept
    assert "hanging weight" not in caption and "hanging weight" in result_figure(valve)._suptitle.get_text()


# ---------------------------------------------------------------- the paper's measured points
def _measured_lines(fig) -> dict[str, list]:
    """{axes y label: the lines labelled "measured ..."} of a run's figure."""
    return {ax.get_ylabel(): [ln for ln in ax.get_lines() if ln.get_label().startswith("measured")]
            for ax in fig.axes}


@pytest.mark.parametrize("name", sorted(PAPER_SCENARIOS))
def test_paper_scenarios_mark_the_measured_end_of_their_test(name):
    """Figures 3-6 of the ACRA 2012 paper draw traces it does not give as numbers; its Tables 1 and 2 give the
    end of each test.  The figure marks those two numbers, taken from pamsim.paperdata for the test the
    paper's caption names, and says that they are all there is."""
    step_bar, weight_N = PAPER_SCENARIOS[name]
    rows = acra2012_steady_state()
    row = rows[(rows["pressure_step_bar"] == step_bar) & (rows["weight_N"] == weight_N)]
    assert len(row) == 1
    sc = pamsim.load_scenario(SCENARIOS / f"{name}.toml")
    run = pamsim.run(sc.with_changes({"simulation": {"duration_s": 1.2}}))  # the measured values are the test's
    lines = _measured_lines(run.figure())
    (x_line,), (p_line,), () = lines.values()
    assert list(x_line.get_ydata()) == [row["contraction_stable_mm"][0]] * 2
    assert list(p_line.get_ydata()) == [row["pressure_stable_bar"][0]] * 2
    for line in (x_line, p_line):
        assert list(line.get_xdata()) == [6.0, 8.0]  # the paper's averaging window (its sec. 3.2)
        assert "mean over 6-8 s" in line.get_label()
    assert "final contraction" in x_line.get_label() and "stable pressure" in p_line.get_label()
    title = run.figure()._suptitle.get_text()
    assert "only the final contraction and pressure" in title and "Tables 1 and 2" in title
    assert all(not v for v in _measured_lines(run.figure(measured=False)).values())


def test_measured_end_follows_the_scenarios_conditions_not_its_name():
    rows = acra2012_steady_state()
    table2 = {(r["pressure_step_bar"], r["weight_N"]): r["contraction_stable_mm"] for r in rows}
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    assert sc.measured_steady_state().contraction_mm == table2[3.6, 22.74] == 59.67
    assert sc.with_changes({"load": {"weight_N": 32.74}}).measured_steady_state().contraction_mm == table2[3.6, 32.74]
    assert sc.with_changes({"load": {"mass_kg": 42.74 / 9.81}}).measured_steady_state().contraction_mm == \
        table2[3.6, 42.74]
    assert sc.with_changes({"load": {"weight_N": 30.0}}).measured_steady_state() is None  # no such test
    assert sc.with_changes({"pressure": {"supply_gauge_bar": 3.634}}).measured_steady_state() is None
    plain = dict(sc.spec)
    plain.pop("measured")
    assert pamsim.Scenario.from_dict(plain).measured_steady_state() is None  # opt-in


def test_pamsim_run_draws_the_measured_end_unless_told_not_to(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    saved = []
    original = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: (saved.append(fig), original(fig, *a, **k))[1])
    fig4 = SCENARIOS / "acra2012_fig4.toml"
    assert run_main("run", fig4, "-o", tmp_path / "a", "--no-progress", "--format", "svg").returncode == 0
    assert [len(v) for v in _measured_lines(saved[-1]).values()] == [1, 1, 0]
    assert "measured final contraction 59.67 mm" in (tmp_path / "a" / "acra2012_fig4.svg").read_text()
    assert run_main("run", fig4, "-o", tmp_path / "b", "--no-progress", "--no-measured").returncode == 0
    assert [len(v) for v in _measured_lines(saved[-1]).values()] == [0, 0, 0]
    other = tmp_path / "fig4_30N.toml"
    other.write_text(fig4.read_text().replace("weight_N = 22.74", "weight_N = 30.0"))
    r = run_main("run", other, "-o", tmp_path / "c", "--no-progress")
    assert r.returncode == 0 and "no measured test at a 3.6 bar supply step with 30 N" in r.stderr


def test_an_unknown_measured_data_set_is_refused_naming_the_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((SCENARIOS / "acra2012_fig4.toml").read_text().replace('steady_state = "acra2012"',
                                                                           'steady_state = "acra2013"'))
    r = run_main("run", bad, "-o", tmp_path / "out")
    assert r.returncode == 2 and "measured.steady_state" in r.stderr and "acra2013" in r.stderr
    assert "did you mean 'acra2012'" in r.stderr and not (tmp_path / "out").exists()


def test_negative_damping_energy_is_explained_in_the_caption_and_the_summary(fig4_and_pulled):
    """The paper's D1 < 0: below |v| = -D1/D2 its damping pushes the motion, so E_damping_J < 0."""
    res = fig4_and_pulled[0]
    assert res.energy_balance()["E_damping_J"] < 0
    caption = result_figure(res)._suptitle.get_text()
    note = res.summary()["energy_balance_note"]
    for text in (caption, note):
        assert "damping added" in text and "D1" in text and "< 0" in text
    dissipative = pamsim.simulate(pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes(
        {"model": {"damping": "linear"}}))
    assert dissipative.energy_balance()["E_damping_J"] > 0
    assert "damping" not in result_figure(dissipative)._suptitle.get_text()
    assert "energy_balance_note" not in dissipative.summary()


def test_frequency_figure_labels_stay_off_the_markers_and_lines():
    """Two friction models with nearly equal frequencies (the case where per-point labels collide)."""
    weights = [12.74, 22.74, 32.74, 42.74, 52.74, 62.74, 72.74]
    rows = []
    for i, w in enumerate(weights):
        f0 = 3.9 * math.sqrt(12.74 / w)
        rows.append({"weight_N": w, "load_dependent_frequency_Hz": f0, "load_dependent_n_half_cycles": 5 + i,
                     "constant_frequency_Hz": f0 * (1.01 if i % 2 else 0.99), "constant_n_half_cycles": 8 + i})
    result = SimpleNamespace(frequency_rows=rows, spec=SimpleNamespace(
        friction_models=("load_dependent", "constant"), frequency=SimpleNamespace(pressure_bar=3.6)))
    fig = frequency_figure(result)
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    labels = [t.get_window_extent(renderer) for ax in fig.axes for t in ax.texts]
    assert len(labels) == 2 * len(weights)
    for ax in fig.axes:
        for line in ax.get_lines():
            xy = line.get_transform().transform(line.get_xydata())
            # Sample each segment, and widen each point by the marker's radius (in pixels).
            pts = np.concatenate([a + np.linspace(0, 1, 50)[:, None] * (b - a) for a, b in zip(xy, xy[1:])])
            r = line.get_markersize() * fig.dpi / 72.0 / 2.0
            for box in labels:
                inside = ((pts[:, 0] > box.x0 - r) & (pts[:, 0] < box.x1 + r)
                          & (pts[:, 1] > box.y0 - r) & (pts[:, 1] < box.y1 + r))
                assert not inside.any(), (line.get_label(), box)


def test_the_sweeps_time_responses_mark_the_measured_end_of_each_paper_test():
    from pamsim.sweep import run_sweep, sweep_from_dict
    from pamsim.sweep.plots import time_responses_figure

    spec = sweep_from_dict({"base_scenario": "acra2012_fig4.toml", "friction_models": ["constant"],
                            "axes": {"pressure_bar": [3.6], "weight_N": [22.74]},
                            "time_responses": {"scenarios": ["acra2012_fig6b.toml", "parallel_spring.toml"]}},
                           base_dir=SCENARIOS)
    fig = time_responses_figure(run_sweep(spec))
    panels = {ax.get_title(): ax for ax in fig.axes if ax.get_title()}
    rows = acra2012_steady_state()
    row = rows[(rows["pressure_step_bar"] == 2.0) & (rows["weight_N"] == 22.74)]
    (line,) = [ln for ln in panels["acra2012_fig6b"].get_lines() if ln.get_label().startswith("measured")]
    assert list(line.get_ydata()) == [row["contraction_stable_mm"][0]] * 2 and list(line.get_xdata()) == [6.0, 8.0]
    # fig4 with a spring added names no measured test: nothing measured is drawn for it
    assert not [ln for ln in panels["parallel_spring"].get_lines() if ln.get_label().startswith("measured")]
    assert "the final contraction only" in fig._suptitle.get_text()


def _fake_sweep(runs: dict):
    """A sweep result with the given time responses ``{scenario: {friction: run output}}``, none measured."""
    scenarios = [SimpleNamespace(name=n, measured_steady_state=lambda: None) for n in runs]
    return SimpleNamespace(responses=runs, spec=SimpleNamespace(time_responses=scenarios))


def _response(scale: float) -> dict:
    t = np.linspace(0.0, 2.0, 5)
    return {"error": "", "t_s": t, "x_m": scale * t * 1e-3, "p_gauge_Pa": scale * t * 1e5}


def test_time_responses_say_which_runs_failed_and_take_the_pressure_from_the_first_that_did_not():
    from pamsim.sweep.plots import time_responses_figure

    fig = time_responses_figure(_fake_sweep({
        "a": {"load_dependent": {"error": "boom"}, "constant": _response(2.0)},
        "b": {"load_dependent": _response(1.0), "constant": _response(3.0)},
        "c": {"load_dependent": {"error": "boom"}, "constant": {"error": "lost: worker gone"}}}))
    grid, twins = fig.axes[:4], fig.axes[4:]
    assert [ax.get_title() for ax in grid] == ["a", "b", "c", ""] and not grid[3].axison  # 3 panels on 2 x 2
    assert [ax.get_xlabel() for ax in grid[:3]] == ["", "time [s]", "time [s]"]  # the bottom panel of each column
    assert [[t.get_text() for t in ax.texts] for ax in grid[:3]] == [
        ["load_dependent: failed"], [], ["load_dependent: failed", "constant: failed"]]
    assert [list(_labelled(ax)) for ax in grid[:3]] == [["constant friction"],
                                                        ["load_dependent friction", "constant friction"], []]
    pressures = [[line.get_ydata().tolist() for line in ax.get_lines()] for ax in twins]
    assert pressures == [[(2.0 * np.linspace(0.0, 2.0, 5)).tolist()], [np.linspace(0.0, 2.0, 5).tolist()], []]
    assert "measured" not in fig._suptitle.get_text()


def test_a_sweep_without_time_responses_draws_a_figure_that_says_so():
    from pamsim.sweep.plots import time_responses_figure

    fig = time_responses_figure(_fake_sweep({}))
    assert [t.get_text() for t in fig.axes[0].texts] == ["no [time_responses] in the sweep file"]
    assert not fig.axes[0].axison and fig._suptitle is None


def test_a_run_with_hysteresis_elements_draws_its_loops():
    """Under the time panels, a run with hysteresis elements gets the contraction against the pressure and the
    elements' force against the contraction, drawn from the run's own columns; a run without has no such row."""
    sc = pamsim.load_scenario(SCENARIOS / "hysteresis_loops.toml").with_changes({"simulation": {"duration_s": 15.0}})
    res = pamsim.simulate(sc)
    axes = result_figure(res).axes
    assert len(axes) == 5
    (p_line,), (f_line,) = axes[3].get_lines(), axes[4].get_lines()
    assert np.array_equal(p_line.get_xdata(), res.p_gauge_Pa / 1e5) and np.array_equal(p_line.get_ydata(), res.x_m * 1e3)
    assert np.array_equal(f_line.get_xdata(), res.x_m * 1e3)
    assert np.array_equal(f_line.get_ydata(), res.signals["hysteresis.F_N"])
    assert len(result_figure(pamsim.simulate(SCENARIOS / "acra2012_fig4.toml")).axes) == 3
