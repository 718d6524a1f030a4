"""The Gymnasium environment pamsim/MusclePosition-v0 (pamsim.envs) and the engine session it steps.

- Gymnasium's own checker passes, with its warnings as errors, for both backends and both commands;
- the trajectory of an episode equals ``pamsim.simulate`` of :meth:`replay_scenario` (the same actions
  as a ``steps`` signal) on the same backend: the Python backend to the bit, the native one to rounding
  (the batch's samples are the dense output at each step's end, the session's the step's solution),
  with the same right-hand-side evaluations and events;
- the same seed gives the same trajectory, also in worker processes (AsyncVectorEnv);
- bad input is refused (InputError, ResetNeeded) and leaves the state as it was.
"""

from __future__ import annotations

import math
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.error import ResetNeeded
from gymnasium.utils.env_checker import check_env

import pamsim
from pamsim.envs import MUSCLE_POSITION_ID, MusclePositionEnv
from pamsim.envs.muscle_position import DEFAULT_SCENARIO
from pamsim.errors import InputError, SolverFailure

from conftest import SCENARIOS

BACKENDS = ("native", "python")
COMMANDS = ("valve", "pressure")


def _actions(command: str, n: int, seed: int = 5) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-1.0 if command == "valve" else 0.0, 1.0, (n, 1))


def _episode(env, actions, seed: int = 3, options=None) -> tuple[np.ndarray, np.ndarray]:
    obs, _ = env.reset(seed=seed, options=options)
    observations, rewards = [obs], []
    for a in actions:
        obs, reward, terminated, truncated, _ = env.step(a)
        assert not terminated
        observations.append(obs)
        rewards.append(reward)
    return np.array(observations), np.array(rewards)


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("backend", BACKENDS)
def test_gymnasium_env_checker_passes_without_warnings(backend, command):
    env = gymnasium.make(MUSCLE_POSITION_ID, backend=backend, command=command)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # check_env reports most of what it finds as warnings
        check_env(env.unwrapped)
        warnings.filterwarnings("ignore", message=".*is different from the unwrapped version")
        check_env(env)  # through make's wrappers too: it then warns only that it is wrapped
    env.close()


def test_default_plant_is_the_fig4_scenarios():
    fig4 = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    env = MusclePositionEnv()
    assert env.scenario.spec["model"] == fig4.spec["model"]
    assert env.scenario.spec["load"] == fig4.spec["load"] == DEFAULT_SCENARIO["load"]
    assert env.scenario.spec["solver"] == fig4.spec["solver"]
    assert env.scenario.parameters.items() == fig4.parameters.items()
    assert env.supply_gauge_Pa == fig4.final_pressure_gauge_Pa == 3.6e5
    # the same plant from the file
    from_file = MusclePositionEnv(SCENARIOS / "acra2012_fig4.toml")
    assert from_file.scenario.spec["model"] == env.scenario.spec["model"]
    assert "measured" in fig4.spec and "measured" not in from_file.scenario.spec  # not the environment's test
    assert from_file.reachable_range_m == env.reachable_range_m


