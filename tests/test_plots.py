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
from pamsim.plotting import result_figure
from pamsim.sweep.plots import frequency_figure

from conftest import SCENARIOS


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
    assert "fmu-me" in ScenarioRun(res, "fmu-me").figure()._suptitle.get_text()
    assert "backend" not in ScenarioRun(res, "python").figure()._suptitle.get_text()


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
