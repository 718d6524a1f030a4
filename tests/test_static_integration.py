"""The static-model library in the dynamics: muscles in scenarios, clipping, tables, CLI, sweeps."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.elements.force_clip import ClippedStaticForce
from pamsim.elements.force_table import clear_cache, table_error, tabulate
from pamsim.muscles import load_muscle
from pamsim.parameters import DYNAMICS_DEFAULTS, dynamics_parameters, get_parameter_set
from pamsim.scenario import ScenarioError
from pamsim.static_models import REGISTRY, Domain, StaticForce
from pamsim.sweep import run_sweep, sweep_from_dict

from conftest import run_cli, run_main

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
SHADOW = get_parameter_set("shadow_6x300_acra2012")

# Three muscles of different size and source, each with a supply pressure it was tested at and a load
# (None: 30 % of its default model's blocked force there).
MUSCLES = {"shadow_6x300_acra2012": (3.6, 22.74), "kothera2009_5a": (4.0, None), "mpam_survey_45mm": (7.58, 0.05)}


def _spec(muscle: str, model: str | None = None, **model_keys) -> dict:
    pbar, weight = MUSCLES.get(muscle, (3.0, 10.0))
    if weight is None:
        weight = 0.3 * float(load_muscle(muscle).static_force().force_N(0.0, pbar * 1e5))
    m = {"muscle": muscle, **model_keys}
    if model:
        m["static_force"] = model
    return {"model": m, "load": {"weight_N": weight},
            "pressure": {"source": "valve", "supply_gauge_bar": pbar, "valve_open_time_s": 0.1},
            "simulation": {"duration_s": 1.0, "sample_rate_Hz": 200.0}}


# ---------------------------------------------------------------- scenarios name a muscle
def test_parameter_set_and_muscle_name_the_same_muscle():
    a = pamsim.Scenario.from_dict({**_spec("shadow_6x300_acra2012"), "model": {"parameter_set": "shadow_6x300_acra2012"}})
    b = pamsim.Scenario.from_dict(_spec("shadow_6x300_acra2012"))
    assert dict(a.parameters) == dict(b.parameters)
    assert a.spec["model"]["static_force"] == "acra2012_polynomial"  # the muscle's default model


def test_shadow_parameters_come_from_its_muscle_file_only():
    m = load_muscle("shadow_6x300_acra2012")
    # The file gives every dynamics value itself: no assumed default is added to the Shadow muscle.
    assert set(SHADOW) == set(m.parameters)
    assert all(SHADOW.entries[k].source == m.parameters.entries[k].source for k in SHADOW)


def test_other_muscles_take_the_assumed_dynamics_defaults_and_the_file_wins():
    m = load_muscle("mpam_survey_45mm")
    p = dynamics_parameters(m.parameters)
    for name, (value, source) in DYNAMICS_DEFAULTS.items():
        if name in m.parameters:
            assert p[name] == m.parameters[name]
        else:
            assert p[name] == value and p.entries[name].source == source
            assert source.startswith("assumed") or "ISO" in source or "standard" in source or "gas constant" in source \
                or "ACRA" in source


def test_muscle_path_is_relative_to_the_scenario(tmp_path):
    text = "\n".join(line for line in (ROOT / "pamsim" / "muscles" / "mpam_survey_45mm.toml").read_text().splitlines()
                     if not line.startswith("[data]") and not line.startswith("file ="))
    (tmp_path / "my").mkdir()
    (tmp_path / "my" / "mini.toml").write_text(text.replace('name = "mpam_survey_45mm"', 'name = "mini"'))
    sc = tmp_path / "s.toml"
    sc.write_text('[model]\nmuscle = "my/mini.toml"\nstatic_force = "gaylord"\n[load]\nweight_N = 0.05\n'
                  '[pressure]\nsource = "valve"\nsupply_gauge_bar = 7.58\nvalve_open_time_s = 0.1\n'
                  '[simulation]\nduration_s = 0.5\n')
    s = pamsim.load_scenario(sc)
    assert s.muscle.name == "mini"
    # Gaylord's free contraction at 0.05 N, from its own formula (second implementation: brentq on the
    # closed form F = p (3 L^2 - b^2) / (4 pi N^2) - W).
    g = s.static_model()
    res = pamsim.simulate(s)
    assert res.x_m[-1] == pytest.approx(g.free_contraction_m(7.58e5, 0.05), abs=1e-4)


@pytest.mark.parametrize("model, extra, words", [
    ("gaylrd", {}, ["model.static_force", "gaylrd", "gaylord"]),
    ("chou_hannaford", {}, ["model.static_force", "chou_hannaford", "wall_thickness_m", "shadow_6x300_acra2012"]),
    ("gaylord", {"static_force_negative": "push"}, ["static_force_negative", "push"]),
    ("gaylord", {"static_force_variant": "nope"}, ["static_force_variant", "nope"]),
])
def test_bad_model_choices_name_key_and_value(model, extra, words):
    with pytest.raises(ScenarioError) as exc:
        pamsim.Scenario.from_dict(_spec("shadow_6x300_acra2012", model, **extra), origin="x.toml")
    msg = str(exc.value)
    assert msg.startswith("x.toml: ") and "\n" not in msg
    for w in words:
        assert w in msg


def test_unknown_muscle_and_both_keys_are_refused():
    with pytest.raises(ScenarioError, match="model.muscle = 'kothera2009_5x'.*kothera2009_5"):
        pamsim.Scenario.from_dict(_spec("kothera2009_5x"))
    spec = _spec("shadow_6x300_acra2012")
    spec["model"]["parameter_set"] = "shadow_6x300_acra2012"
    with pytest.raises(ScenarioError, match="either muscle or parameter_set"):
        pamsim.Scenario.from_dict(spec)


def test_overrides_apply_to_muscle_parameters_and_add_known_ones():
    spec = _spec("shadow_6x300_acra2012", "chou_hannaford")
    spec["parameters"] = {"wall_thickness_m": 5e-4, "r0_m": 0.0031}
    s = pamsim.Scenario.from_dict(spec)
    assert s.parameters["wall_thickness_m"] == 5e-4 and s.parameters["r0_m"] == 0.0031
    spec["parameters"] = {"wall_thickness_m": 0.004}
    with pytest.raises(ScenarioError, match="parameters.r0_m = 0.003: must exceed the bladder wall thickness"):
        pamsim.Scenario.from_dict(spec)
    spec["parameters"] = {"theta0_deg": 60.0}
    with pytest.raises(ScenarioError, match="parameters.theta0_deg = 60.0"):
        pamsim.Scenario.from_dict(spec)


def test_chamber_volume_follows_the_muscle_geometry():
    """V(0) is the cylinder pi r0^2 L0 plus the dead volume, for every muscle (hand calculation)."""
    for name in MUSCLES:
        s = pamsim.Scenario.from_dict(_spec(name))
        p = s.parameters
        V0 = s.build_model().source.chamber.volume_m3(0.0)
        assert V0 == pytest.approx(math.pi * p["r0_m"] ** 2 * p["L0_m"] + p["dead_volume_m3"], rel=1e-12)


# ---------------------------------------------------------------- clipping
def test_negative_force_is_clipped_unless_kept():
    raw = REGISTRY["acra2012_polynomial"].build(SHADOW)
    assert raw.force_N(0.0, 0.0) == pytest.approx(-11.56)  # the paper's S3: a push at zero pressure
    clipped = pamsim.Scenario.from_dict(_spec("shadow_6x300_acra2012")).build_model().static_force
    kept = pamsim.Scenario.from_dict(_spec("shadow_6x300_acra2012", static_force_negative="keep")).build_model()
    assert clipped.force_N(0.0, 0.0) == 0.0 and kept.static_force.force_N(0.0, 0.0) == pytest.approx(-11.56)
    x = np.linspace(0, 0.07, 50)
    p = np.linspace(0, 4e5, 50)
    assert np.array_equal(clipped.force_N(x, p), np.maximum(raw.force_N(x, p), 0.0))
    assert all(clipped.force_N(float(a), float(b)) == max(raw.force_N(float(a), float(b)), 0.0) for a, b in zip(x, p))


def test_clipping_changes_a_fall_under_exhaust():
    """A fast exhaust under a light load: the raw polynomial goes negative and pushes the load down,
    the clipped force only stops pulling, so the load reaches the lower stop later (never above it)."""
    spec = _spec("shadow_6x300_acra2012")
    spec["load"] = {"weight_N": 2.74}
    spec["pressure"] = {"source": "prescribed", "prescribed": {"kind": "ramp", "start_s": 0.0, "end_s": 0.02,
                                                               "initial_gauge_bar": 3.0, "final_gauge_bar": 0.0}}
    spec["simulation"] = {"duration_s": 0.5, "sample_rate_Hz": 1000.0, "initial_contraction_m": 0.04}
    spec["model"]["friction"] = "none"
    clip = pamsim.simulate(pamsim.Scenario.from_dict(spec))
    spec["model"]["static_force_negative"] = "keep"
    keep = pamsim.simulate(pamsim.Scenario.from_dict(spec))
    assert np.all(clip.x_m >= keep.x_m - 1e-9)
    assert np.argmax(clip.x_m <= 0.0) > np.argmax(keep.x_m <= 0.0) + 50  # 50 ms later at 1 kHz
    assert np.min(clip.signals["F_static_N"]) >= 0.0 and np.min(keep.signals["F_static_N"]) < -1.0


# ---------------------------------------------------------------- tables for implicit models
class _Affine(StaticForce):
    """F = (a x^2 + c) p + e x: affine in p, quadratic in x (known second derivative 2 a p)."""

    name = "affine_test"

    def __init__(self, a, c, e):
        self.a, self.c, self.e = a, c, e
        self.domain = Domain(0.0, 0.05, 0.0, 5e5)

    def force_N(self, x_m, p_gauge_Pa):
        return (self.a * x_m * x_m + self.c) * p_gauge_Pa + self.e * x_m


class _Smooth(StaticForce):
    """F = sin(40 x) p / 1e4 + exp(-p / 3e5) (smooth, neither polynomial in x nor in p)."""

    name = "smooth_test"
    domain = Domain(0.0, 0.05, 0.0, 5e5)

    def force_N(self, x_m, p_gauge_Pa):
        return np.sin(40.0 * x_m) * p_gauge_Pa / 1e4 + np.exp(-p_gauge_Pa / 3e5)


def test_the_table_spline_is_exact_for_cubics_and_fourth_order_otherwise():
    """The bicubic interpolating spline reproduces a force quadratic in x and affine in p to rounding, and
    on a smooth force its cell-centre error falls 16-fold when the spacing halves (fourth order)."""
    m = _Affine(-400.0, 2e-4, -300.0)
    t = tabulate(m, (0.0, 0.1), (0.0, 1e6), n_x=51, n_p=6)
    assert table_error(m, t) < 1e-9 * abs(float(m.force_N(0.05, 5e5)))
    smooth = _Smooth()
    errors = [table_error(smooth, tabulate(smooth, (0.0, 0.05), (0.0, 5e5), n_x=n, n_p=n, refine_tol=None))
              for n in (17, 33, 65)]
    ratios = [errors[k] / errors[k + 1] for k in range(2)]
    assert all(13.0 < r < 19.0 for r in ratios), ratios
    # Exact on the grid nodes, and scalar and array paths agree, also outside the grid, where the force is
    # held at the grid's edge rather than extrapolated.
    X, P = np.meshgrid(t.x_grid_m, t.p_grid_Pa, indexing="ij")
    assert np.allclose(t.force_N(X, P), m.force_N(X, P), rtol=1e-12, atol=1e-9)
    xs, ps = np.linspace(-0.01, 0.06, 37), np.linspace(-1e4, 5.5e5, 37)
    assert np.allclose([t.force_N(float(a), float(b)) for a, b in zip(xs, ps)], t.force_N(xs, ps), rtol=1e-12, atol=1e-9)
    assert t.force_N(0.07, 6e5) == pytest.approx(float(m.force_N(0.05, 5e5)), rel=1e-12)
    assert t.force_N(-0.01, -1e4) == pytest.approx(float(m.force_N(0.0, 0.0)), abs=1e-9)


@pytest.mark.parametrize("muscle, model, overrides", [
    ("kothera2009_5a", "kothera_energy", {}), ("mpam_survey_45mm", "chou_hannaford", {}),
    ("kothera2009_5a", "kothera_force_balance_thickness", {}),
    ("mpam_survey_45mm", "mpam_two_phase", {"E_nylon_Pa": 3e9}),  # nylon 6: 2-4 GPa
])
def test_default_table_is_within_0p1_percent_of_the_blocked_force(muscle, model, overrides):
    """Judged by the force the dynamics apply, max(F, 0), at the cell centres and between them: the upper
    stop of a muscle without fibre data is the end of its model's domain, where a bladder model's push
    diverges (-1.2e8 N for kothera_energy on 5a at its last node), and the two-phase model has a kink
    where the tube meets the sleeve; the grid follows both (on a uniform grid the spline rings back from
    the first and misses the second by 0.33 %)."""
    p = {**dynamics_parameters(load_muscle(muscle).parameters), **overrides}
    m = REGISTRY[model].build(p)
    x_hi = pamsim.Scenario.from_dict({**_spec(muscle, model), "parameters": overrides}).build_model().stops.x_high_m
    t = tabulate(m, (0.0, x_hi), (0.0, p["rated_pressure_gauge_Pa"]))
    x, p_grid = t.x_grid_m, t.p_grid_Pa
    xs = np.concatenate([x[:-1] + f * np.diff(x) for f in (0.25, 0.5, 0.75)])
    X, P = np.meshgrid(xs, 0.5 * (p_grid[1:] + p_grid[:-1]), indexing="ij")  # cell centres and between
    applied = np.abs(ClippedStaticForce(m).force_N(X, P) - ClippedStaticForce(t).force_N(X, P))
    assert applied.max() <= 1e-3 * float(m.force_N(0.0, p["rated_pressure_gauge_Pa"]))


def test_tables_are_cached_per_model_and_parameters(monkeypatch):
    clear_cache()
    m = _Affine(-400.0, 2e-4, -300.0)
    a = tabulate(m, (0.0, 0.1), (0.0, 1e6), key=("affine", 1))
    assert tabulate(m, (0.0, 0.1), (0.0, 1e6), key=("affine", 1)) is a
    assert tabulate(m, (0.0, 0.1), (0.0, 1e6), key=("affine", 2)) is not a


def test_implicit_models_are_tabulated_for_the_dynamics(monkeypatch):
    """A model of kind "implicit" reaches the ODE as a table that agrees with it."""
    import dataclasses

    import pamsim.elements.muscle_force as mf

    spec = REGISTRY["kothera_energy"]  # closed-form; marked implicit here, as no shipped model is yet
    implicit = dataclasses.replace(spec, kind="implicit")
    monkeypatch.setattr(mf, "get", lambda name: implicit)
    s = pamsim.Scenario.from_dict(_spec("kothera2009_5a", "kothera_energy"))
    f = s.build_model().static_force
    assert type(f.inner).__name__ == "TabulatedStaticForce"
    raw = s.static_model()
    assert f.force_N(0.01, 3e5) == pytest.approx(raw.force_N(0.01, 3e5), rel=1e-3)


# ---------------------------------------------------------------- runs and sweeps
def test_chou_hannaford_paper_scenario_ends_at_rest_and_balances_energy():
    poly = pamsim.simulate(pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml"))
    ch = pamsim.simulate(pamsim.load_scenario(SCENARIOS / "acra2012_fig4_chou_hannaford.toml"))
    for res in (poly, ch):
        assert res.at_rest_at_end
        assert res.energy_balance()["relative"] <= 1e-3
    s = pamsim.load_scenario(SCENARIOS / "acra2012_fig4_chou_hannaford.toml")
    # At rest the static force holds the weight within the friction band: equilibrium of the model itself.
    net, level = ch.final_rest_forces_N
    assert abs(net) <= level + 1e-6
    assert s.static_model().force_N(ch.x_m[-1], ch.p_gauge_Pa[-1]) == pytest.approx(22.74, abs=level + 1e-6)


def _every_model_sweep(tmp_path: Path, muscle: str):
    m = load_muscle(muscle)
    for model in m.applicable_models():
        base = tmp_path / f"{muscle}_{model}.toml"
        spec = _spec(muscle, model)
        lines = [f'[model]\nmuscle = "{muscle}"\nstatic_force = "{model}"\n',
                 f"[load]\nweight_N = {spec['load']['weight_N']!r}\n",
                 '[pressure]\nsource = "valve"\nsupply_gauge_bar = 1.0\nvalve_open_time_s = 0.1\n',
                 "[simulation]\nduration_s = 0.6\nsample_rate_Hz = 200.0\n"]
        base.write_text("\n".join(lines))
        pbar, weight = spec["pressure"]["supply_gauge_bar"], spec["load"]["weight_N"]
        yield model, sweep_from_dict({"base_scenario": base.name, "friction_models": ["load_dependent", "none"],
                                      "case": [{"pressure_bar": pbar, "weight_N": weight},
                                               {"pressure_bar": 0.5 * pbar, "weight_N": 0.5 * weight}]},
                                     base_dir=tmp_path, origin=f"{muscle}-{model}")


def _assert_no_failed_case(res, what):
    for row in res.rows:
        for f in ("", "none_"):
            assert not row[f + "failure"], (what, row[f + "failure"])
            assert math.isfinite(row[f + "final_contraction_m"])


@pytest.mark.parametrize("muscle", list(MUSCLES))
def test_a_sweep_of_every_model_over_three_muscles_has_no_failed_case(tmp_path, muscle):
    n = 0
    for model, spec in _every_model_sweep(tmp_path, muscle):
        _assert_no_failed_case(run_sweep(spec), (muscle, model))
        n += 1
    assert n == len(load_muscle(muscle).applicable_models()) >= 5


def test_models_no_shipped_muscle_gives_run_with_assumed_constants(tmp_path):
    """The fitted-coefficient models no paper gives constants for run on the miniature muscle with the
    constants the sanity tests assume (their Gaylord-equivalent expansions), added under [parameters]."""
    from test_static_models_sanity import ASSUMED

    for model, constants in ASSUMED.items():
        base = tmp_path / f"{model}.toml"
        base.write_text(f'[model]\nmuscle = "mpam_survey_45mm"\nstatic_force = "{model}"\n[parameters]\n'
                        + "".join(f"{k} = {v!r}\n" for k, v in constants.items())
                        + '[load]\nweight_N = 0.05\n[pressure]\nsource = "valve"\nsupply_gauge_bar = 1.0\n'
                        'valve_open_time_s = 0.1\n[simulation]\nduration_s = 0.6\nsample_rate_Hz = 200.0\n')
        spec = sweep_from_dict({"base_scenario": base.name, "friction_models": ["load_dependent", "none"],
                                "case": [{"pressure_bar": 7.58, "weight_N": 0.05}, {"pressure_bar": 3.0, "weight_N": 0.02}]},
                               base_dir=tmp_path, origin=model)
        _assert_no_failed_case(run_sweep(spec), model)


def test_force_map_muscle_runs_in_the_dynamics(tmp_path):
    """A muscle with a measured F(x, p) table: the force_map model drives the run and the equilibrium
    matches the table's own free contraction at the load."""
    g = load_muscle("mpam_survey_45mm").static_force("gaylord")
    xs, ps = np.linspace(0.0, g.domain.x_max_m, 12), np.linspace(0.0, 8e5, 9)
    (tmp_path / "map.csv").write_text("contraction_m,pressure_gauge_Pa,force_N\n" + "".join(
        f"{float(x)!r},{float(p)!r},{float(g.force_N(x, p))!r}\n" for x in xs for p in ps))
    text = "\n".join(line for line in (ROOT / "pamsim" / "muscles" / "mpam_survey_45mm.toml").read_text().splitlines()
                     if not line.startswith("[data]") and not line.startswith("file ="))
    (tmp_path / "m.toml").write_text(text.replace('name = "mpam_survey_45mm"', 'name = "mapped"\nforce_map = "map.csv"', 1))
    spec = _spec("mpam_survey_45mm", "force_map")
    spec["model"]["muscle"] = "m.toml"
    spec["simulation"]["duration_s"] = 2.0
    s = pamsim.Scenario.from_dict(spec, base_dir=tmp_path)
    res = pamsim.simulate(s)
    assert res.x_m[-1] == pytest.approx(s.static_model().free_contraction_m(7.58e5, 0.05), abs=2e-4)
    from pamsim.errors import InputError
    from pamsim.export import casadi_model

    with pytest.raises(InputError, match="'force_map' and the other elements called on floats"):
        casadi_model(s)  # a table has no CasADi form: said, not an opaque CasADi error


