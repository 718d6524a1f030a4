"""Muscles on a linear slider: the paper's rig as one case of it (Figure 4 and the 66 tests, against the
hanging load), analytic motion on an inclined guide, the energy balance, and bad scenarios."""

from __future__ import annotations

import copy
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from pamsim.api import simulate
from pamsim.errors import InputError
from pamsim.joints import JointScenario, load_joint_scenario, simulate_joint
from pamsim.joints.scenario import slider_of_rig
from pamsim.joints.static import JointStatics
from pamsim.scenario import ScenarioError, load_scenario
from pamsim.sweep.spec import load_sweep

ROOT = Path(__file__).resolve().parents[1]
FIG4 = ROOT / "scenarios" / "acra2012_fig4.toml"
FIG4_SLIDER = ROOT / "scenarios" / "acra2012_fig4_slider.toml"
G = 9.81


def test_the_shipped_slider_file_is_the_figure_4_rig():
    """The file's numbers are those the rig gives itself: weight, stops, source, solver."""
    shipped, derived = load_joint_scenario(FIG4_SLIDER), slider_of_rig(load_scenario(FIG4))
    assert shipped.joint == derived.joint
    assert shipped.muscles[0][1].spec["pressure"] == derived.muscles[0][1].spec["pressure"]
    assert shipped.solver == derived.solver and shipped.duration_s == derived.duration_s


@pytest.mark.parametrize("backend, bound_m", [("python", 5.6e-7), ("native", 5.6e-7)])
def test_figure_4_on_a_vertical_slider_is_the_hanging_load(backend, bound_m):
    """While the muscle pulls, slider and hanging load are the same equations: the traces agree within
    the integrators' tolerance, 10 rtol times the largest contraction (5.6e-7 m at rtol 1e-6), and the
    events are the same, at the same times within a step of the output (1 ms)."""
    rig = simulate(load_scenario(FIG4), backend=backend)
    slider = simulate_joint(load_joint_scenario(FIG4_SLIDER), backend)
    assert np.max(np.abs(rig.x_m - slider.position)) < bound_m
    assert np.max(np.abs(rig.p_gauge_Pa - slider.muscle("muscle", "p_gauge_Pa"))) < 1e-6 * 3.6e5 * 10
    events = [(e.kind, e.t_s) for e in slider.transitions]
    assert [k for k, _ in events] == ["release_up", "velocity_zero", "velocity_zero", "velocity_zero"]
    assert [k for k, _ in events] == [e.kind for e in rig.transitions]
    assert np.allclose([t for _, t in events], [e.t_s for e in rig.transitions], atol=1e-3)
    assert abs(slider.position[-1] - 0.05603) < 1e-5  # the paper's rig: 56.03 mm (docs/validation.md)


def test_the_66_paper_tests_on_a_slider_match_the_hanging_load():
    """Every ACRA 2012 test of the grid, on the native engine: the slider's trace is the rig's within
    10 rtol of the contraction (rtol 1e-6 with the engine's native_rtol_factor)."""
    sweep = load_sweep(ROOT / "scenarios" / "acra2012_grid.toml")
    worst = 0.0
    for case in sweep.cases:
        sc = sweep.case_scenario(case, "load_dependent")
        rig, slider = simulate(sc, backend="native"), simulate_joint(slider_of_rig(sc), "native")
        worst = max(worst, float(np.max(np.abs(rig.x_m - slider.position))))
    assert len(sweep.cases) == 66 and worst < 1e-6


def _free_slider(incline_rad: float, b: float, F_c: float) -> dict:
    """A 1 kg carriage at 50 mm on a guide at ``incline_rad``, its one muscle unpressurised (no static
    force: its tendon slack) and without damping or friction, the guide's ``b`` and ``F_c``."""
    return {"name": "free", "slider": {"mass_kg": 1.0, "incline_rad": incline_rad, "b_N_s_per_m": b,
                                       "F_coulomb_N": F_c, "x_min_m": 0.0, "x_max_m": 0.1, "initial_position_m": 0.05},
            "muscle": [{"name": "m", "side": 1, "x_at_zero_m": 0.0,
                        "model": {"parameter_set": "shadow_6x300_acra2012", "friction": "none", "damping": "none"},
                        "pressure": {"source": "prescribed", "prescribed": {"kind": "constant", "value_gauge_bar": 0.0}}}],
            "simulation": {"duration_s": 0.3, "sample_rate_Hz": 1000.0}, "solver": {"method": "RK45", "rtol": 1e-9}}


def _coulomb(t, a, b, F_c):
    return 0.05 - 0.5 * (G * math.sin(a) - F_c) * t ** 2


def _viscous(t, a, b, F_c):
    return 0.05 - G * math.sin(a) / b * (t - (1.0 - np.exp(-b * t)) / b)


@pytest.mark.parametrize("backend", ["python", "native"])
@pytest.mark.parametrize("incline, b, F_c, exact", [(math.pi / 2, 0.0, 0.0, _coulomb), (math.pi / 6, 0.0, 2.0, _coulomb),
                                                     (math.pi / 4, 5.0, 0.0, _viscous)])