def test_spaces_and_reference_range():
    env = MusclePositionEnv()
    lo, hi = env.reachable_range_m
    # the static equilibrium at 3.6 bar with 22.74 N (pamsim static --pressure-bar 3.6 --load-N 22.74)
    assert lo == 0.0 and hi == pytest.approx(0.05922508562502729, rel=1e-9)
    assert env.reference_range_m == pytest.approx((0.1 * hi, 0.9 * hi))
    assert env.action_space == gymnasium.spaces.Box(-1.0, 1.0, (1,), np.float64)
    assert env.observation_space.shape == (4,)
    assert env.observation_space.low[0] == 0.0 and env.observation_space.high[0] == pytest.approx(0.115679, rel=1e-5)
    pressure = MusclePositionEnv(command="pressure")
    assert pressure.action_space == gymnasium.spaces.Box(0.0, 1.0, (1,), np.float64)
    assert pressure.observation_space.high[2] == 3.6e5
    references = [MusclePositionEnv().reset(seed=s)[0][3] for s in range(40)]
    assert min(references) >= env.reference_range_m[0] and max(references) <= env.reference_range_m[1]
    assert np.ptp(references) > 0.5 * np.diff(env.reference_range_m)[0]  # drawn across the range


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("backend", BACKENDS)
def test_episode_equals_simulate_of_its_replay_scenario(backend, command):
    env = MusclePositionEnv(backend=backend, command=command)
    actions = _actions(command, env.n_steps)
    obs, rewards = _episode(env, actions)
    result = pamsim.simulate(env.replay_scenario(actions), backend=backend)
    assert np.array_equal(result.t_s, np.linspace(0.0, 2.0, 201))
    # The same integration: every right-hand-side evaluation and event.
    assert env.solver_stats() == {"rhs_evaluations": result.stats["rhs_evaluations"],
                                  "events": result.stats["events"]}
    assert env.solver_stats()["events"] > 10  # the random commands move the load up and down
    dx, dv = np.abs(obs[:, 0] - result.x_m), np.abs(obs[:, 1] - result.v_m_s)
    if command == "valve":
        dp = np.abs(obs[:, 2] - result.p_gauge_Pa)
    else:  # the observation is the pressure held over the step just taken; the result's, the next one's
        assert np.array_equal(obs[1:, 2], actions[:, 0] * env.supply_gauge_Pa)
        dp = np.abs(obs[1:, 2] - result.p_gauge_Pa[:-1])
    if backend == "python":  # the same solve_ivp calls: the same numbers
        assert dx.max() == 0.0 and dv.max() == 0.0 and dp.max() == 0.0
    else:  # the same steps; the batch samples each step's dense output at its end
        assert dx.max() <= 1e-14 and dv.max() <= 1e-13 and dp.max() <= 1e-7  # measured 1.4e-17, 5e-16, 1.2e-10
    assert np.array_equal(rewards, -np.abs(obs[1:, 0] - obs[1:, 3]) / np.diff(env.reachable_range_m)[0])
    assert env.mode() == int(result.mode[-1])


def test_the_backends_agree_to_micrometres():
    actions = _actions("valve", 200)
    native, _ = _episode(MusclePositionEnv(backend="native"), actions)
    python, _ = _episode(MusclePositionEnv(backend="python"), actions)
    assert np.abs(native[:, 0] - python[:, 0]).max() < 1e-5  # measured 2.1 um: two integrators
    assert np.abs(native[:, 2] - python[:, 2]).max() < 100.0  # Pa; measured 7 Pa


@pytest.mark.parametrize("backend", BACKENDS)
def test_same_seed_same_trajectory_and_other_seeds_other_references(backend):
    actions = _actions("valve", 60)
    runs = []
    for _ in range(2):
        env = MusclePositionEnv(backend=backend, episode_duration_s=0.6)
        runs.append(_episode(env, actions, seed=11))
        # a second episode of the same environment, with the generator carried on
        runs.append(_episode(env, actions, seed=None))
    assert np.array_equal(runs[0][0], runs[2][0]) and np.array_equal(runs[0][1], runs[2][1])
    assert np.array_equal(runs[1][0], runs[3][0]) and np.array_equal(runs[1][1], runs[3][1])
    assert runs[0][0][0, 3] != runs[1][0][0, 3]
    other = _episode(MusclePositionEnv(backend=backend, episode_duration_s=0.6), actions, seed=12)
    assert other[0][0, 3] != runs[0][0][0, 3]
    # the reset's state does not depend on the previous episode
    assert np.array_equal(runs[0][0][:, :3], runs[1][0][:, :3])


@pytest.mark.parametrize("context", [None, "spawn"])
def test_async_vector_env_in_worker_processes_gives_the_serial_trajectories(context):
    n = 210  # past the episode's end: the vector env resets each environment itself
    actions = np.random.default_rng(2).uniform(-1.0, 1.0, (n, 2, 1))
    envs = gymnasium.make_vec(MUSCLE_POSITION_ID, num_envs=2, vectorization_mode="async",
                              vector_kwargs={"context": context})
    try:
        assert isinstance(envs, gymnasium.vector.AsyncVectorEnv)
        obs, _ = envs.reset(seed=[21, 22])
        vector = [obs]
        truncations = []
        for a in actions:
            obs, _, _, truncated, _ = envs.step(a)
            vector.append(obs)
            truncations.append(truncated)
    finally:
        envs.close()
    vector = np.array(vector)
    assert np.array(truncations)[199].all() and not np.array(truncations)[:199].any()
    for i, seed in enumerate((21, 22)):
        serial, _ = _episode(MusclePositionEnv(), actions[:200, i], seed=seed)
        assert np.array_equal(vector[:201, i], serial)