def test_linearize_works_with_another_muscle_and_model(tmp_path):
    sc = tmp_path / "k.toml"
    spec = _spec("kothera2009_5a", "kothera_energy")
    sc.write_text('[model]\nmuscle = "kothera2009_5a"\nstatic_force = "kothera_energy"\nfriction = "none"\n'
                  f"[load]\nweight_N = {spec['load']['weight_N']!r}\n"
                  '[pressure]\nsource = "valve"\nsupply_gauge_bar = 3.0\nvalve_open_time_s = 0.1\n'
                  "[simulation]\nduration_s = 2.0\n")
    r = run_main("linearize", sc, "-o", tmp_path / "lin")
    assert r.returncode == 0, r.stderr


# ---------------------------------------------------------------- command line
def test_models_json_lists_every_registry_entry():
    r = run_main("models", "--json")
    assert r.returncode == 0, r.stderr
    rows = json.loads(r.stdout)
    assert [x["name"] for x in rows] == list(REGISTRY)
    assert all({"name", "kind", "source", "parameters"} <= set(x) for x in rows)


def test_muscles_json_lists_the_shipped_muscles():
    r = run_main("muscles", "--json")
    assert r.returncode == 0, r.stderr
    names = [x["name"] for x in json.loads(r.stdout)]
    assert {"shadow_6x300_acra2012", "kothera2009_5a", "mpam_survey_45mm", "festo_dmsp_20_120"} <= set(names)


