"""Steps per second of ``pamsim/MusclePosition-v0`` at a 100 Hz control rate, native and Python backends.

    python benchmarks/bench_gym.py [--repeat N] [--episodes E]

Each row steps one environment made by ``gymnasium.make`` (with the wrappers ``make`` adds) through
whole episodes of 200 steps (2 s), resets included, with actions drawn beforehand from a seeded
generator, so that drawing them is not timed: uniform in the action space (the valve or the pressure
never settles) and, as a policy would act, a proportional valve command towards the reference
(``clip(50 (reference - x), -1, 1)``, computed in the loop and timed).  Native rows run E episodes,
Python rows max(1, E // 25); each figure is the best of N repeats, wall time; the ratio is of figures
from this run.  The last row steps 2 native environments in an ``AsyncVectorEnv`` (worker processes,
the actions sent and observations returned through pipes): the steps of both, per second; and the
engine session alone (``EngineSession.step`` with the same random valve commands, no environment
around it), what the library call costs.

Before the timings it prints how closely an episode of 200 random actions (seeded) agrees with
``pamsim.simulate`` of the environment's ``replay_scenario`` of the same actions on the same backend,
and the two backends' episodes with each other: the largest differences in contraction, velocity and
pressure over the 201 samples, and the right-hand-side evaluations and events of both.

The first native environment of a process compiles the model with the engine (about 2 s) unless the
native cache holds it; that is done before the timing.
"""

from __future__ import annotations

import argparse
import os
import time

import gymnasium
import numpy as np

import pamsim
import pamsim.envs  # noqa: F401  (registers the environments)
from pamsim.envs import MusclePositionEnv

ENV_ID = "pamsim/MusclePosition-v0"
TARGET_STEPS_PER_S = 20_000


def _run(env, episodes: int, actions: np.ndarray | None) -> int:
    """Step ``env`` through ``episodes`` episodes; returns the steps taken."""
    steps = 0
    for e in range(episodes):
        obs, _ = env.reset(seed=e)
        truncated = False
        k = 0
        while not truncated:
            if actions is None:
                action = np.array([min(1.0, max(-1.0, 50.0 * (obs[3] - obs[0])))])
            else:
                action = actions[k]
            obs, _, _, truncated, _ = env.step(action)
            k += 1
        steps += k
    return steps


def steps_per_s(backend: str, command: str, policy: str, episodes: int, repeat: int) -> float:
    """Best of ``repeat`` timings of ``episodes`` episodes, in steps per second."""
    env = gymnasium.make(ENV_ID, backend=backend, command=command)
    low = env.action_space.low[0]
    n = env.unwrapped.n_steps
    actions = None if policy == "proportional" else np.random.default_rng(1).uniform(low, 1.0, (n, 1))
    _run(env, 1, actions)  # warm up: compiled library loaded, generated code imported
    best = 0.0
    for _ in range(repeat):
        t0 = time.perf_counter()
        steps = _run(env, episodes, actions)
        best = max(best, steps / (time.perf_counter() - t0))
    env.close()
    return best


def vector_steps_per_s(episodes: int, repeat: int) -> float:
    """Best of ``repeat`` timings of 2 native environments in an AsyncVectorEnv, steps of both per second."""
    envs = gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="async")
    n = 200  # one episode of the default environment
    actions = np.random.default_rng(1).uniform(-1.0, 1.0, (n, 2, 1))
    envs.reset(seed=0)
    best = 0.0
    for _ in range(repeat):
        envs.reset(seed=0)
        t0 = time.perf_counter()
        for _ in range(episodes):
            for a in actions:
                envs.step(a)
        best = max(best, 2 * episodes * n / (time.perf_counter() - t0))
    envs.close()
    return best


def _episode(env, actions) -> np.ndarray:
    observations = [env.reset(seed=3)[0]]
    observations += [env.step(a)[0] for a in actions]
    return np.array(observations)


def agreement() -> None:
    """Print the episodes' agreement with ``pamsim.simulate`` of their replay scenarios, and across backends."""
    print("agreement of a 200-step episode of random actions (max abs difference over 201 samples):")
    for command in ("valve", "pressure"):
        low = -1.0 if command == "valve" else 0.0
        actions = np.random.default_rng(5).uniform(low, 1.0, (200, 1))
        episodes = {}
        for backend in ("native", "python"):
            env = MusclePositionEnv(backend=backend, command=command)
            obs = episodes[backend] = _episode(env, actions)
            res = pamsim.simulate(env.replay_scenario(actions), backend=backend)
            # with a prescribed pressure, the result's sample k holds the next step's pressure
            p = res.p_gauge_Pa if command == "valve" else np.r_[0.0, res.p_gauge_Pa[:-1]]
            d = np.abs(obs[:, :3] - np.c_[res.x_m, res.v_m_s, p]).max(axis=0)
            same = env.solver_stats() == {k: res.stats[k] for k in ("rhs_evaluations", "events")}
            print(f"  {command:8} {backend:6} env - simulate(replay): x {d[0]:.1e} m, v {d[1]:.1e} m/s, "
                  f"p {d[2]:.1e} Pa; RHS evaluations and events {'equal' if same else 'DIFFER'} "
                  f"({env.solver_stats()['rhs_evaluations']}, {env.solver_stats()['events']})")
        d = np.abs(episodes["native"][:, :3] - episodes["python"][:, :3]).max(axis=0)
        print(f"  {command:8} native - python env:          x {d[0]:.1e} m, v {d[1]:.1e} m/s, p {d[2]:.1e} Pa")


def session_steps_per_s(episodes: int, repeat: int) -> float:
    """Best of ``repeat`` timings of the default plant's engine session alone, random valve commands."""
    plant = MusclePositionEnv().unwrapped._plant
    session, u = plant._session, plant._u.copy()
    k_command = plant._k
    commands = np.random.default_rng(1).uniform(-1.0, 1.0, 200)
    best = 0.0
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(episodes):
            session.reset(plant._params, u, *plant._settings)
            for k, command in enumerate(commands):
                u[k_command] = command
                session.step(u, (k + 1) * 0.01)
        best = max(best, episodes * len(commands) / (time.perf_counter() - t0))
    return best


def main() -> None:
    """Measure and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="timings per row; the best is kept")
    parser.add_argument("--episodes", type=int, default=50, help="native episodes per timing (Python: E // 25)")
    args = parser.parse_args()
    print(f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}; repeat {args.repeat}, "
          f"{args.episodes} native episodes of 200 steps at 100 Hz")
    agreement()
    print(f"{'command':9} {'actions':13} {'native [steps/s]':>17} {'python [steps/s]':>17} {'ratio':>7}  target")
    for command in ("valve", "pressure"):
        for policy in ("random", "proportional"):
            if command == "pressure" and policy == "proportional":
                continue  # the policy is a valve command
            native = steps_per_s("native", command, policy, args.episodes, args.repeat)
            python = steps_per_s("python", command, policy, max(1, args.episodes // 25), args.repeat)
            met = "met" if native >= TARGET_STEPS_PER_S else "NOT met"
            print(f"{command:9} {policy:13} {native:17,.0f} {python:17,.0f} {native / python:6.1f}x  "
                  f">= {TARGET_STEPS_PER_S:,}: {met}")
    vector = vector_steps_per_s(max(1, args.episodes // 5), args.repeat)
    print(f"AsyncVectorEnv, 2 native workers, random valve commands: {vector:,.0f} steps/s (both together)")
    session = session_steps_per_s(args.episodes, args.repeat)
    print(f"engine session alone, random valve commands: {session:,.0f} steps/s")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
