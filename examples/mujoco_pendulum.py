"""
Two pamsim muscles on a MuJoCo hinge
====================================

The antagonistic pair of ``scenarios/antagonistic_pair.toml`` (two Shadow 6 mm x 300 mm muscles with
the ACRA 2012 model on a finger-sized link) as a MuJoCo model: a hinge with the link's inertia, weight,
bearing and limits, and one fixed tendon and actuator per muscle (``pamsim.coupling.mujoco.joint_mjcf``).
Before each MuJoCo step, each pamsim muscle reads its tendon's length and velocity, advances its valve,
chamber and forces over the step on the native engine, and pulls on its tendon
(``pamsim.coupling.mujoco.MujocoMuscles``).  The same pair run by pamsim itself, with its exact
stick/slip joint, is drawn beside it.  Needs ``pip install 'pamsim[mujoco]'``.
"""

import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from pamsim.coupling.mujoco import MujocoMuscles, joint_mjcf, joint_muscles  # noqa: E402
from pamsim.joints import load_joint_scenario, simulate_joint  # noqa: E402

scenario = load_joint_scenario("../scenarios/antagonistic_pair.toml")
model = mujoco.MjModel.from_xml_string(joint_mjcf(scenario, timestep_s=2.5e-4))
data = mujoco.MjData(model)
muscles = MujocoMuscles(model, data, joint_muscles(scenario))

steps = int(round(scenario.duration_s / model.opt.timestep))
t, theta, tension = np.empty(steps + 1), np.empty(steps + 1), np.empty((steps + 1, 2))
t[0], theta[0], tension[0] = 0.0, data.qpos[0], 0.0
wall = time.perf_counter()
for k in range(steps):
    muscles.mj_step()
    t[k + 1], theta[k + 1] = data.time, data.qpos[0]
    tension[k + 1] = [muscles.tension_N(m.name) for m in muscles.muscles]
wall = time.perf_counter() - wall
print(f"MuJoCo, {steps} steps of {model.opt.timestep * 1e3:g} ms: {wall * 1e6 / steps / 2:.1f} us per step and muscle, "
      f"final angle {theta[-1]:.4f} rad")

# %%
# pamsim's own run of the same pair (the bearing's Coulomb friction exact there, MuJoCo's frictionloss
# a soft constraint here):

own = simulate_joint(scenario)
print(f"pamsim: final angle {own.theta_rad[-1]:.4f} rad; largest difference over the run "
      f"{np.max(np.abs(np.interp(own.t_s, t, theta) - own.theta_rad)):.4f} rad")

fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 6), layout="constrained")
ax1.plot(own.t_s, np.degrees(own.theta_rad), "k", label="pamsim joint")
ax1.plot(t, np.degrees(theta), "C1--", label="MuJoCo hinge, pamsim muscles")
ax1.set_ylabel("joint angle [deg]")
ax1.legend()
for k, m in enumerate(muscles.muscles):
    ax2.plot(t, tension[:, k], f"C{k}", label=f"{m.name} tension (MuJoCo)")
    ax2.plot(own.t_s, own.muscle(m.name, "F_tendon_N"), f"C{k}:", label=f"{m.name} (pamsim)")
ax2.set_ylabel("tendon force [N]")
ax2.set_xlabel("time [s]")
ax2.legend(fontsize="small")
fig.savefig("mujoco_pendulum.png", dpi=110)