def test_force_json_is_gaylords_formula():
    """Hand calculation: F = p (3 L^2 - b^2) / (4 pi N^2), b = L0 / cos(theta0), N = b sin(theta0) / (2 pi r0)."""
    r = run_main("force", "--model", "gaylord", "--muscle", "mpam_survey_45mm", "--pressure-bar", "7.58",
                   "--contraction-mm", "5", "--set", "r0_m=0.0006", "--json")
    assert r.returncode == 0, r.stderr
    p = dynamics_parameters(load_muscle("mpam_survey_45mm").parameters)
    th = math.radians(p["theta0_deg"])
    b = p["L0_m"] / math.cos(th)
    N = b * math.sin(th) / (2 * math.pi * 0.0006)
    L = p["L0_m"] - 0.005
    assert json.loads(r.stdout)["force_N"] == pytest.approx(7.58e5 * (3 * L * L - b * b) / (4 * math.pi * N * N), rel=1e-12)


def test_static_with_another_model_solves_its_equilibrium():
    r = run_main("static", "--model", "gaylord", "--muscle", "kothera2009_5a", "--pressure-bar", "3",
                   "--load-N", "50", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    g = load_muscle("kothera2009_5a").static_force("gaylord")
    assert float(g.force_N(out["equilibrium_contraction_m"], 3e5)) == pytest.approx(50.0, abs=1e-6)
    assert out["max_load_N"] == pytest.approx(float(g.force_N(0.0, 3e5)), rel=1e-9)  # Gaylord falls with x


@pytest.mark.parametrize("args, words", [
    (["force", "--model", "gaylord", "--pressure-bar", "3", "--contraction-mm", "1", "--set", "L0_m=abc"],
     ["--set L0_m", "abc"]),
    (["force", "--model", "gaylord", "--pressure-bar", "3", "--contraction-mm", "1", "--set", "L0=0.1"],
     ["--set L0", "L0_m"]),
    (["force", "--model", "gaylord", "--pressure-bar", "3", "--contraction-mm", "1", "--set", "L0_m=-1"],
     ["--set L0_m", "-1"]),
    (["force", "--model", "chou_hannaford", "--pressure-bar", "3", "--contraction-mm", "1"],
     ["chou_hannaford", "wall_thickness_m"]),
    # Reported as the user wrote it, in the flag's unit.
    (["force", "--model", "gaylord", "--pressure-bar", "3", "--contraction-mm", "500"],
     ["--contraction-mm 500", "domain", "mm"]),
    (["force", "--pressure-bar", "3", "--contraction-mm", "-5"], ["--contraction-mm -5", "[-0.1, 76] mm"]),
    (["force", "--pressure-bar", "-1", "--contraction-mm", "5"], ["--pressure-bar -1", "bar"]),
    (["force", "--model", "gaylord", "--muscle", "nosuch", "--pressure-bar", "3", "--contraction-mm", "1"],
     ["nosuch"]),
    (["static", "--model", "gaylord", "--pressure-bar", "3", "--load-N", "5", "--set", "festo"], ["festo"]),
])
def test_bad_cli_values_exit_2_naming_them(args, words):
    # The commands run in this process; the first case also through a real subprocess, as a user sees it.
    r = run_main(*args)
    if args[-1] == "L0_m=abc":
        sub = run_cli(*args)
        assert (sub.returncode, sub.stderr) == (r.returncode, r.stderr)
    assert r.returncode == 2
    line = r.stderr.strip()
    assert "\n" not in line and "Traceback" not in line
    for w in words:
        assert w in line


# ---------------------------------------------------------------- atlas
def test_atlas_writes_curves_table_and_figures_of_every_applicable_model(tmp_path):
    out = tmp_path / "atlas"
    r = run_main("atlas", "--muscle", "mpam_survey_45mm", "-o", out)
    assert r.returncode == 0, r.stderr
    m = load_muscle("mpam_survey_45mm")
    rows = list(csv.DictReader((out / "atlas_table.csv").open()))
    assert [row["model"] for row in rows] == m.applicable_models()
    p = dynamics_parameters(m.parameters)
    for row in rows:  # each row from the model itself (its own blocked force and free contraction)
        model = REGISTRY[row["model"]].build(p)
        P = float(row["pressure_bar"]) * 1e5
        assert float(row["blocked_force_N"]) == pytest.approx(float(model.force_N(0.0, P)), rel=1e-5)
        free = float(row["free_contraction_mm"])
        assert free == pytest.approx(model.free_contraction_m(P) * 1e3, rel=1e-5, nan_ok=True)
    # The survey's measured point (758 kPa, 13 mm) sets the pressure and is overlaid.
    assert [float(r["pressure_bar"]) for r in rows][:1] == [7.58]
    curves = list(csv.DictReader((out / "atlas_curves.csv").open()))
    assert len(curves) == len(rows) * 201
    for name in ("atlas_7.58bar.png", "atlas_all.png", "atlas_table.md"):
        assert (out / name).stat().st_size > 0


def test_atlas_gives_the_reason_where_a_model_has_no_free_contraction(tmp_path):
    """Zang's printed law, 2 pi r0^2 p (1 - eps)^2/tan^2(theta0), stays positive over its whole domain."""
    out = tmp_path / "atlas"
    r = run_main("atlas", "--muscle", "mpam_survey_45mm", "--models", "gaylord,zang", "-o", out)
    assert r.returncode == 0, r.stderr
    for text in (r.stdout, (out / "atlas_table.md").read_text()):
        assert "nan" not in text
        row = next(ln for ln in text.splitlines() if ln.startswith("| `zang`"))
        assert row.endswith("/ none |")
        note = next(ln for ln in text.splitlines() if "`zang`" in ln and "free contraction" in ln)
        assert "stays above zero" in note and "12.9 mm" in note and "7.58 bar" in note
    rows = {row["model"]: row for row in csv.DictReader((out / "atlas_table.csv").open())}
    assert "stays above zero" in rows["zang"]["free_contraction_note"] and rows["gaylord"]["free_contraction_note"] == ""


def test_static_says_why_the_equilibrium_is_the_upper_stop():
    args = ("static", "--muscle", "mpam_survey_45mm", "--model", "zang", "--pressure-bar", "3", "--load-N", "0.5")
    r = run_main(*args)
    assert r.returncode == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if "equilibrium contraction" in ln)
    assert "upper stop" in line and "pulls harder than the load" in line
    out = json.loads(run_main(*args, "--json").stdout)
    assert "upper stop" in out["equilibrium_note"]
    plain = json.loads(run_main("static", "--muscle", "mpam_survey_45mm", "--model", "gaylord", "--pressure-bar", "3",
                                "--load-N", "0.5", "--json").stdout)
    assert plain["equilibrium_note"] == ""


