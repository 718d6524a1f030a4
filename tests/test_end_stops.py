"""The upper end stop where the physics puts it: the braid's jam angle or the end of the static model's
domain, not the braid lock at 54.7 deg, where only the ideal force vanishes.  Each figure is checked
against the MPAM survey's number or a hand calculation written out here."""

from __future__ import annotations

import json
import math

import pytest
from scipy.optimize import brentq

import pamsim
from pamsim.muscles import load_muscle, muscle_from_dict

from conftest import SCENARIOS, run_main

SURVEY = "mpam_survey_45mm"
E_KOTHERA_FIT_PA = 0.345e6  # MPAM survey: the modulus fitted with Kothera's model (its sec. 4)
SURVEY_REST_MM = 13.30  # the survey muscle at 758 kPa under 0.05 N by eq. (33) with that modulus


def survey_geometry():
    """Rest length, braid radius, wall, rest angle of the survey's 45 mm muscle, from its file."""
    p = load_muscle(SURVEY).parameters
    return p["L0_m"], p["r0_m"], p["wall_thickness_m"], math.radians(p["theta0_deg"])


def eq33_rest_m(p_Pa: float, load_N: float, E_Pa: float) -> float:
    """Contraction [m] at which Kothera's eq. (33) (= MPAM survey eq. 17) pulls ``load_N``, written out here."""
    L0, r0, t0, th0 = survey_geometry()
    B = L0 / math.cos(th0)
    N = B * math.sin(th0) / (2 * math.pi * r0)
    Vb = math.pi * L0 * (r0 ** 2 - (r0 - t0) ** 2)

    def force(L):
        R = math.sqrt(B * B - L * L) / (2 * math.pi * N)
        t = R - math.sqrt(R * R - Vb / (math.pi * L))
        return (p_Pa / (4 * N * N * math.pi) * (3 * L * L - B * B) + p_Pa * (Vb / L - t * L * L / (2 * math.pi * R * N * N))
                + E_Pa * Vb * (1 / L0 - 1 / L) + E_Pa * L / (2 * math.pi * R * N * N) * (t * L - t0 * L0))

    # Bracketed between rest and Gaylord's lock less 5 mm, where eq. (33) pulls less than the load.
    return L0 - brentq(lambda L: force(L) - load_N, B / math.sqrt(3) - 5e-3, L0 - 1e-9, xtol=1e-14)


def static_json(*args):
    out = run_main("static", *args, "--json")
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_survey_muscle_rests_where_eq33_puts_it_not_at_the_braid_lock():
    """758 kPa, 0.05 N: 13.30 mm by eq. (33) (the survey's modulus), past the braid lock at 12.89 mm."""
    by_hand = eq33_rest_m(7.58e5, 0.05, E_KOTHERA_FIT_PA)
    assert by_hand * 1e3 == pytest.approx(SURVEY_REST_MM, abs=0.005)
    r = static_json("--muscle", SURVEY, "--pressure-bar", "7.58", "--load-N", "0.05",
                    "--set", f"E_bladder_Pa={E_KOTHERA_FIT_PA:g}")
    assert r["equilibrium_contraction_m"] == pytest.approx(by_hand, abs=1e-9)
    assert r["on_stop"] is None and r["equilibrium_note"] == ""


@pytest.mark.parametrize("backend", ["python", "native", "fmu-cs", "fmu-me"])
def test_a_run_of_the_survey_muscle_comes_to_rest_there(backend):
    sc = pamsim.Scenario.from_dict({
        "model": {"muscle": SURVEY}, "parameters": {"E_bladder_Pa": E_KOTHERA_FIT_PA}, "load": {"weight_N": 0.05},
        "pressure": {"source": "valve", "supply_gauge_bar": 7.58, "valve_open_time_s": 0.1},
        "simulation": {"duration_s": 3.0}})
    s = pamsim.run(sc, backend=backend).result.summary()
    assert s["final_contraction_m"] * 1e3 == pytest.approx(SURVEY_REST_MM, abs=0.01)
    assert s["at_rest_at_end"] and s["on_stop"] is None