def test_a_carriage_slides_down_its_guide_as_the_hand_solution_says(backend, incline, b, F_c, exact):
    """m a = -m g sin(incline) - b v + F_c (sliding down), from rest: the analytic position to 1e-9 m
    before the lower stop, where it then rests; the slack tendon carries nothing; gravity's work is
    what the carriage gained and the guide lost."""
    res = simulate_joint(JointScenario.from_dict(_free_slider(incline, b, F_c)), backend)
    t, x = res.t_s, res.position
    moving = x > 1e-4
    assert moving.sum() > 20
    assert np.max(np.abs(x[moving] - exact(t[moving], incline, b, F_c))) < 1e-8
    assert np.all(res.muscle("m", "F_tendon_N") == 0.0) and np.all(res.muscle("m", "taut") == 0.0)
    assert res.final_mode.label == "stop_low" and x[-1] == 0.0
    balance = res.energy_balance()
    assert balance["dPE_J"] == pytest.approx(-1.0 * G * math.sin(incline) * 0.05, rel=1e-12)
    assert balance["relative"] < 1e-6


def test_a_tilted_guide_holds_the_carriage_while_friction_can():
    """On a 10 degree guide with 2 N of Coulomb friction a 1 kg carriage (1.70 N downhill) stays where it is."""
    res = simulate_joint(JointScenario.from_dict(_free_slider(math.radians(10.0), 0.0, 2.0)))
    assert np.all(res.position == 0.05) and res.final_mode.label == "stick"


def test_the_slider_run_writes_its_files_and_every_backend_agrees(tmp_path):
    """``pamsim run`` on the slider file: CSV columns in the slider's names, its figure; the FMU backends
    agree with python within 10 rtol of the contraction."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(FIG4_SLIDER), "-o", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "final position 56.029 mm" in done.stdout
    header = (out / "acra2012_fig4_slider.csv").read_text().splitlines()[0].split(",")
    assert header[:4] == ["t_s", "x_m", "v_m_s", "mode"] and "muscle.F_N" in header and "F_gravity_N" in header
    assert (out / "acra2012_fig4_slider.png").stat().st_size > 10_000
    python = simulate_joint(load_joint_scenario(FIG4_SLIDER))
    cs = simulate_joint(load_joint_scenario(FIG4_SLIDER), "fmu-cs")
    assert abs(cs.position[-1] - python.position[-1]) < 5.6e-7


BAD = [
    (lambda s: s["slider"].update(mass_kg=0.0), "slider.mass_kg = 0.0: must be > 0"),
    (lambda s: s["slider"].update(x_min_m=0.2), "slider.x_min_m = 0.2: must be below slider.x_max_m"),
    (lambda s: s["slider"].update(weight_N=10.0), "slider.weight_N = 10.0: give mass_kg or weight_N, not both"),
    (lambda s: s["slider"].update(friction_load="load"), "slider.friction_load = 'load': must be one of"),
    (lambda s: s["slider"].update(b_N_s_per_m=-1.0), "slider.b_N_s_per_m = -1.0: must be >= 0"),
    (lambda s: s["muscle"][0].update(radius_m=0.01), "muscle 'm'.radius_m = 0.01: unknown key"),
    (lambda s: s.update(joint={"inertia_kg_m2": 1.0}), "a scenario has a [joint] or a [slider], not both"),
    (lambda s: s["slider"].update(x_max_m=0.2), "muscle 'm' would contract to 200.00 mm there, outside its range"),
    (lambda s: s.update(controller={"kind": "angle_stiffness"}), "controller = "),
]


@pytest.mark.parametrize("change, message", BAD, ids=[m.split(":")[0][:40] for _, m in BAD])
def test_bad_slider_scenarios_are_refused_by_key(change, message):
    spec = copy.deepcopy(_free_slider(math.pi / 2, 0.0, 0.0))
    change(spec)
    with pytest.raises(ScenarioError) as info:
        JointScenario.from_dict(spec, origin="slider.toml")
    assert message in str(info.value) and str(info.value).startswith("slider.toml")


def test_joint_only_tools_refuse_a_slider(tmp_path):
    """The joint's statics and linearisation, and its MuJoCo model, name the slider and exit 2."""
    with pytest.raises(InputError, match="move a slider"):
        JointStatics(load_joint_scenario(FIG4_SLIDER))
    for args in (["linearize", str(FIG4_SLIDER), "--pressures-bar", "3.6"], ["joint-map", str(FIG4_SLIDER)]):
        done = subprocess.run([sys.executable, "-m", "pamsim", *args, "-o", str(tmp_path / "x")],
                              capture_output=True, text=True)
        assert done.returncode == 2 and "Traceback" not in done.stderr, (args, done.stderr)


def test_every_number_of_the_shipped_slider_says_where_it_comes_from():
    """Each of the shipped file's [slider] values and each muscle's geometry carries a comment."""
    text = FIG4_SLIDER.read_text()
    spec = tomllib.loads(text)
    keys = set(spec["slider"]) | {"side", "x_at_zero_m"}
    lines = [ln for ln in text.splitlines() if ln.split("=")[0].strip() in keys]
    assert len(lines) == len(keys) and all("#" in ln for ln in lines), lines


def test_the_slider_fmu_validates_with_the_sliders_names(tmp_path):
    """``pamsim fmu build --scenario`` on the slider file: fmpy validates it; its variables are the
    slider's (``slider.x_m``, ``F_external_N``, the muscle's tendon)."""
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    path = tmp_path / "slider.fmu"
    done = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario", str(FIG4_SLIDER), "-o",
                           str(path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "the slider and its 1 muscle" in done.stdout and validate_fmu(str(path)) == []
    names = {v.name for v in read_model_description(str(path)).modelVariables}
    assert {"slider.x_m", "slider.mass_kg", "F_external_N", "muscle_tendon.F_N", "muscle_chamber.p_gauge_Pa"} <= names