def test_atlas_refuses_a_model_that_does_not_apply_and_writes_nothing(tmp_path):
    out = tmp_path / "atlas"
    r = run_main("atlas", "--muscle", "shadow_6x300_acra2012", "--models", "gaylord,chou_hannaford", "-o", out)
    assert r.returncode == 2 and "chou_hannaford" in r.stderr and "wall_thickness_m" in r.stderr
    assert not out.exists()


NO_MODEL = "festo_dmsp_20_120"  # its paper's geometry table and Ogden constants are not in the source text


def test_muscles_says_why_no_model_applies_instead_of_a_count_of_zero():
    r = run_main("muscles")
    assert r.returncode == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith(NO_MODEL))
    assert "0 models apply" not in line
    assert "no static model applies" in line and "r0_m" in line and "theta0_deg" in line and "ogden_mu1_Pa" in line
    gaps = [ln.strip() for ln in r.stdout.splitlines() if ln.strip().startswith("gap:")]
    assert any("Table 1" in g for g in gaps) and any("Ogden constants" in g for g in gaps)
    row = next(x for x in json.loads(run_main("muscles", "--json").stdout) if x["name"] == NO_MODEL)
    assert row["applicable_models"] == [] and "ogden_alpha1" in row["no_model_reason"] and row["gaps"]