@pytest.mark.parametrize("backend", ["python", "native", "fmu-cs"])
def test_the_scenario_key_puts_the_stop_back_at_the_braid_lock(backend):
    """``upper_stop = "braid_lock"``: every backend holds the survey muscle on the old stop, 12.886 mm."""
    sc = pamsim.Scenario.from_dict({
        "model": {"muscle": SURVEY, "upper_stop": "braid_lock"}, "parameters": {"E_bladder_Pa": E_KOTHERA_FIT_PA},
        "load": {"weight_N": 0.05}, "simulation": {"duration_s": 3.0},
        "pressure": {"source": "valve", "supply_gauge_bar": 7.58, "valve_open_time_s": 0.1}})
    s = pamsim.run(sc, backend=backend).result.summary()
    lock = sc.build_model().stops.x_high_m
    assert s["final_contraction_m"] == pytest.approx(lock, abs=1e-9) and s["on_stop"] == "upper"
    assert lock * 1e3 == pytest.approx(12.886, abs=0.001)


def test_jam_angle_by_hand():
    """Survey muscle with strands of 0.08 mm radius (twice its own): n w = 4 pi r cos(theta) at the jam, with
    r = r0 sin(theta) / sin(theta0), so sin(2 theta) = n w sin(theta0) / (2 pi r0)."""
    L0, r0, _, th0 = survey_geometry()
    n, w = 30, 2 * 0.08e-3
    theta = math.pi / 2 - 0.5 * math.asin(n * w * math.sin(th0) / (2 * math.pi * r0))
    x_jam = L0 - L0 / math.cos(th0) * math.cos(theta)
    assert math.degrees(theta) == pytest.approx(62.64, abs=0.01) and x_jam * 1e3 == pytest.approx(19.43, abs=0.01)
    r = static_json("--muscle", SURVEY, "--pressure-bar", "7.58", "--load-N", "0.05", "--set", "fibre_radius_m=8e-5")
    assert r["upper_stop_m"] == pytest.approx(x_jam, rel=1e-12)
    assert r["upper_stop_basis"] == "jam" and r["upper_stop"] == "auto"
    flat = static_json("--muscle", SURVEY, "--pressure-bar", "7.58", "--load-N", "0.05", "--set", f"fibre_width_m={w}")
    assert flat["upper_stop_m"] == r["upper_stop_m"]  # a flat yarn as wide as the round strand


def test_a_jam_beyond_the_bladder_fill_leaves_the_stop_at_the_domain_end():
    """The survey's own strands (0.04 mm) would jam at 77.95 deg, 33.39 mm; the bladder fills the braid at
    31.95 mm (R^2 = V_b / (pi L), the end of eq. 33's domain), which stops it first."""
    L0, r0, t0, th0 = survey_geometry()
    B = L0 / math.cos(th0)
    N = B * math.sin(th0) / (2 * math.pi * r0)
    Vb = math.pi * L0 * (r0 ** 2 - (r0 - t0) ** 2)
    L_fill = brentq(lambda L: (B * B - L * L) / (2 * math.pi * N) ** 2 - Vb / (math.pi * L), 1e-3, B / math.sqrt(3))
    theta_jam = math.pi / 2 - 0.5 * math.asin(30 * 0.08e-3 * math.sin(th0) / (2 * math.pi * r0))
    assert (L0 - B * math.cos(theta_jam)) * 1e3 == pytest.approx(33.39, abs=0.01)
    r = static_json("--muscle", SURVEY, "--pressure-bar", "7.58", "--load-N", "0.05")
    assert r["upper_stop_m"] == pytest.approx(L0 - L_fill, abs=1e-8)
    assert r["upper_stop_basis"] == "domain_end"


def test_static_and_force_say_when_the_load_rests_on_a_stop():
    """At the braid lock (54.7356 deg: L = b / sqrt(3)) the survey muscle at 758 kPa still out-pulls 0.05 N."""
    L0, _, _, th0 = survey_geometry()
    lock = L0 - L0 / math.cos(th0) / math.sqrt(3)
    r = static_json("--muscle", SURVEY, "--pressure-bar", "7.58", "--load-N", "0.05", "--upper-stop", "braid_lock")
    assert r["on_stop"] == "upper" and r["equilibrium_contraction_m"] == pytest.approx(lock, rel=1e-12)
    assert r["upper_stop_basis"] == "braid_lock"
    # The Shadow muscle cannot lift 52.74 N at 1 bar: 23.90 * 1 - 11.56 = 12.34 N at x = 0 (ACRA 2012 eq. 11).
    assert static_json("--pressure-bar", "1", "--load-N", "52.74")["on_stop"] == "lower"
    assert static_json("--pressure-bar", "3.6", "--load-N", "22.74")["on_stop"] is None
    force = run_main("force", "--muscle", SURVEY, "--pressure-bar", "7.58", "--contraction-mm", "13", "--json")
    assert json.loads(force.stdout)["on_stop"] is None
    locked = run_main("force", "--muscle", SURVEY, "--pressure-bar", "7.58", "--contraction-mm", "13",
                      "--upper-stop", "braid_lock")
    assert "at or past the upper stop, 12.89 mm" in locked.stdout