def test_gymnasium_make_by_module_prefix_and_kwargs():
    env = gymnasium.make("pamsim.envs:pamsim/MusclePosition-v0", backend="python", weight_N=12.74,
                         control_rate_Hz=50.0, episode_duration_s=1.0)
    assert env.unwrapped.n_steps == 50 and env.unwrapped.backend == "python"
    assert env.unwrapped.scenario.spec["load"] == {"weight_N": 12.74}
    obs, info = env.reset(seed=0, options={"reference_m": 0.03})
    assert obs[3] == 0.03 and info == {"time_s": 0.0}
    lo, hi = env.unwrapped.reachable_range_m
    for reference in (lo, hi):  # beyond the range references are drawn from, inside the observation space
        obs, _ = env.reset(options={"reference_m": reference})
        assert obs[3] == reference and obs in env.observation_space
    obs, _, _, _, info = env.step(np.array([1.0]))
    assert info == {"time_s": 0.02} and obs[2] > 0.0


def test_other_muscle_and_load():
    env = MusclePositionEnv(muscle="kothera2009_5a", mass_kg=1.0, supply_gauge_Pa=4e5)
    assert env.scenario.muscle.name == "kothera2009_5a"
    assert env.scenario.spec["model"]["static_force"] == env.scenario.muscle.default_static_force
    obs, _ = env.reset(seed=0)
    for _ in range(50):
        obs, *_ = env.step(np.array([1.0]))
    assert obs[0] > 0.0 and obs[2] == pytest.approx(4e5, rel=0.01)  # compression takes it 333 Pa past the supply


def test_random_episodes_stay_inside_the_observation_bounds_unclipped():
    for command in COMMANDS:
        env = MusclePositionEnv(command=command)
        low, high = env.observation_space.low, env.observation_space.high
        for seed in range(5):
            env.reset(seed=seed)
            for a in _actions(command, env.n_steps, seed=seed):
                env.step(a)
                states = env.states()
                x, v = states["load.x_m"], states["load.v_m_s"]
                assert low[0] <= x <= high[0] and low[1] < v < high[1]
                if command == "valve":
                    assert low[2] < states["chamber.p_abs_Pa"] - 101325.0 < high[2]


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, names", [
    ({"muscle": "no_such_muscle"}, "model.muscle"),
    ({"scenario": "no/such/file.toml"}, "no such scenario file"),
    ({"scenario": 3}, "scenario = 3"),
    ({"command": "torque"}, "command = 'torque'"),
    ({"backend": "fmu-cs"}, "backend = 'fmu-cs'"),
    ({"control_rate_Hz": 0.0}, "control_rate_Hz"),
    ({"control_rate_Hz": math.nan}, "control_rate_Hz"),
    ({"episode_duration_s": 0.001}, "episode_duration_s"),
    ({"reference_margin": 0.5}, "reference_margin"),
    ({"weight_N": 10.0, "mass_kg": 1.0}, "at most one"),
    ({"weight_N": -1.0}, "load.weight_N"),
    ({"weight_N": 500.0}, "cannot lift"),
    ({"supply_gauge_Pa": 9e5}, "rating"),
    ({"render_mode": "human"}, "render_mode"),
])
@pytest.mark.filterwarnings("ignore:.*render_mode:UserWarning")  # make's own warning, before the refusal
def test_bad_arguments_are_refused_naming_them(kwargs, names):
    with pytest.raises(InputError, match=names.replace(".", r"\.").replace("(", r"\(")):
        gymnasium.make(MUSCLE_POSITION_ID, **kwargs)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("action", [np.array([1.5]), np.array([-1.01]), np.array([np.nan]), np.array([np.inf]),
                                    np.array([0.5, 0.5]), np.array([[0.5]]), 0.5, "open", None, [2.0],
                                    np.array([1], dtype=np.int64) * 2])
def test_an_action_outside_the_space_is_refused_and_changes_nothing(backend, action):
    actions = _actions("valve", 20)
    reference, _ = _episode(MusclePositionEnv(backend=backend, episode_duration_s=0.2), actions)
    env = MusclePositionEnv(backend=backend, episode_duration_s=0.2)
    obs, _ = env.reset(seed=3)
    observed = [obs]
    for k, a in enumerate(actions):
        if k == 10:
            with pytest.raises(InputError, match="outside the action space"):
                env.step(action)
            assert np.all(np.isfinite(list(env.states().values())))
        observed.append(env.step(a)[0])
    assert np.array_equal(np.array(observed), reference)