@pytest.mark.parametrize("args", [
    ["atlas", "--muscle", NO_MODEL, "-o", "{out}"],
    ["static", "--muscle", NO_MODEL, "--pressure-bar", "3", "--load-N", "10"],
    ["static", "--muscle", NO_MODEL, "--pressure-bar", "3", "--load-N", "10", "--json"],
])
def test_a_muscle_no_model_applies_to_is_refused_naming_it_and_nothing_is_written(tmp_path, args):
    out = tmp_path / "atlas"
    r = run_main(*[a.format(out=out) for a in args])
    assert r.returncode == 2 and r.stdout == ""
    line = r.stderr.strip()
    assert "\n" not in line and "Traceback" not in line
    assert NO_MODEL in line and "no static model applies" in line
    assert not out.exists()


def test_atlas_refuses_when_no_curve_lies_in_any_models_domain(tmp_path):
    out = tmp_path / "atlas"
    # Ogden with soft fibres: the domain's pressure ends near 3.1 bar, below the 4 bar asked for.
    r = run_main("atlas", "--muscle", "kothera2009_5a", "--models", "ogden", "--pressures-bar", "4", "-o", out,
                 "--set", "ogden_mu1_Pa=2e6", "--set", "ogden_alpha1=2", "--set", "E_braid_Pa=1e7")
    assert r.returncode == 2 and "kothera2009_5a" in r.stderr and "ogden" in r.stderr
    assert not out.exists()


def test_docs_list_the_dynamics_defaults():
    from pamsim.cli.params import defaults_table

    assert defaults_table() in (ROOT / "docs" / "model.md").read_text()


def test_with_changes_to_another_muscle_takes_its_default_model():
    base = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")  # parameter_set = the Shadow muscle
    k = base.with_changes({"model": {"muscle": "kothera2009_5a"}, "load": {"weight_N": 10.0}})
    assert k.spec["model"]["static_force"] == load_muscle("kothera2009_5a").default_static_force
    g = base.with_changes({"model": {"static_force": "gaylord"}})
    assert g.with_changes({"model": {"parameter_set": "mpam_survey_45mm"}, "load": {"weight_N": 0.05},
                           "pressure": {"supply_gauge_bar": 3.0}}).spec["model"]["static_force"] == "gaylord"
