"""
A stiff tendon tends to the rigid one
=====================================

``scenarios/antagonistic_elastic.toml`` is the antagonistic pair on tendons of 2 kN/m.  This runs it with
tendons of 2, 10, 100 and 1000 kN/m and with rigid ones (python backend), and prints the largest gap of
the link's angle from the rigid pair's: it falls as 1/k, with the tendon's stretch T/k.  It also prints
what each costs, in right-hand-side evaluations on python (LSODA, stiff when it must) and native
(Dormand-Prince while the link moves, whose steps the muscle end's time constant c/k bounds, and Rodas4
where a held link's steps are bound by their stability).  The figure shows the angles.
"""

import copy
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pamsim.joints import simulate_joint  # noqa: E402
from pamsim.joints.scenario import JointScenario  # noqa: E402

with open("../scenarios/antagonistic_elastic.toml", "rb") as f:
    spec = tomllib.load(f)


def run(k_N_per_m, backend="python"):
    """The pair on tendons of ``k_N_per_m`` (None: rigid) on ``backend``."""
    changed = copy.deepcopy(spec)
    for muscle in changed["muscle"]:
        muscle.pop("tendon_stiffness_N_per_m")
        if k_N_per_m is not None:
            muscle["tendon_stiffness_N_per_m"] = k_N_per_m
    return simulate_joint(JointScenario.from_dict(changed, base_dir="../scenarios"), backend)


rigid = run(None)
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
ax.plot(rigid.t_s, np.degrees(rigid.theta_rad), "k-", lw=2, label="rigid tendons")
for k in (2e3, 1e4, 1e5, 1e6):
    res = run(k)
    gap = np.max(np.abs(np.interp(rigid.t_s, res.t_s, res.theta_rad) - rigid.theta_rad))
    print(f"k = {k:8.0f} N/m: largest angle gap {gap:.3e} rad, final angle {res.theta_rad[-1]:.4f} rad "
          f"(rigid {rigid.theta_rad[-1]:.4f}), final stretch {res.muscle('flexor', 'stretch_m')[-1] * 1e3:.3f} mm; "
          f"RHS evaluations python {res.stats['rhs_evaluations']}, native {run(k, 'native').stats['rhs_evaluations']}")
    ax.plot(res.t_s, np.degrees(res.theta_rad), label=f"{k / 1e3:g} kN/m")
ax.set_xlabel("time [s]")
ax.set_ylabel("joint angle [deg]")
ax.legend()
fig.savefig("plot_tendon_stiffness.png", dpi=120)
