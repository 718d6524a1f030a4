"""The atlas's figures: models that give the same curve are one line with one legend entry, told apart from
the curves' own values; the combined figure has no empty panel; a muscle's measured points are read from any
file whose columns carry their units (the data.csv a static fit writes beside its muscle.toml)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from pamsim.atlas import build_atlas, measured_points
from pamsim.atlas_plots import grid_shape, plot_all, plot_pressure
from pamsim.errors import InputError

from conftest import run_main

REDUCED_TO_GAYLORD = ("gaylord", "gaylord_normalised", "de_volder", "tondu_lopez")

MUSCLE = """name = "home_made"
description = "home-made 10 mm muscle"
citation = "own measurements"
default_static_force = "chou_hannaford"
rated_pressure_gauge_Pa = 5e5
[parameters.L0_m]
value = 0.15
source = "ruler"
[parameters.r0_m]
value = 0.005
source = "calliper"
[parameters.wall_thickness_m]
value = 0.001
source = "tube datasheet"
[parameters.theta0_deg]
value = 25.0
source = "sleeve pitch"
"""


def _equal_everywhere(atlas, a: str, b: str) -> bool:
    """Whether models a and b give the same curve at every pressure, judged here from the curves' values."""
    ca = {c.pressure_Pa: c for c in atlas.curves if c.model == a}
    cb = {c.pressure_Pa: c for c in atlas.curves if c.model == b}
    if ca.keys() != cb.keys():
        return False
    for p in ca:
        x, y = ca[p], cb[p]
        if not np.array_equal(x.x_m, y.x_m):
            return False
        if np.max(np.abs(x.F_N - y.F_N)) > 1e-9 * np.max(np.abs(np.concatenate([x.F_N, y.F_N]))):
            return False
    return True


@pytest.fixture(scope="module")
def kothera():
    """Kothera's actuator 5a: 17 models, four of which reduce to Gaylord's at their default corrections."""
    return build_atlas("kothera2009_5a", pressures_bar=[0.6895, 2.0684, 4.1368, 1.0, 3.0])


def test_models_are_grouped_exactly_when_their_curves_are_equal(kothera):
    groups = kothera.groups
    assert REDUCED_TO_GAYLORD in groups
    assert sorted(itertools.chain(*groups)) == sorted(kothera.models)  # every model in one group
    group_of = {m: i for i, g in enumerate(groups) for m in g}
    for a, b in itertools.combinations(kothera.models, 2):
        assert (group_of[a] == group_of[b]) == _equal_everywhere(kothera, a, b), (a, b)


def test_a_model_that_differs_is_not_grouped(tmp_path):
    """Tondu and Lopez's model with a correction away from its default is its own curve again."""
    atlas = build_atlas("kothera2009_5a", models=list(REDUCED_TO_GAYLORD), overrides={"tondu_kappa1": 1.2})
    assert atlas.groups == [REDUCED_TO_GAYLORD[:3], ("tondu_lopez",)]


def _data_lines(ax):
    return [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 2]


@pytest.mark.parametrize("figure", ["one pressure", "all pressures"])
def test_each_group_is_one_line_with_one_legend_entry(kothera, tmp_path, figure):
    labels = [" = ".join(g) for g in kothera.groups]
    if figure == "one pressure":
        axes = [plot_pressure(kothera, kothera.pressures_Pa[0], tmp_path / "p.png").axes[0]]
    else:
        axes = [ax for ax in plot_all(kothera, tmp_path / "all.png").axes if ax.get_lines()]
    assert len(axes) == (1 if figure == "one pressure" else 5)
    for ax in axes:
        lines = _data_lines(ax)
        assert [ln.get_label() for ln in lines] == labels
        assert "gaylord = gaylord_normalised = de_volder = tondu_lopez" in labels
        for a, b in itertools.combinations(lines, 2):  # nothing drawn on top of another
            assert not np.allclose(a.get_ydata(), b.get_ydata(), rtol=1e-6), (a.get_label(), b.get_label())
        # a group keeps its line style in every panel
        styles = {ln.get_label(): (ln.get_color(), ln.get_linestyle(), ln.get_marker()) for ln in lines}
        assert len(set(styles.values())) == len(styles)


def test_grid_leaves_at_most_one_free_cell():
    for n in range(1, 25):
        rows, cols = grid_shape(n)
        assert 0 <= rows * cols - n <= 1 and cols <= 4, n


