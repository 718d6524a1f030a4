"""Hybrid stick/slip integration of a :class:`~pamsim.model.MuscleModel` with
``scipy.integrate.solve_ivp``.

The load is in one of the :class:`~pamsim.model.Mode` s.  Each mode is a
smooth ODE; ``solve_ivp`` integrates it until a terminal event (velocity
reaching zero, a stop reached, the friction margin exceeded) or a breakpoint
of the inputs, and the simulator then decides the next mode from the forces
(MODEL_NOTES sec. 4).  Two thresholds keep the switching free of chatter: a
held load is released only when the net force exceeds friction by
``release_margin_N``, and a stopping load is held when it exceeds it by no
more than ``stick_margin_N`` < ``release_margin_N``.  So every new segment
starts strictly inside its mode and has positive length.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from .core_table import MAX_ZERO_LENGTH_EVENTS
from .errors import SolverFailure
from .model import Mode, MuscleModel
from .result import Result, TransitionEvent


@dataclass(frozen=True)
class SolverOptions:
    """Integrator settings.

    ``rtol`` is relative; absolute tolerances are ``rtol`` times a typical
    scale of each state (10 mm, 0.1 m/s, 1 bar, 10 mg of air, 0.1 J).
    ``held_max_step_s`` caps the step while the load is held.  There the
    states may be constant and the integrator may take one step to the next
    input breakpoint; a release is still found if the inputs are monotonic
    between breakpoints (steps, ramps, lags) and, for a measured trace, the
    step is capped at its sample spacing automatically.  Set this only for
    inputs that are neither (a custom callable that rises and falls).
    """

    method: str = "LSODA"
    rtol: float = 1e-6
    sample_rate_Hz: float = 1000.0
    max_events: int = 20000
    max_step_s: float = math.inf
    held_max_step_s: float = math.inf
    stick_margin_N: float = 1e-7
    release_margin_N: float = 2e-7


_SCALE = {"x_m": 1e-2, "v_m_s": 1e-1, "p_abs_Pa": 1e5, "air_mass_kg": 1e-5}
_REST = (Mode.STICK, Mode.STOP_LOW, Mode.STOP_HIGH)


def _event(fun, direction: float):
    fun.terminal = True
    fun.direction = direction
    return fun


class _Events:
    """Event functions for each mode, built once per run."""

    def __init__(self, model: MuscleModel, opts: SolverOptions):
        stops = model.stops
        eps = opts.release_margin_N
        self.t_left = math.inf  # inputs are read at min(t, t_left): the left limit at a segment's end

        def velocity_zero(t, y):
            return y[1]

        def at_low(t, y):
            return y[0] - stops.x_low_m

        def at_high(t, y):
            return y[0] - stops.x_high_m

        def release_up(t, y):
            net, level = model.rest_forces(min(t, self.t_left), y)
            return net - level - eps

        def release_down(t, y):
            net, level = model.rest_forces(min(t, self.t_left), y)
            return -net - level - eps

        self.by_mode = {
            Mode.SLIP_UP: [("velocity_zero", _event(velocity_zero, -1.0)), ("stop_high", _event(at_high, 1.0))],
            Mode.SLIP_DOWN: [("velocity_zero", _event(lambda t, y: y[1], 1.0)), ("stop_low", _event(at_low, -1.0))],
            Mode.STICK: [("release_up", _event(release_up, 1.0)), ("release_down", _event(release_down, 1.0))],
            Mode.STOP_LOW: [("release_up", _event(release_up, 1.0))],
            Mode.STOP_HIGH: [("release_down", _event(release_down, 1.0))],
        }


def _rest_mode(model: MuscleModel, t: float, y, where: Mode, stick_margin_N: float) -> Mode:
    """Mode of a load at zero velocity: slip if the net force beats friction, else held."""
    net, level = model.rest_forces(t, y)
    if where != Mode.STOP_HIGH and net - level > stick_margin_N:
        return Mode.SLIP_UP
    if where != Mode.STOP_LOW and -net - level > stick_margin_N:
        return Mode.SLIP_DOWN
    return where


def initial_mode(model: MuscleModel, t: float, y, stick_margin_N: float = SolverOptions.stick_margin_N) -> Mode:
    """Mode of a load starting at rest at ``y``."""
    x = y[0]
    where = Mode.STOP_LOW if x <= model.stops.x_low_m else Mode.STOP_HIGH if x >= model.stops.x_high_m else Mode.STICK
    return _rest_mode(model, t, y, where, stick_margin_N)


def simulate_model(model: MuscleModel, duration_s: float, options: SolverOptions | None = None,
                   x0_m: float = 0.0, name: str = "", p0_gauge_Pa: float | None = None) -> Result:
    """Integrate ``model`` from rest at ``x0_m`` (chamber at ``p0_gauge_Pa``, if given) over ``[0, duration_s]``.

    Raises :class:`SolverFailure` when ``solve_ivp`` fails, the event count
    exceeds ``options.max_events``, or the switching stops making progress.
    """
    opts = options or SolverOptions()
    wall0 = time.perf_counter()
    names = model.state_names
    atol = np.array([opts.rtol * _SCALE.get(n, 0.1) for n in names])
    n_samples = int(round(duration_s * opts.sample_rate_Hz)) + 1
    grid = np.linspace(0.0, duration_s, n_samples)
    breaks = sorted({b for b in model.breakpoints if 0.0 < b < duration_s} | {duration_s})
    events = _Events(model, opts)
    m = model.load.mass_kg
    held_max_step = min(opts.held_max_step_s, model.max_input_step_s)

    t = 0.0
    y = model.initial_state(x0_m, p0_gauge_Pa)
    mode = initial_mode(model, t, y, opts.stick_margin_N)
    ts, ys, modes = [], [], []
    transitions: list[TransitionEvent] = []
    impact_loss_J = []  # (t, J): kinetic energy removed by inelastic impacts and velocity resets
    nfev = 0
    n_segments = 0
    n_zero = 0
    next_sample = 0

    while t < duration_s:
        t_break = next(b for b in breaks if b > t)
        j = np.searchsorted(grid, t_break, side="right")
        t_eval = grid[next_sample:j]
        if t_eval.size == 0 or t_eval[-1] < t_break:
            t_eval = np.append(t_eval, t_break)
        named = events.by_mode[mode]
        seg_mode = mode
        # An input that jumps at t_break belongs to the next segment: this one sees its left limit,
        # so a jump cannot hide a crossing that happened before it.
        t_left = events.t_left = float(np.nextafter(t_break, -math.inf))
        max_step = opts.max_step_s if mode.is_slip else min(opts.max_step_s, held_max_step)
        sol = solve_ivp(lambda tt, yy: model.rhs(tt if tt < t_left else t_left, yy, seg_mode), (t, t_break), y,
                        method=opts.method, t_eval=t_eval, events=[f for _, f in named], rtol=opts.rtol,
                        atol=atol, max_step=max_step)
        nfev += sol.nfev
        n_segments += 1
        if sol.status == -1:
            raise SolverFailure(f"solve_ivp failed at t = {t:.6g} s in mode {mode.label}: {sol.message}")
        keep = np.isin(sol.t, grid[next_sample:j])
        if keep.any():
            ts.append(sol.t[keep])
            ys.append(sol.y[:, keep])
            modes.append(np.full(int(keep.sum()), int(mode)))
            next_sample += int(keep.sum())
        if sol.status == 1:
            k = next(i for i, te in enumerate(sol.t_events) if len(te))
            kind = named[k][0]
            t_event = float(sol.t_events[k][0])
            y = np.array(sol.y_events[k][0], dtype=float)
            n_zero = n_zero + 1 if t_event - t <= 1e-12 * max(1.0, t) else 0
            if n_zero > MAX_ZERO_LENGTH_EVENTS:
                raise SolverFailure(f"event switching made no progress at t = {t_event:.9g} s ({kind})")
            old = mode
            mode = _transition(model, kind, t_event, y, mode, opts, impact_loss_J, m)
            transitions.append(TransitionEvent(t_event, kind, old.label, mode.label, float(y[0])))
            if len(transitions) > opts.max_events:
                raise SolverFailure(f"more than {opts.max_events} events by t = {t_event:.6g} s "
                                    "(raise [solver] max_events if this is expected)")
            t = t_event
        else:
            t = t_break
            y = sol.y[:, -1].copy()
            if mode in _REST:
                mode = _rest_mode(model, t, y, mode, opts.stick_margin_N)

    t_out = np.concatenate(ts)
    Y = np.concatenate(ys, axis=1)
    mode_arr = np.concatenate(modes)
    return Result.from_trace(model, name, t_out, Y, mode_arr, transitions, impact_loss_J,
                             {"rhs_evaluations": int(nfev), "events": len(transitions), "segments": n_segments,
                              "method": opts.method, "rtol": opts.rtol},
                             time.perf_counter() - wall0)


def _transition(model: MuscleModel, kind: str, t: float, y: np.ndarray, mode: Mode, opts: SolverOptions,
                impact_loss_J: list, mass_kg: float) -> Mode:
    """Apply the jump at an event to ``y`` in place and return the new mode."""
    if kind.startswith("release"):
        return Mode.SLIP_UP if kind == "release_up" else Mode.SLIP_DOWN
    v = y[1]
    if kind == "velocity_zero":
        impact_loss_J.append((t, 0.5 * mass_kg * v * v))
        y[1] = 0.0
        return _rest_mode(model, t, y, Mode.STICK, opts.stick_margin_N)
    low = kind == "stop_low"
    y[0] = model.stops.x_low_m if low else model.stops.x_high_m
    rebound = model.stops.rebound_speed_m_s(v)
    impact_loss_J.append((t, 0.5 * mass_kg * (v * v - rebound * rebound)))
    if rebound > 0.0:
        y[1] = rebound if low else -rebound
        return Mode.SLIP_UP if low else Mode.SLIP_DOWN
    y[1] = 0.0
    return _rest_mode(model, t, y, Mode.STOP_LOW if low else Mode.STOP_HIGH, opts.stick_margin_N)


__all__ = ["SolverFailure", "SolverOptions", "simulate_model", "initial_mode"]