def test_actions_of_other_types_inside_the_space_are_taken():
    env = MusclePositionEnv(episode_duration_s=0.05)
    env.reset(seed=0)
    for a in (np.array([0.5], dtype=np.float32), [0.5], (0.5,), np.array([1], dtype=np.int64)):
        env.step(a)
    assert env.time_s == pytest.approx(0.04)


def test_step_before_reset_and_after_the_last_step_needs_a_reset():
    env = MusclePositionEnv(episode_duration_s=0.03)
    with pytest.raises(ResetNeeded, match="first"):
        env.step(np.array([0.0]))
    env.reset(seed=0)
    truncated = [env.step(np.array([1.0]))[3] for _ in range(3)]
    assert truncated == [False, False, True]
    with pytest.raises(ResetNeeded, match="last step"):
        env.step(np.array([0.0]))
    env.reset()
    env.step(np.array([0.0]))


def test_bad_reset_options_and_replay_actions_are_refused():
    env = MusclePositionEnv()
    with pytest.raises(InputError, match="reference_m"):
        env.reset(options={"reference_m": 0.09})  # beyond the reachable 59 mm
    with pytest.raises(InputError, match="reference_m"):
        env.reset(options={"reference_m": math.nan})
    with pytest.raises(InputError, match="unknown"):
        env.reset(options={"target": 0.01})
    with pytest.raises(InputError, match=r"actions\[1\]"):
        env.replay_scenario([0.0, 1.5])
    with pytest.raises(InputError, match="at least one"):
        env.replay_scenario([])


def test_a_solver_failure_ends_the_episode_without_a_nan_state():
    env = MusclePositionEnv(episode_duration_s=0.1)
    env.reset(seed=0)
    session = env._plant._session
    session.reset(env._plant._params, env._plant._u, 1e-6, 1e-3, 1)  # one internal step per advance: too few
    env._k = 0
    with pytest.raises(SolverFailure, match="internal steps"):
        env.step(np.array([1.0]))
    with pytest.raises(ResetNeeded):
        env.step(np.array([1.0]))
    obs, _ = env.reset(seed=0)
    assert np.all(np.isfinite(obs))


# ----------------------------------------------------------------------------- the engine session
def _session():
    from pamsim.native.backend import case_inputs
    from pamsim.native.engine import engine_library

    case = case_inputs(pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml"))
    library = engine_library(case.assembly)
    first = case.engine_case(library, 1)
    return library.session(), first


def test_engine_session_refuses_bad_inputs_and_times_and_changes_nothing():
    session, case = _session()
    u = np.array(case.segment_u[1])  # the valve open
    settings = (case.rtol, case.max_step_s, case.max_steps)
    with pytest.raises(InputError, match="must be reset first"):
        session.advance(u, 0.1)
    bad = np.array(case.params)
    bad[3] = np.nan
    with pytest.raises(InputError, match="must be a finite number"):
        session.reset(bad, u, *settings)
    with pytest.raises(InputError, match="rtol"):
        session.reset(case.params, u, 0.0, *settings[1:])
    session.reset(case.params, u, *settings)
    session.advance(u, 0.1)
    before = session.states.copy(), session.time_s
    with pytest.raises(InputError, match="valve_command = nan: must be a finite number"):
        session.advance(np.array([np.nan, 3.6e5, 0.0]), 0.2)
    with pytest.raises(InputError, match="must be a finite time after"):
        session.advance(u, 0.1)
    session.read()
    assert np.array_equal(session.states, before[0]) and session.time_s == before[1] == 0.1
    session.advance(u, 0.2)
    assert session.states[0] > before[0][0]  # it goes on from there
    high, low = session.extremes()
    names = session.library.names["outputs"]
    assert high[names.index("load.x_m")] >= session.states[0] >= low[names.index("load.x_m")] == 0.0


def test_engine_session_integrates_the_work_as_the_batch_does():
    session, case = _session()
    result = pamsim.simulate(pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml"), backend="native")
    session.reset(case.params, case.segment_u[0], case.rtol, case.max_step_s, case.max_steps)
    session.advance(case.segment_u[0], 1.0)
    session.advance(case.segment_u[1], 8.0)
    names = session.library.names["states"]
    assert session.states[names.index("muscle.W_muscle_J")] == pytest.approx(result.signals["W_muscle_J"][-1],
                                                                           rel=1e-12)
    assert session.states[0] == pytest.approx(result.x_m[-1], rel=1e-12)
    assert session.stats["rhs_evaluations"] == result.stats["rhs_evaluations"]