@pytest.mark.parametrize("n_pressures", [1, 3, 4, 5, 6])
def test_the_combined_figure_has_no_empty_panel(tmp_path, n_pressures):
    pressures = [0.6895, 2.0684, 4.1368, 1.0, 3.0, 2.5][:n_pressures]
    atlas = build_atlas("kothera2009_5a", models=["gaylord", "zang", "neo_hookean"], pressures_bar=pressures)
    fig = plot_all(atlas, tmp_path / "all.svg")
    visible = [ax for ax in fig.axes if ax.get_visible()]
    panels = [ax for ax in visible if ax.axison]
    assert len(panels) == n_pressures and all(_data_lines(ax) for ax in panels)
    free = [ax for ax in visible if not ax.axison]
    rows, cols = grid_shape(n_pressures)
    if rows * cols > n_pressures:  # the free cell holds the legend
        assert len(free) == 1 and free[0].get_legend() is not None and not fig.legends
    else:
        assert not free and len(fig.legends) == 1
    assert len(fig.axes) == len(panels) + len(free)


def test_the_legend_names_measured_points_whichever_panel_has_them(tmp_path):
    """The survey's 45 mm muscle has one measured point, at 7.58 bar: here the second panel."""
    atlas = build_atlas("mpam_survey_45mm", models=["gaylord"], pressures_bar=[3.0, 7.58])
    fig = plot_all(atlas, tmp_path / "all.png")
    legend = fig.legends[0] if fig.legends else next(ax.get_legend() for ax in fig.axes if ax.get_legend())
    assert [t.get_text() for t in legend.get_texts()] == ["gaylord", "measured"]


# ---------------------------------------------------------------- measured points
@pytest.mark.parametrize("header, row, expected", [
    ("pressure_bar,contraction_mm,weight_N", "2.5,12.0,30", (2.5e5, 0.012, 30.0)),
    ("p_kPa,x_m,force_N", "250,0.012,30", (2.5e5, 0.012, 30.0)),
    ("weight_N,pressure_step_bar,pressure_stable_bar,contraction_stable_mm", "30,2.4,2.5,12.0", (2.5e5, 0.012, 30.0)),
    ("pressure_gauge_Pa,load_N,contraction_mm", "250000,30,12.0", (2.5e5, 0.012, 30.0)),
    ("pressure_psi,contraction_mm,weight_N", "10,12.0,30", (68947.57293168, 0.012, 30.0)),
    ("pressure_bar, contraction_mm, weight_N", "2.5, 12.0, 30", (2.5e5, 0.012, 30.0)),
])
def test_measured_points_are_found_by_their_units(tmp_path, header, row, expected):
    path = tmp_path / "points.csv"
    path.write_text(f"# a comment\n{header}\n{row}\n")
    assert measured_points(path) == pytest.approx(np.array([expected]), rel=1e-12)


def test_a_points_file_without_a_force_column_says_what_it_needs(tmp_path):
    path = tmp_path / "points.csv"
    path.write_text("pressure_bar,contraction_mm,mass_kg\n2,10,3\n")
    with pytest.raises(InputError, match=r"points.csv: no measured points: need a force or hung weight column "
                                         r"\(force\* or weight\* or load\* ending in _N\)"):
        measured_points(path)


def test_the_atlas_of_a_fitted_muscle_shows_the_data_it_was_fitted_to(tmp_path):
    """``pamsim fit static`` copies the data beside the muscle.toml it writes; the atlas of that muscle reads
    them, whatever the columns were called (they were refused before unless named as the ACRA tables)."""
    (tmp_path / "home_made.toml").write_text(MUSCLE)
    pressures, weights = np.meshgrid([2.0, 3.0, 4.0], [20.0, 40.0, 60.0])
    from pamsim.identification.equilibrium import equilibrium_m
    from pamsim.muscles import load_muscle

    model = load_muscle(tmp_path / "home_made.toml").static_force()
    x = equilibrium_m(model.force_N, pressures.ravel() * 1e5, weights.ravel(), 0.05)
    rows = "".join(f"{p:g},{1e3 * xi:.4f},{w:g}\n" for p, xi, w in zip(pressures.ravel(), x, weights.ravel()))
    (tmp_path / "tests.csv").write_text("pressure_bar,contraction_mm,weight_N\n" + rows)
    fit = tmp_path / "fit"
    r = run_main("fit", "static", tmp_path / "tests.csv", "--muscle", tmp_path / "home_made.toml", "-o", fit,
                 "--cv", "none")
    assert r.returncode == 0, r.stderr
    r = run_main("atlas", "--muscle", fit / "muscle.toml", "-o", tmp_path / "atlas")
    assert r.returncode == 0, r.stderr
    atlas = build_atlas(str(fit / "muscle.toml"))
    assert len(atlas.measured) == 9 and atlas.pressures_Pa == (2e5, 3e5, 4e5)
    assert atlas.measured[:, 1] == pytest.approx(np.round(x, 7), abs=1e-9)
