"""pamsim muscles driving a MuJoCo hinge (pulleys, levers) or slide joint, against pamsim's own model.

The coupling is explicit (each muscle's force over a MuJoCo step is the one its pneumatics reach at the
step's end, from the length at its start) and MuJoCo's Euler integration is first order: both errors
shrink in proportion to the time step dt.  The tolerance follows from that: for a first-order method
e(dt) = C dt + O(dt^2), so e(dt) - e(dt/2) = C dt / 2 and e(dt) ~ 2 |theta(dt) - theta(dt/2)|, the
Richardson estimate from the two runs.  The test holds the error against pamsim's own run (native, rtol
1e-9) to 1.5 times that estimate, and checks the order itself: halving dt must at least cut the error by
a third.  The shipped pair's bearing has no Coulomb friction here and its muscles none either: MuJoCo's
friction is a soft constraint, pamsim's an exact stick/slip, and they differ by design.
"""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from pamsim.errors import InputError
from pamsim.joints import JointScenario, simulate_joint

from joint_specs import on_levers

mujoco = pytest.importorskip("mujoco", reason="the optional extra pamsim[mujoco] (installed by the test extra)")
from pamsim.coupling.mujoco import CoupledMuscle, MujocoMuscles, joint_mjcf, joint_muscles  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PAIR = tomllib.loads((ROOT / "scenarios" / "antagonistic_pair.toml").read_text())


def frictionless_pair() -> JointScenario:
    spec = copy.deepcopy(PAIR)
    spec["joint"]["tau_coulomb_Nm"] = 0.0
    for table in spec["muscle"]:
        table["model"] = dict(table["model"], friction="none")
    return JointScenario.from_dict(spec)


def mujoco_run(scenario, dt: float):
    model = mujoco.MjModel.from_xml_string(joint_mjcf(scenario, dt))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    coupled = MujocoMuscles(model, data, joint_muscles(scenario))
    n = int(round(scenario.duration_s / dt))
    t, theta = np.empty(n + 1), np.empty(n + 1)
    t[0], theta[0] = 0.0, data.qpos[0]
    for k in range(n):
        coupled.mj_step()
        t[k + 1], theta[k + 1] = data.time, data.qpos[0]
    return t, theta, coupled


def frictionless_levers() -> JointScenario:
    """The frictionless pair with each muscle on a lever (an anchor 0.35 m out on the base, a point 0.03 m
    out on the link, at right angles at angle zero), their damping linear (the paper's, negative at rest,
    keeps a frictionless link on levers ringing, and the ringing's phase is not a thing to converge)."""
    spec = on_levers(frictionless_pair().spec)
    for table in spec["muscle"]:
        table["model"]["damping"] = "linear"
    return JointScenario.from_dict(spec)


def frictionless_slider() -> JointScenario:
    """Figure 4's rig as a slider, 2.5 s, on a guide at 60 degrees, the muscle without Coulomb friction, at
    2 bar and 20 mm at the start (clear of the stops, where MuJoCo's soft limits and pamsim's exact ones
    would differ by design), its damping linear (as the levers'), the guide's viscous friction 50 N s/m
    (so that it is at rest at the end, where the two must balance the same forces)."""
    spec = copy.deepcopy(tomllib.loads((ROOT / "scenarios" / "acra2012_fig4_slider.toml").read_text()))
    spec["slider"].update(incline_rad=math.pi / 3, initial_position_m=0.02, b_N_s_per_m=50.0)
    spec["muscle"][0]["pressure"]["initial_gauge_bar"] = 2.0
    spec["muscle"][0]["model"].update(friction="none", damping="linear")
    spec["simulation"]["duration_s"] = 2.5
    return JointScenario.from_dict(spec)


def frictionless_elastic() -> JointScenario:
    """The shipped pair on 2 kN/m tendons (``antagonistic_elastic.toml``, its damping linear), without Coulomb
    friction on the bearing or the muscles: the spring in series and the massless muscle end are pamsim's,
    integrated over each MuJoCo step with the tendon's path held."""
    spec = tomllib.loads((ROOT / "scenarios" / "antagonistic_elastic.toml").read_text())
    spec["joint"]["tau_coulomb_Nm"] = 0.0
    for table in spec["muscle"]:
        table["model"] = dict(table["model"], friction="none")
    return JointScenario.from_dict(spec)


@pytest.mark.parametrize("make, bound", [(frictionless_pair, 0.01), (frictionless_levers, 0.01),
                                         (frictionless_slider, 1e-3), (frictionless_elastic, 0.01)],
                         ids=["pulleys", "levers", "slider", "elastic tendons"])
