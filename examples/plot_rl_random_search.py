"""
Reinforcement learning: a linear policy by random search
========================================================

Train a controller for ``pamsim/MusclePosition-v0`` (the Shadow muscle lifting 22.74 N, a valve
command every 10 ms, a new reference contraction each episode) with basic random search (Mania,
Guy and Recht, "Simple random search provides a competitive approach to reinforcement learning",
2018): no gradient and no library beyond numpy.  The policy is linear in the scaled observation,

    valve command = clip(theta . [(reference - x) / range, v / (1 m/s), p / supply, 1], -1, 1)

Each iteration tries 8 random directions of theta, each way, on the same 2 references, and moves
theta along the 4 directions that did best, weighted by how much more one way earned than the other
(the paper's version V1-t).  The environment runs on the native backend, so the 1,200 episodes
(240,000 steps) take a few seconds.  A proportional valve command alone makes this lightly damped
load oscillate; the search finds that the velocity and pressure terms damp it.
"""

import gymnasium
import matplotlib.pyplot as plt
import numpy as np

import pamsim.envs  # noqa: F401  (registers pamsim/MusclePosition-v0)
from pamsim.figure_style import REFERENCE, series

env = gymnasium.make("pamsim/MusclePosition-v0")
lo, hi = env.unwrapped.reachable_range_m
span, supply = hi - lo, env.unwrapped.supply_gauge_Pa


def features(obs):
    x, v, p, reference = obs
    return np.array([(reference - x) / span, v, p / supply, 1.0])


def episode_return(theta, seed, record=False):
    obs, _ = env.reset(seed=int(seed))
    total, trace, truncated = 0.0, [], False
    while not truncated:
        action = np.clip([theta @ features(obs)], -1.0, 1.0)
        obs, reward, _, truncated, info = env.step(action)
        total += reward
        if record:
            trace.append((info["time_s"], obs[0], obs[3], action[0]))
    return (total, np.array(trace)) if record else total


rng = np.random.default_rng(2012)
theta = np.zeros(4)  # start: the valve stays closed and the load on its lower stop
directions, best, step_size, noise = 8, 4, 1.0, 2.0
eval_seeds = np.arange(1000, 1008)  # the learning curve: the same 8 references every iteration
curve = [np.mean([episode_return(theta, s) for s in eval_seeds])]
for iteration in range(30):
    seeds = rng.integers(0, 2**31, size=2)  # common random numbers: both signs see the same 2 references
    deltas = rng.standard_normal((directions, theta.size))
    plus = np.array([np.mean([episode_return(theta + noise * d, s) for s in seeds]) for d in deltas])
    minus = np.array([np.mean([episode_return(theta - noise * d, s) for s in seeds]) for d in deltas])
    top = np.argsort(-np.maximum(plus, minus))[:best]  # the directions that did best either way
    spread = np.concatenate([plus[top], minus[top]]).std() or 1.0
    theta = theta + step_size / (best * spread) * ((plus[top] - minus[top]) @ deltas[top])
    curve.append(np.mean([episode_return(theta, s) for s in eval_seeds]))

steps = 200 * (2 * directions * len(seeds) + len(eval_seeds)) * (len(curve) - 1)
print(f"policy theta = {np.array2string(theta, precision=2)}")
print(f"mean return on 8 held-out references: {curve[0]:.1f} at the start, {curve[-1]:.1f} after "
      f"{len(curve) - 1} iterations ({steps:,} steps)")

# %%
# The learning curve, and one episode of the learned policy: the contraction follows the reference.
_, trace = episode_return(theta, eval_seeds[0], record=True)
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
ax1.plot(np.arange(len(curve)), curve, **series(0, points=True))
ax1.set_xlabel("iteration")
ax1.set_ylabel("mean return (8 references)")
ax1.set_title("basic random search, linear policy")
ax2.plot(trace[:, 0], 1e3 * trace[:, 1], label="contraction", **series(0))
ax2.plot(trace[:, 0], 1e3 * trace[:, 2], label="reference", **REFERENCE)
ax2.set_xlabel("time [s]")
ax2.set_ylabel("contraction [mm]")
ax2.set_title("learned policy, one episode")
ax2.legend()
fig.tight_layout()
fig.savefig("rl_random_search.png", dpi=110)
