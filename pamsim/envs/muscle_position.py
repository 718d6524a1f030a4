"""``pamsim/MusclePosition-v0``: hold a hanging load at a reference contraction with one muscle.

The plant is a scenario's muscle, load and solver settings (by default those of the ACRA 2012
Figure 4 test: the Shadow 6 mm x 300 mm muscle, 22.74 N, a 3.6 bar supply); the environment replaces
its pressure signal by the agent's action, held over each control step.  ``docs/rl.md`` describes the
spaces, the reward and the episode.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded

from ..errors import InputError, SolverFailure
from ..scenario import Scenario, load_scenario
from ..static import equilibrium_contraction_m
from .plants import PLANTS

DEFAULT_SCENARIO: dict = {
    "name": "muscle_position",
    "model": {"muscle": "shadow_6x300_acra2012", "friction": "load_dependent", "damping": "paper"},
    "load": {"weight_N": 22.74},
    "pressure": {"source": "valve", "supply_gauge_bar": 3.6, "valve_open_time_s": 0.0},
    "simulation": {"duration_s": 1.0},
    "solver": {"method": "LSODA", "rtol": 1e-6},
}
"""The plant when no scenario is given: ``scenarios/acra2012_fig4.toml``'s muscle, load, supply and
solver settings (the file is not installed with the package; a test holds the two equal)."""

COMMANDS = {"valve": "valve_command", "pressure": "prescribed_pressure_gauge_Pa"}
"""What an action sets, by the ``command`` argument: the flat model's input it is held in."""
OBSERVATION_NAMES = ("x_m", "v_m_s", "p_gauge_Pa", "reference_m")
"""The observation's entries, in order: contraction, velocity, muscle pressure (gauge), reference."""
SPEED_BOUND_FACTOR = 2.0
"""The velocity bound of the observation space: this times the speed the load would reach if the
muscle's force at the pressure bound, the weight and the external force all drove it over the whole
stroke (a speed no run reaches; the observation is clipped to its space all the same)."""


def _positive(name: str, value: Any) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {value!r}: must be a positive number") from None
    if not (math.isfinite(number) and number > 0):
        raise InputError(f"{name} = {value!r}: must be a positive finite number")
    return number


def _base_scenario(scenario) -> Scenario:
    if scenario is None:
        return Scenario.from_dict(DEFAULT_SCENARIO, origin="<MusclePosition-v0 default scenario>")
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, (str, Path)):
        return load_scenario(scenario)
    raise InputError(f"scenario = {scenario!r}: must be a scenario file's path or a pamsim.Scenario")


def _check_choices(render_mode, command: str, backend: str, weight_N, mass_kg) -> None:
    """Refuse a rendering, an unknown command or backend, and a load given both as weight and mass.

    Raises
    ------
    InputError
        Naming the first argument that is wrong.
    """
    if render_mode is not None:
        raise InputError(f"render_mode = {render_mode!r}: MusclePosition-v0 renders nothing (render_modes: [])")
    if command not in COMMANDS:
        raise InputError(f"command = {command!r}: must be one of {', '.join(map(repr, COMMANDS))}")
    if backend not in PLANTS:
        raise InputError(f"backend = {backend!r}: must be one of {', '.join(map(repr, PLANTS))}")
    if weight_N is not None and mass_kg is not None:
        raise InputError("weight_N and mass_kg: give at most one of the two")


def _episode(control_rate_Hz, episode_duration_s, reference_margin) -> tuple[float, int, float]:
    """``(rate [Hz], steps per episode, reference margin)`` of the arguments, each checked.

    Raises
    ------
    InputError
        A rate or duration that is not a positive finite number, an episode shorter than one step, or a
        margin outside [0, 0.5).
    """
    rate = _positive("control_rate_Hz", control_rate_Hz)
    duration = _positive("episode_duration_s", episode_duration_s)
    n_steps = round(duration * rate)
    if n_steps < 1:
        raise InputError(f"episode_duration_s = {episode_duration_s!r}: shorter than one control step "
                         f"(1 / control_rate_Hz = {1 / rate:g} s)")
    margin = float(reference_margin) if isinstance(reference_margin, (int, float)) else math.nan
    if not 0.0 <= margin < 0.5:
        raise InputError(f"reference_margin = {reference_margin!r}: must lie in [0, 0.5)")
    return rate, n_steps, margin


