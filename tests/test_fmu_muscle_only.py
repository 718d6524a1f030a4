"""The muscle-only FMU: length and lengthening velocity in, force out, against the force written out by
hand from the muscle's elements at the inputs the FMU saw."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import pamsim

P_BAR = 3.0


SCENARIO = f"""
name = "muscle_alone"
[model]
parameter_set = "shadow_6x300_acra2012"
friction = "constant"
damping = "paper"
[load]
weight_N = 22.74
[pressure]
source = "prescribed"
prescribed = {{ kind = "constant", value_gauge_bar = {P_BAR} }}
[simulation]
duration_s = 2.0
"""
"""The muscle of the ACRA 2012 tests at a constant pressure, with the paper's constant friction (2.5 N) so
that the force holds a Coulomb term at every contraction."""


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    src = tmp_path_factory.mktemp("mo") / "scenario.toml"
    src.write_text(SCENARIO)
    path = src.parent / "muscle.fmu"
    done = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario", str(src), "--muscle-only",
                           "-o", str(path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return pamsim.load_scenario(src), path


def test_it_validates_and_has_the_motion_inputs_and_the_force_output(built):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    _, path = built
    assert validate_fmu(str(path)) == []
    causality = {v.name: v.causality for v in read_model_description(str(path)).modelVariables}
    assert causality["length_m"] == causality["lengthening_velocity_m_s"] == "input"
    assert causality["prescribed_pressure_gauge_Pa"] == "input" and causality["motion.F_N"] == "output"


def test_the_force_is_the_hand_sum_of_the_muscles_forces(built):
    """Driven by the importer along a 1 Hz sinusoid of contraction, co-simulation: at every output point,
    the force is F_static(x, p) - F_damping(v) - sign(v) F_c(x, p, F_static / g), the elements called on
    floats at the contraction and velocity the FMU reports from its inputs, to 1e-9 N."""
    from fmpy import simulate_fmu

    scenario, path = built
    model = scenario.build_model()
    L0, g = scenario.parameters["L0_m"], scenario.parameters["g_m_s2"]
    t = np.linspace(0.0, 2.0, 2001)
    x, v = 0.03 + 0.01 * np.sin(2 * np.pi * t), 0.01 * 2 * np.pi * np.cos(2 * np.pi * t)
    inputs = np.zeros(t.size, dtype=[("time", float), ("prescribed_pressure_gauge_Pa", float), ("length_m", float),
                                     ("lengthening_velocity_m_s", float)])
    inputs["time"], inputs["prescribed_pressure_gauge_Pa"] = t, P_BAR * 1e5
    inputs["length_m"], inputs["lengthening_velocity_m_s"] = L0 - x, -v
    res = simulate_fmu(str(path), fmi_type="CoSimulation", start_time=0.0, stop_time=2.0, output_interval=1e-3,
                       input=inputs, start_values={"input_source": 0},
                       output=["motion.F_N", "motion.x_m", "motion.v_m_s", "muscle.F_static_N"], validate=False)
    xs, vs, p = res["motion.x_m"], res["motion.v_m_s"], P_BAR * 1e5
    # the contraction and its rate the FMU reports are the inputs' (L0 - L, -dL/dt), within what they move
    # in one 1 ms step (6.3e-5 m, 4e-4 m/s); a sign error would be off by 0.06 m and 0.12 m/s
    x_out = 0.03 + 0.01 * np.sin(2 * np.pi * res["time"])
    v_out = 0.01 * 2 * np.pi * np.cos(2 * np.pi * res["time"])
    assert np.max(np.abs(xs - x_out)) < 1e-4 and np.max(np.abs(vs - v_out)) < 1e-3
    static = np.array([float(model.static_force.force_N(a, p)) for a in xs])
    level = np.array([float(model.friction.level_N(a, p, max(f, 0.0) / g)) for a, f in zip(xs, static)])
    damping = np.array([float(model.damping.force_N(b)) for b in vs])
    want = static - damping - np.sign(vs) * level
    assert np.max(np.abs(res["muscle.F_static_N"] - static)) < 1e-9
    assert np.max(np.abs(res["motion.F_N"] - want)) < 1e-9
    assert np.ptp(xs) > 0.019 and np.all(level == 2.5) and np.count_nonzero(np.diff(np.sign(vs))) >= 3