def test_the_coupling_converges_to_pamsims_joint_at_first_order(make, bound):
    """For pulleys, levers (spatial tendons), a slider (a slide joint) and elastic tendons: the error against
    pamsim's own run is within 1.5 Richardson estimates, halves with the step, and is below ``bound`` (rad,
    or m) at dt = 0.25 ms; at rest the tensions, pressures and (on elastic tendons) the muscles' own
    contractions are pamsim's."""
    scenario = make()
    dt = 2.5e-4
    # The reference sampled at MuJoCo's finer step: a 1 kHz trace interpolated across a fast swing would
    # add an error of its own that no step of MuJoCo's removes.
    simulation = {**scenario.spec.get("simulation", {}), "sample_rate_Hz": 2.0 / dt}
    reference = simulate_joint(JointScenario.from_dict({**copy.deepcopy(scenario.spec), "solver": {"rtol": 1e-9},
                                                        "simulation": simulation}), "native")
    t1, th1, coupled = mujoco_run(scenario, dt)
    t2, th2, _ = mujoco_run(scenario, dt / 2)
    err1 = np.max(np.abs(th1 - np.interp(t1, reference.t_s, reference.position)))
    err2 = np.max(np.abs(th2 - np.interp(t2, reference.t_s, reference.position)))
    richardson = 2.0 * np.max(np.abs(th1 - th2[::2]))
    assert err1 <= 1.5 * richardson, (err1, richardson)
    assert err2 <= err1 / 1.5, (err1, err2)
    assert err1 < bound
    # at rest both balance the same torques: the static equilibrium
    assert th1[-1] == pytest.approx(reference.position[-1], abs=1e-7)
    for m in reference.muscles:
        assert coupled.tension_N(m) == pytest.approx(reference.muscle(m, "F_tendon_N")[-1], rel=1e-6)
        assert coupled.outputs(m)["chamber.p_gauge_Pa"] == pytest.approx(reference.muscle(m, "p_gauge_Pa")[-1], rel=1e-6)
        if any("tendon_stiffness_N_per_m" in table for table in scenario.spec["muscle"]):
            assert coupled.outputs(m)["series_spring.x_m"] == pytest.approx(reference.muscle(m, "x_m")[-1], rel=1e-6)


def test_a_component_on_an_elastic_muscles_end_acts_there_in_mujoco():
    """A ``linear_spring`` named ``spring`` (the name the scenario docs use) on the flexor's end of the
    frictionless elastic pair: it acts on the massless end, not on MuJoCo's tendon, so MuJoCo comes to rest
    where pamsim's joint does (-0.252 rad, where the pair alone rests at +0.309), with the same tensions,
    contractions and spring force."""
    spec = copy.deepcopy(frictionless_elastic().spec)
    spec["muscle"][0]["component"] = [{"name": "spring", "type": "linear_spring", "k_N_per_m": 1000.0,
                                       "x_free_m": 0.02, "connect": {"flange": "load.flange"}}]
    reference = simulate_joint(JointScenario.from_dict({**copy.deepcopy(spec), "solver": {"rtol": 1e-9}}), "native")
    _, theta, coupled = mujoco_run(JointScenario.from_dict(spec), 2.5e-4)
    assert reference.position[-1] < -0.2
    assert theta[-1] == pytest.approx(reference.position[-1], abs=1e-7)
    for m in reference.muscles:
        assert coupled.tension_N(m) == pytest.approx(reference.muscle(m, "F_tendon_N")[-1], rel=1e-6)
        assert coupled.outputs(m)["series_spring.x_m"] == pytest.approx(reference.muscle(m, "x_m")[-1], rel=1e-6)
    F_spring_N = reference.signals["flexor_spring.F_spring_N"][-1]
    assert abs(F_spring_N) > 1.0
    assert coupled.outputs("flexor")["spring.F_spring_N"] == pytest.approx(F_spring_N, rel=1e-6)


def test_a_missing_actuator_or_one_not_on_a_tendon_is_refused_by_name():
    scenario = frictionless_pair()
    model = mujoco.MjModel.from_xml_string(joint_mjcf(scenario))
    data = mujoco.MjData(model)
    table, sc = scenario.muscles[0]
    with pytest.raises(InputError, match="muscle 'flexor': actuator = 'elbow': the MuJoCo model has no such actuator"):
        MujocoMuscles(model, data, [CoupledMuscle("flexor", sc, "elbow", 0.28)])
    joint_actuated = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint name="j" type="hinge"/><geom size=".1"/></body></worldbody>'
        '<actuator><motor name="m" joint="j"/></actuator></mujoco>')
    with pytest.raises(InputError, match="actuator = 'm': it does not act on a tendon"):
        MujocoMuscles(joint_actuated, mujoco.MjData(joint_actuated), [CoupledMuscle("flexor", sc, "m", 0.28)])