def _plant_scenario(scenario, muscle: str | None, weight_N, mass_kg) -> Scenario:
    """The scenario of the plant, with the muscle and load given in place of its own.

    Raises
    ------
    InputError
        A bad scenario, muscle or load, or an external force that is not constant (the environment's time
        restarts every episode).
    """
    base = _base_scenario(scenario)
    changes: dict = {}
    if muscle is not None:
        changes["model"] = {"muscle": muscle}
    if weight_N is not None or mass_kg is not None:
        changes["load"] = {"weight_N": weight_N} if weight_N is not None else {"mass_kg": mass_kg}
    if changes:
        base = base.with_changes(changes)
    external = base.spec["load"].get("external_force")
    if external is not None and external.get("kind") != "constant":
        raise InputError(f"{base.origin}: load.external_force: kind = {external.get('kind')!r}: the environment's "
                         "time restarts every episode, so it takes only a constant external force")
    return base


def _supply_Pa(base: Scenario, supply_gauge_Pa) -> float:
    """The valve's supply [Pa gauge]: the argument, else the scenario's supply (or final prescribed) pressure.

    Raises
    ------
    InputError
        An argument that is not a positive finite number, or a scenario whose pressure is not positive.
    """
    supply = base.final_pressure_gauge_Pa if supply_gauge_Pa is None else _positive("supply_gauge_Pa",
                                                                                    supply_gauge_Pa)
    if not supply > 0:
        raise InputError(f"{base.origin}: the scenario's pressure is {supply:g} Pa gauge: give supply_gauge_Pa > 0")
    return float(supply)