def test_the_shadow_muscle_keeps_the_braid_lock():
    """Its polynomial's domain ends where its fit ends (76 mm), no stop: its file keeps the stop every
    paper scenario ran with, L0 - b / sqrt(3) = 115.68 mm for b = 0.3 m / cos(20 deg)."""
    model = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").build_model()
    assert model.stops.x_high_m == pytest.approx(0.3 - 0.3 / math.cos(math.radians(20)) / math.sqrt(3), rel=1e-12)
    assert model.stops.upper_basis == "braid_lock"
    assert load_muscle("shadow_6x300_acra2012").upper_stop == "braid_lock"


def test_a_scenario_chooses_the_stop():
    spec = {"model": {"muscle": SURVEY, "upper_stop": "braid_lock"}, "load": {"weight_N": 0.05},
            "pressure": {"source": "valve", "supply_gauge_bar": 7.58, "valve_open_time_s": 0.1},
            "simulation": {"duration_s": 2.0}}
    res = pamsim.simulate(pamsim.Scenario.from_dict(spec))
    assert res.summary()["on_stop"] == "upper"
    assert res.x_m[-1] == pytest.approx(pamsim.Scenario.from_dict(spec).build_model().stops.x_high_m)


@pytest.mark.parametrize("model, why", [
    ({"upper_stop": "jamm"}, "model.upper_stop = 'jamm': unknown choice (did you mean 'jam'?)"),
    ({"muscle": "kothera2009_5a", "upper_stop": "jam"}, "model.upper_stop = 'jam': a jam angle needs the fibre count"),
])
def test_a_stop_that_cannot_be_met_is_refused_naming_the_key(model, why):
    spec = {"model": model, "load": {"weight_N": 10.0},
            "pressure": {"source": "valve", "supply_gauge_bar": 2.0, "valve_open_time_s": 0.1},
            "simulation": {"duration_s": 1.0}}
    with pytest.raises(pamsim.ScenarioError, match="^<dict>: " + why.replace("(", r"\(").replace(")", r"\)")
                       .replace("?", r"\?")):
        pamsim.Scenario.from_dict(spec)


def _muscle(upper_stop):
    raw = {"name": "m", "description": "d", "citation": "c", "default_static_force": "gaylord",
           "parameters": {k: {"value": v, "source": "test"} for k, v in
                          (("L0_m", 0.1), ("r0_m", 0.005), ("theta0_deg", 30.0))},
           "upper_stop": upper_stop}
    return muscle_from_dict(raw, "m.toml")


@pytest.mark.parametrize("table, why", [
    ({"at": "lock"}, "m.toml: upper_stop.at = 'lock': must be one of auto, jam, domain_end, braid_lock"),
    ({"at": "jam"}, "m.toml: missing key upper_stop.source: required"),
    ({"at": "jam", "source": "x", "why": "y"}, "m.toml: upper_stop.why = 'y': unknown key"),
    ("jam", "m.toml: upper_stop = 'jam': must be a table"),
])
def test_a_muscle_file_names_its_stop_with_a_source(table, why):
    with pytest.raises(pamsim.muscles.MuscleError) as err:
        _muscle(table)
    assert str(err.value).startswith(why)
    assert _muscle({"at": "domain_end", "source": "test"}).upper_stop == "domain_end"


def test_the_cli_refuses_fibres_that_could_not_move_in_one_line():
    out = run_main("static", "--muscle", SURVEY, "--pressure-bar", "1", "--load-N", "0.05",
                   "--set", "fibre_radius_m=2e-4")
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.strip().splitlines() == [
        "pamsim: error: muscle 'mpam_survey_45mm': its upper stop 'auto': fibre_radius_m = 0.0002 with "
        "n_fibres = 30: the fibres would cover the braid at every angle: the braid could not move"]