class MusclePositionEnv(gymnasium.Env):
    """One muscle lifting a hanging load, commanded each control step to track a random contraction.

    Parameters
    ----------
    scenario : str, Path or Scenario, optional
        The plant: its muscle, static force, friction, damping, load, parameters, added components,
        initial contraction and solver settings.  Its pressure signal and run length are replaced by the
        environment's.  Default: :data:`DEFAULT_SCENARIO` (``scenarios/acra2012_fig4.toml``'s plant).
    muscle : str, optional
        A shipped muscle's name or a muscle file, in place of the scenario's (its default static force
        with it, as ``Scenario.with_changes`` does).
    weight_N, mass_kg : float, optional
        The hanging load, in place of the scenario's (at most one of the two).
    supply_gauge_Pa : float, optional
        The valve's supply pressure and, with ``command="pressure"``, the largest pressure command [Pa
        gauge].  Default: the scenario's supply (or final prescribed) pressure.
    command : {"valve", "pressure"}
        What an action is: the proportional valve's command in [-1, 1] (-1 vents, 0 closes, 1 opens to the
        supply), or the muscle's gauge pressure as a fraction of ``supply_gauge_Pa`` in [0, 1], imposed at
        once (a prescribed-pressure source).
    backend : {"native", "python"}
        ``"native"``: the scenario's model compiled with pamsim's C engine (a C compiler is needed the first
        time); ``"python"``: its generated Python integrated with ``scipy.integrate.solve_ivp``.
    control_rate_Hz : float
        Actions per second; each is held over 1 / ``control_rate_Hz``.
    episode_duration_s : float
        Simulated time of an episode; it is truncated after round(``episode_duration_s`` x
        ``control_rate_Hz``) steps.
    reference_margin : float
        The reference is drawn uniformly from the reachable range with this fraction of it cut off at
        each end, in [0, 0.5).
    render_mode : None
        No rendering is offered (:meth:`replay_scenario` gives a run that ``pamsim.simulate`` plots).

    Raises
    ------
    InputError
        An unknown muscle or scenario file, a bad argument or scenario key (naming it), a load the muscle
        cannot lift at the largest pressure, a scenario the backend cannot run.
    """

    metadata = {"render_modes": []}

    def __init__(self, scenario: str | Path | Scenario | None = None, *, muscle: str | None = None,
                 weight_N: float | None = None, mass_kg: float | None = None, supply_gauge_Pa: float | None = None,
                 command: str = "valve", backend: str = "native", control_rate_Hz: float = 100.0,
                 episode_duration_s: float = 2.0, reference_margin: float = 0.1, render_mode: str | None = None):
        _check_choices(render_mode, command, backend, weight_N, mass_kg)
        rate, n_steps, margin = _episode(control_rate_Hz, episode_duration_s, reference_margin)
        self.render_mode = None
        self.command = command
        self.backend = backend
        self.control_rate_Hz = rate
        self.n_steps = n_steps
        """Steps of an episode."""
        self._dt = 1.0 / rate

        base = _plant_scenario(scenario, muscle, weight_N, mass_kg)
        self.supply_gauge_Pa = _supply_Pa(base, supply_gauge_Pa)
        """The valve's supply, and the largest pressure command [Pa gauge]."""
        initial = base.spec["pressure"].get("initial_gauge_bar") if base.spec["pressure"]["source"] == "valve" else None
        self._initial_gauge_bar = initial
        # The base run holds the largest value, so that the scenario's checks (the rating) see it.
        self.scenario = self._scenario_with(base, [0.0], [1.0], n_steps)
        """The plant as a scenario: the environment's pressure signal, one episode long."""
        self._plant = PLANTS[backend](self.scenario, COMMANDS[command])

        model = self.scenario.build_model()
        load = model.load
        self.load_N = load.mass_kg * load.g_m_s2 - load.external_N(0.0)
        """The weight less the external force [N]: what the muscle holds at rest without friction."""
        x_lo, x_hi = self._reachable_m(model)
        self.reachable_range_m = (float(x_lo), float(x_hi))
        """Contractions [m] at which the muscle holds the load without friction, at no pressure and at the
        supply: the static equilibria (components added to the rig are not counted)."""
        span = x_hi - x_lo
        self.reference_range_m = (float(x_lo + margin * span), float(x_hi - margin * span))
        """Where the reference is drawn from [m]."""
        self._make_spaces(model, x_lo, x_hi)
        self._span = float(span)
        self._k: int | None = None  # steps taken in this episode; None: reset needed
        self._reference = self.reference_range_m[0]
        self._time_s = 0.0

    def _reachable_m(self, model) -> tuple[float, float]:
        """The static equilibria [m] of the load at no pressure and at the supply.

        Raises
        ------
        InputError
            The muscle cannot lift the load at the supply: there would be no contraction to track.
        """
        x_lo, x_hi = (equilibrium_contraction_m(model.static_force, p, self.load_N, model.stops.x_high_m)
                      for p in (0.0, self.supply_gauge_Pa))
        if not x_hi > x_lo:
            raise InputError(f"{self.scenario.origin}: the muscle cannot lift {self.load_N:g} N at "
                             f"{self.supply_gauge_Pa:g} Pa gauge: no contraction to track")
        return x_lo, x_hi

    def _make_spaces(self, model, x_lo: float, x_hi: float) -> None:
        """The observation space (stops, a speed bound, pressure and the reachable range) and the action
        space of the command, with the bounds the step's fast paths read."""
        stops, load = model.stops, model.load
        p_atm = self.scenario.parameters["p_atm_Pa"]
        p_bound = self.supply_gauge_Pa if self.command == "pressure" else 2.0 * max(
            self.supply_gauge_Pa, self.scenario.parameters["rated_pressure_gauge_Pa"])
        drive = model.static_force.force_N(stops.x_low_m, p_bound) + abs(load.mass_kg * load.g_m_s2) \
            + abs(load.external_N(0.0))
        v_bound = SPEED_BOUND_FACTOR * math.sqrt(2.0 * drive * (stops.x_high_m - stops.x_low_m) / load.mass_kg)
        # the reference: within the reachable range, where reset's option may set it
        self._low = np.array([stops.x_low_m, -v_bound, -p_atm, x_lo])
        self._high = np.array([stops.x_high_m, v_bound, p_bound, x_hi])
        self.observation_space = spaces.Box(self._low, self._high, dtype=np.float64)
        low = -1.0 if self.command == "valve" else 0.0  # Gymnasium's advice: [-1, 1] or [0, 1]
        self.action_space = spaces.Box(low, 1.0, shape=(1,), dtype=np.float64)
        self._a_low, self._a_high = low, 1.0
        self._scale = 1.0 if self.command == "valve" else self.supply_gauge_Pa
        self._lo = tuple(self._low.tolist())
        self._hi = tuple(self._high.tolist())

    # ------------------------------------------------------------------ Gymnasium API
    def reset(self, *, seed: int | None = None, options: Mapping[str, Any] | None = None):
        """Start an episode: the load at rest at the scenario's initial contraction, the valve closed (or
        the pressure at 0 Pa gauge), a new reference.

        Parameters
        ----------
        seed : int, optional
            Seeds the environment's random number generator (the references it draws).
        options : mapping, optional
            ``{"reference_m": x}`` sets this episode's reference [m] (within :attr:`reachable_range_m`)
            instead of drawing it.

        Returns
        -------
        observation : numpy.ndarray
            Contraction [m], velocity [m/s], gauge pressure [Pa], reference [m].
        info : dict
            ``time_s``: 0.0.
        """
        super().reset(seed=seed)
        opts = dict(options or {})
        reference = opts.pop("reference_m", None)
        if opts:
            raise InputError(f"reset options {sorted(opts)}: unknown; the only option is 'reference_m'")
        if reference is None:
            reference = float(self.np_random.uniform(*self.reference_range_m))
        else:
            lo, hi = self.reachable_range_m
            if not (isinstance(reference, (int, float, np.floating)) and lo <= reference <= hi):
                raise InputError(f"reset option reference_m = {reference!r}: must be a contraction in the "
                                 f"reachable range [{lo:.6g}, {hi:.6g}] m")
        self._reference = float(reference)
        self._k = None
        x, v, p = self._plant.reset(0.0)
        self._k = 0
        self._time_s = 0.0
        return self._observation(x, v, p), {"time_s": 0.0}

    def step(self, action):
        """Hold ``action`` over one control step.

        Returns
        -------
        observation : numpy.ndarray
            Contraction [m], velocity [m/s], gauge pressure [Pa] at the step's end, and the reference [m].
        reward : float
            -abs(contraction - reference) / (the reachable range's width).
        terminated : bool
            Always False: no state ends the task.
        truncated : bool
            True at the episode's last step.
        info : dict
            ``time_s``: the time reached [s].

        Raises
        ------
        InputError
            An action outside the action space (or not a number): nothing changes.
        gymnasium.error.ResetNeeded
            Before the first reset, after the episode's last step, and after a solver failure.
        SolverFailure
            The integrator failed (the episode is over: reset).
        """
        if self._k is None or self._k >= self.n_steps:
            raise ResetNeeded("MusclePosition-v0: call reset() " + ("first" if self._k is None else
                                                                  "after the episode's last step (truncated)"))
        value = self._action_value(action)
        k = self._k + 1
        try:
            x, v, p = self._plant.step(value * self._scale, k * self._dt)
        except SolverFailure:
            self._k = None
            raise
        if not (math.isfinite(x) and math.isfinite(v) and math.isfinite(p)):  # never hand on a NaN state
            self._k = None
            raise SolverFailure(f"MusclePosition-v0: non-finite state x = {x}, v = {v}, p = {p} at step {k}")
        self._k = k
        self._time_s = k * self._dt
        reward = -abs(x - self._reference) / self._span
        return self._observation(x, v, p), reward, False, k >= self.n_steps, {"time_s": self._time_s}

    def close(self):
        """Release the plant (an engine session's memory); closing twice is allowed."""
        self._plant = None
        self._k = None

    # ------------------------------------------------------------------ helpers
    def _action_value(self, action) -> float:
        # The common case (an array of the space's shape) is checked without Box.contains, which costs
        # more than the step's integration; anything else goes through it.
        if type(action) is np.ndarray and action.shape == (1,) and action.dtype.kind == "f":
            value = float(action[0])
            if self._a_low <= value <= self._a_high:  # False for NaN
                return value
        else:
            try:
                array = np.asarray(action)
                ok = self.action_space.contains(array)
            except (TypeError, ValueError):
                ok = False
            if ok:
                return float(array.astype(float).reshape(-1)[0])
        raise InputError(f"action {action!r}: outside the action space {self.action_space} "
                         f"(a float array of shape (1,) with values in [{self._a_low:g}, {self._a_high:g}])")

    def _observation(self, x: float, v: float, p: float) -> np.ndarray:
        lo, hi = self._lo, self._hi
        return np.array([min(max(x, lo[0]), hi[0]), min(max(v, lo[1]), hi[1]), min(max(p, lo[2]), hi[2]),
                         self._reference])

    @property
    def reference_m(self) -> float:
        """This episode's reference contraction [m]."""
        return self._reference

    @property
    def time_s(self) -> float:
        """The time reached in this episode [s]."""
        return self._time_s

    def states(self) -> dict[str, float]:
        """Every state of the plant now, by the flat model's names (``load.x_m``, ``chamber.p_abs_Pa``, ...),
        unclipped."""
        return dict(zip(self._plant.state_names, self._plant.states().tolist()))

    def mode(self) -> int:
        """The load's friction or contact mode now (:class:`pamsim.model.Mode`'s value: -1 slip down, 0
        stick, 1 slip up, 2 on the lower stop, 3 on the upper stop)."""
        return self._plant.mode()

    def solver_stats(self) -> dict[str, int]:
        """Right-hand-side evaluations and events of this episode, counted as a ``Result``'s ``stats``
        counts them (equal to those of :meth:`replay_scenario`'s run on the same backend)."""
        return self._plant.stats()

    def replay_scenario(self, actions: Sequence[float] | np.ndarray) -> Scenario:
        """The scenario that runs ``actions`` (one per control step, from t = 0) through ``pamsim.simulate``.

        Its pressure signal holds each action over its step (a ``steps`` signal), its duration is
        ``len(actions)`` steps and it is sampled at the control rate, so sample k of its result is the
        state after step k.  With the environment's backend it takes the steps the environment takes;
        its ``Result`` has every force, the events and the energy balance, and plots.

        Raises
        ------
        InputError
            An action outside the action space, or no action.
        """
        values = np.asarray(actions, dtype=float).reshape(-1)
        if values.size == 0:
            raise InputError("actions: at least one action is needed")
        bad = np.flatnonzero(~((values >= self._a_low) & (values <= self._a_high)))
        if bad.size:
            raise InputError(f"actions[{int(bad[0])}] = {values[bad[0]]!r}: outside the action space "
                             f"[{self._a_low:g}, {self._a_high:g}]")
        return self._scenario_with(self.scenario, [k * self._dt for k in range(values.size)], values.tolist(),
                                   values.size)

    def _scenario_with(self, base: Scenario, times_s: list, values: list, n_steps: int) -> Scenario:
        spec = copy.deepcopy(dict(base.spec))
        spec.pop("controller", None)  # the environment's agent is the controller
        spec.pop("measured", None)  # a paper's measured test is not the environment's
        signal = {"kind": "steps", "times_s": times_s}
        if self.command == "valve":
            pressure = {"source": "valve", "supply_gauge_Pa": self.supply_gauge_Pa,
                        "command": {**signal, "values": values}}
            if self._initial_gauge_bar is not None:
                pressure["initial_gauge_bar"] = self._initial_gauge_bar
        else:
            pressure = {"source": "prescribed",
                        "prescribed": {**signal, "values_gauge_Pa": [a * self.supply_gauge_Pa for a in values]}}
        spec["pressure"] = pressure
        spec["simulation"] = {"duration_s": n_steps * self._dt, "sample_rate_Hz": self.control_rate_Hz,
                              "initial_contraction_m": base.initial_contraction_m}
        return Scenario.from_dict(spec, name=base.name, base_dir=base.base_dir, origin=base.origin)
