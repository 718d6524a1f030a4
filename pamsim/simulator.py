"""Hybrid stick/slip integration of a :class:`~pamsim.model.MuscleModel` with
scipy's integrators (``solve_ivp``'s methods, stepped by :mod:`pamsim.stepping`).

The load is in one of the :class:`~pamsim.model.Mode` s.  Each mode is a
smooth ODE; the integrator steps it until a terminal event (velocity
reaching zero, a stop reached, the friction margin exceeded) or a breakpoint
of the inputs, and the simulator then decides the next mode from the forces
(MODEL_NOTES sec. 4).  Two thresholds keep the switching free of chatter: a
held load is released only when the net force exceeds friction by
``release_margin_N``, and a stopping load is held when it exceeds it by no
more than ``stick_margin_N`` < ``release_margin_N``.  A segment that starts on
an event surface does not see its own start as an event (:func:`_from_start`);
a slip too small for the integrator to resolve ends in a short hold
(``_HOLD_S``).  Summary extremes are taken over every integrator step, the
samples from the dense output (docs/model.md sec. 4).
"""

from __future__ import annotations

import bisect
import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .assemblies import one_muscle_assembly
from .assemblies.one_muscle import RUN_FUNCTIONS, RigOutputs
from .components.hanging_load import EVENT_NAMES
from .errors import InputError, SolverFailure
from .model import STATE_SCALES, Mode, MuscleModel
from .modeling.pygen import compiled_by_mode
from .result import Result, TransitionEvent
from .stepping import DOPRI5, LsodaRestarts, integrate_segment


MIN_RTOL = 1e-13
"""The finest ``solver.rtol`` a scenario may give, and the finest the native backend integrates at."""
NATIVE_RTOL_FACTOR = 0.01
"""Default ``solver.native_rtol_factor``.  At the same ``rtol`` the native backend's Dormand-Prince 5(4)
is less accurate than the python backend's LSODA (measured by ``python benchmarks/accuracy.py``: on the
five paper figures and the 66 paper cases up to 11 times the error of LSODA against a converged run at
factor 1, up to 4 times at 0.1; at 0.01 below LSODA's error on every one, and on the free swing)."""


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
    ``native_rtol_factor``: the native backend integrates at ``rtol`` times this, so that its
    Dormand-Prince 5(4) meets the accuracy LSODA reaches at ``rtol`` (:data:`NATIVE_RTOL_FACTOR`);
    the python backend ignores it.
    """

    method: str = "LSODA"
    rtol: float = 1e-6
    sample_rate_Hz: float = 1000.0
    max_events: int = 20000
    max_step_s: float = math.inf
    held_max_step_s: float = math.inf
    stick_margin_N: float = 1e-7
    release_margin_N: float = 2e-7
    native_rtol_factor: float = NATIVE_RTOL_FACTOR


MIN_MAX_STEP_S = 1e-6
"""Smallest ``solver.max_step_s`` [s]: a thousandth of the shortest time scale of the model (the valve's
millisecond pressure transients); smaller steps only make a run hang."""


PROGRESS_EVERY = 2000
"""Right-hand-side evaluations between two progress reports inside a segment (a few milliseconds)."""

_REST = (Mode.STICK, Mode.STOP_LOW, Mode.STOP_HIGH)
_HOLD_S = 1e-9
"""First hold [s] of a load whose slip from rest ended as it began.

A load at zero velocity whose net force beats friction by a little, but is
falling fast (a controller venting), turns back within a time and speed below
the integrator's resolution: the slip segment ends with a velocity event at
its own start, and deciding the mode again from the same forces would repeat
it forever.  The load is then held for this time, doubled at each repetition,
and its mode decided again from the forces at the end of the hold.  The motion
lost is of the order of the integrator's velocity tolerance times the hold.
"""
_MAX_ZERO_LENGTH = 30
"""Zero-length segments in a row with no time between them before it is a solver failure; also the
longest hold's doubling (2**29 ns, about 0.5 s)."""


def simulate_python(scenario, progress: Callable[[float], None] | None = None,
                    model: MuscleModel | None = None) -> Result:
    """Backend ``python``: integrate a :class:`~pamsim.scenario.Scenario` with ``scipy.integrate.solve_ivp``.

    ``scenario`` is not annotated: :mod:`pamsim.scenario` imports this module, so this one cannot import it.
    ``model``: the scenario's model with its pressure source replaced (a controller's); None: its own.
    """
    return simulate_model(model or scenario.build_model(), scenario.duration_s, scenario.solver,
                          x0_m=scenario.initial_contraction_m, name=scenario.name,
                          p0_gauge_Pa=scenario.initial_pressure_gauge_Pa, progress=progress,
                          added=scenario.added_components)


def n_samples(duration_s: float, sample_rate_Hz: float) -> int:
    """Number of output samples: round(duration x rate) + 1, evenly spaced, at least the start and the end."""
    return max(2, int(round(duration_s * sample_rate_Hz)) + 1)


def _event(fun, direction: float):
    fun.terminal = True
    fun.direction = direction
    return fun


_ON_SURFACE = 1e-12
"""Magnitude [m, m/s or N] given to an event function that is exactly zero at its segment's start."""


def _from_start(fun, t0: float, y0: np.ndarray):
    """``fun`` with its value at the segment start ``t0`` taken from the exact start state ``y0``.

    A segment can start on an event surface (a load released from rest starts
    at v = 0, and the velocity event watches v).  The dense interpolant need
    not reproduce ``y0`` exactly at ``t0`` (LSODA gives v = -5e-23), so the
    root finder could see no sign change at a crossing that does happen later
    in the step.  The start value is therefore taken from ``y0``, and if it is
    zero, placed on the side the mode implies (before the crossing the event
    looks for): the segment's own start is never an event.
    """
    g0 = float(fun(t0, y0))
    if g0 == 0.0:
        g0 = -fun.direction * _ON_SURFACE

    def guarded(t, y):
        return g0 if t <= t0 else fun(t, y)

    return _event(guarded, fun.direction)


def fired_together(z, k_fired: int, candidates) -> list[int]:
    """``k_fired`` and every indicator of ``candidates`` at or below zero in ``z``, the indicators where
    ``solve_ivp`` reported ``k_fired``'s crossing: they crossed at the same instant (two elements of equal slip
    displacement, the two muscles' elements of a symmetric pair), and fire together, as in the native engine.
    ``solve_ivp`` reports one; one left behind would start the next segment below zero, where no crossing can
    be found."""
    return [k_fired] + [k for k in candidates if k != k_fired and z[k] <= 0.0]


_V_ROW = 1
"""Row of the load's velocity in the state vector (``MuscleModel.state_names`` begins ``x_m, v_m_s``): a step
in which it changes sign is checked inside for a crossing its ends do not show
(:func:`pamsim.stepping.missed_crossing`)."""


BREAK_RESOLUTION = 1e-12
"""Breakpoints closer than this fraction of their time (at least of 1 s) are one: a segment between them
would be shorter than the integrator can step (knots at 0.1 + 0.2 and 0.3 s, 5.6e-17 s apart, made
LSODA fail)."""


def _distinct_breaks(breakpoints, duration_s: float) -> list[float]:
    """The inputs' breakpoints inside the run, each once (see :data:`BREAK_RESOLUTION`), and its end."""
    out: list[float] = []
    for b in sorted({float(b) for b in breakpoints if 0.0 < b < duration_s}):
        if not out or b - out[-1] > BREAK_RESOLUTION * max(1.0, b):
            out.append(b)
    if out and duration_s - out[-1] <= BREAK_RESOLUTION * max(1.0, duration_s):
        out.pop()
    return out + [duration_s]


class GeneratedCode:
    """An assembly's generated code for one run, one set of functions per mode of its hybrid component
    (:func:`pamsim.modeling.pygen.compiled_by_mode`, shared by runs of the same structure), with the
    run's parameter values, its inputs in the flat model's input order (``inputs(t)``) and the
    absolute tolerance scale of each state (``nominal``)."""

    def __init__(self, assembly, hybrid: str, inputs: Callable, nominal):
        self.assembly = assembly
        self.code = compiled_by_mode(assembly, hybrid, RUN_FUNCTIONS)
        self.nominal = np.asarray(nominal, dtype=float)
        # The indicators are the components', in their order: the hybrid one's own start at an offset, and
        # the others (components whose state jumps at an event, without modes) watch in every mode.
        indicators = assembly.indicator_names()
        self.own_indicators = next((k for k, (c, _) in enumerate(indicators) if c == hybrid), 0)
        self.other_indicators = [(f"{c}.{n}", k) for k, (c, n) in enumerate(indicators) if c != hybrid]
        self.n_indicators = len(indicators)
        self.p = assembly.parameter_values()
        self.kinetic = self.code[Mode.STICK].names["outputs"].index(f"{hybrid}.kinetic_energy_J")
        self.t_left = math.inf  # inputs are read at min(t, t_left): the left limit at a segment's end
        self.inputs = inputs

    @classmethod
    def of_model(cls, model: MuscleModel, opts: SolverOptions, x0_m: float, p0_gauge_Pa: float | None,
                 added: tuple = ()) -> "GeneratedCode":
        """The one-muscle rig's code for ``model`` with the components ``added`` to it."""
        assembly = one_muscle_assembly(model, x0_m, p0_gauge_Pa, opts.stick_margin_N, opts.release_margin_N, added)
        # Absolute tolerances: the rig's states' typical scales (10 mm, 0.1 m/s, 1 bar, 10 mg of air, 0.1 J of
        # work and of a controller's states, as always), then each added component's declared nominals.
        added_nominal = [v.nominal for c in assembly.components[-len(added):] for v in c.states] if added else []
        source, external_N = model.source.inputs, model.load.external_N

        def inputs(t):
            return [*source(t), external_N(t)]

        gen = cls(assembly, "load", inputs, [STATE_SCALES.get(n, 0.1) for n in model.state_names] + added_nominal)
        local = [name.split(".", 1)[1] for name in gen.code[Mode.STICK].names["states"]]
        if local[:len(model.state_names)] != list(model.state_names):  # peaks and Result read them by position
            raise ValueError(f"the components' states {local} do not begin with the model's {list(model.state_names)}")
        return gen

    def start(self) -> tuple[np.ndarray, Mode]:
        """The state at rest at the start, and its mode decided from the forces."""
        u = self.inputs(0.0)
        x0, (where,) = self.code[Mode.STICK].x0(u, self.p)
        return np.array(x0), self.rest_mode(Mode(int(where)), 0.0, x0)

    def rest_mode(self, mode: Mode, t: float, y) -> Mode:
        """A held load's mode decided afresh from its forces (a sliding one keeps its mode)."""
        (q,) = self.code[mode].rest_mode(list(y), self.inputs(t), self.p, ())
        return Mode(int(q[0]))

    def rhs(self, mode: Mode):
        """The right-hand side ``f(t, y)`` of ``mode``, as ``solve_ivp`` calls it."""
        f, inputs, p = self.code[mode].f, self.inputs, self.p

        def rhs(t, y):
            return np.array(f(y.tolist(), inputs(min(t, self.t_left)), p, ())[0])
        return rhs

    def events(self, mode: Mode) -> list[tuple[str, Callable, int]]:
        """The mode's event functions: its indicators that can cross there, each positive inside it,
        with the event's name and the indicator's index."""
        code = self.code[mode]
        z, inputs, p = code.z, self.inputs, self.p
        no_inputs = None if code.reads_inputs["z"] else [0.0] * len(code.names["inputs"])
        out = []
        own = [(name, self.own_indicators + k) for k, name in enumerate(EVENT_NAMES[mode]) if name is not None]
        # solve_ivp asks each event function in turn at the same point, and z gives every indicator at once:
        # one evaluation serves them all (with ten Maxwell-slip elements, z was 12 times the run's cost).
        last = [None, None]

        def indicators(t, y):
            key = (t, y.tobytes())
            if last[0] != key:
                last[0], last[1] = key, z(y.tolist(), no_inputs or inputs(min(t, self.t_left)), p, ())[0]
            return last[1]
        for name, k in own + self.other_indicators:

            def indicator(t, y, k=k):
                return indicators(t, y)[k]
            out.append((name, _event(indicator, -1.0), k))
        return out

    def also_fired(self, mode: Mode, k_fired: int, t: float, y: np.ndarray) -> list[tuple[str, int]]:
        """The other components' indicators that fire with ``k_fired`` at ``t`` (:func:`fired_together`)."""
        if not self.other_indicators:
            return []
        z = self.code[mode].z(list(y), self.inputs(t), self.p, ())[0]
        names = dict((k, name) for name, k in self.other_indicators)
        return [(names[k], k) for k in fired_together(z, k_fired, names)[1:]]

    def jump(self, mode: Mode, k_fired: int, t: float, y: np.ndarray,
             also: tuple[int, ...] = ()) -> tuple[np.ndarray, Mode, float]:
        """The state and mode after indicator ``k_fired`` (and the indicators ``also``) crossed at ``t``, and the
        kinetic energy the jump removed [J] (an inelastic impact, a velocity reset)."""
        code, u = self.code[mode], self.inputs(t)
        fired = [1.0 if k == k_fired or k in also else 0.0 for k in range(self.n_indicators)]
        x_next, (q_next,) = code.transition(list(y), u, self.p, (), fired)
        q = Mode(int(q_next))
        mode_next = self.rest_mode(q, t, x_next)
        lost = code.y(list(y), u, self.p, ())[0][self.kinetic] - self.code[q].y(x_next, u, self.p, ())[0][self.kinetic]
        return np.array(x_next), mode_next, lost


def simulate_model(model: MuscleModel, duration_s: float, options: SolverOptions | None = None,
                   x0_m: float = 0.0, name: str = "", p0_gauge_Pa: float | None = None,
                   progress: Callable[[float], None] | None = None, added: tuple = ()) -> Result:
    """Integrate ``model`` from rest at ``x0_m`` (chamber at ``p0_gauge_Pa``, if given) over ``[0, duration_s]``,
    with the components ``added`` to the rig (:class:`pamsim.assemblies.one_muscle.AddedComponent`).

    ``progress``, if given, is called with the simulated time [s] reached, at
    every segment and every ``PROGRESS_EVERY`` right-hand-side evaluations
    within one (a long run with a small ``max_step_s`` can stay in one segment).

    Raises :class:`SolverFailure` when ``solve_ivp`` fails, the event count
    exceeds ``options.max_events``, or the switching stops making progress.
    """
    wall0 = time.perf_counter()
    run = _Run(model, duration_s, options or SolverOptions(), x0_m, p0_gauge_Pa, progress, added)
    run.integrate(duration_s)
    if progress is not None:
        progress(duration_s)
    return run.result(name, time.perf_counter() - wall0)


class SteppedRun:
    """A run of ``model`` advanced by its caller, one piece at a time, as a controller drives it.

    Between two calls of :meth:`advance` the caller may change what the model's input signals return
    (a held value it owns, such as an agent's last action).  ``advance(t_k1)`` after ``advance(t_k)``
    takes the steps, events and modes that :func:`simulate_model` takes between the breakpoints ``t_k``
    and ``t_k1`` of a signal that holds the same values (:class:`pamsim.signals.PiecewiseConstant`): a
    held load's mode is decided again at ``t_k`` with the new inputs, as at a breakpoint.  The run
    starts at the first :meth:`advance`, from the state and mode its inputs decide; before that,
    :attr:`y` and :attr:`mode` are the start that the inputs at construction decide.

    Parameters
    ----------
    model : MuscleModel
        The model, with its input signals.
    options : SolverOptions, optional
        Integrator settings (``sample_rate_Hz`` is not used: the caller reads the state).
    x0_m : float
        Contraction at the start [m].
    p0_gauge_Pa : float, optional
        Chamber pressure at the start [Pa gauge] (None: ambient).
    added : tuple
        Components added to the rig (:class:`pamsim.assemblies.one_muscle.AddedComponent`).
    """

    def __init__(self, model: MuscleModel, options: SolverOptions | None = None, x0_m: float = 0.0,
                 p0_gauge_Pa: float | None = None, added: tuple = ()):
        self._attach(_Run(model, 0.0, options or SolverOptions(), x0_m, p0_gauge_Pa, None, added))

    @classmethod
    def of(cls, run: HybridRun) -> "SteppedRun":
        """A stepped run of any assembly's :class:`HybridRun` (muscles on a joint, say), its inputs those
        its :class:`GeneratedCode` reads."""
        self = cls.__new__(cls)
        self._attach(run)
        return self

    def _attach(self, run: HybridRun) -> None:
        self._run = run
        self._started = False
        self.assembly = run.gen.assembly
        """The assembly the run integrates (the rig and the components added to it)."""
        self.state_names = tuple(run.gen.code[Mode.STICK].names["states"])
        """The states' names, in the order of :attr:`y` (the flat model's)."""
        self.output_names = tuple(run.gen.code[Mode.STICK].names["outputs"])
        """The outputs' names, in the order :meth:`outputs` returns them."""

    @property
    def t_s(self) -> float:
        """The time reached [s]."""
        return self._run.t

    @property
    def y(self) -> np.ndarray:
        """Every state at :attr:`t_s`, in the order of :attr:`state_names`."""
        return self._run.y

    @property
    def mode(self) -> Mode:
        """The load's mode at :attr:`t_s`."""
        return self._run.mode

    @property
    def events(self) -> list[TransitionEvent]:
        """The mode changes so far."""
        return self._run.transitions

    @property
    def stats(self) -> dict:
        """Right-hand-side evaluations and events so far (as a :class:`Result`'s ``stats`` counts them)."""
        return {"rhs_evaluations": int(self._run.nfev), "events": len(self._run.transitions)}

    def outputs(self) -> list[float]:
        """Every output at :attr:`t_s` in the current mode, in the order of :attr:`output_names`."""
        gen = self._run.gen
        return gen.code[self._run.mode].y(list(self._run.y), gen.inputs(self._run.t), gen.p, ())[0]

    def advance(self, t_end_s: float) -> None:
        """Integrate to ``t_end_s`` [s] with the inputs the model's signals give now.

        Raises
        ------
        SolverFailure
            As :func:`simulate_model` does.
        """
        run = self._run
        if not self._started:
            run.y, run.mode = run.gen.start()
            self._started = True
        elif run.mode in _REST:
            run.mode = run.gen.rest_mode(run.mode, run.t, run.y)
        while run.t < t_end_s:
            t_break = min(t_end_s, run.hold_until)
            seg, named = run.segment(t_break, sampled=False)
            if seg.status == 1:
                run.at_event(seg, named)
            elif t_break < t_end_s:
                run.at_breakpoint(seg, t_break)
            else:  # the mode is decided at the next advance, with the inputs it brings
                run.t, run.hold_until, run.y = t_break, math.inf, seg.y[:, -1].copy()


class HybridRun:
    """One run of an assembly's generated code (:class:`GeneratedCode`) with ``solve_ivp``, mode by mode of
    its hybrid component: where it is, what it has sampled and seen so far.  Its first state is the
    hybrid component's position (the extremes taken over every step are of it).  ``breakpoints``: times
    [s] where an input jumps; ``max_input_step_s``: the longest step over which every input is monotonic.
    A subclass turns the run into its result."""

    def __init__(self, gen: GeneratedCode, duration_s: float, opts: SolverOptions, breakpoints,
                 max_input_step_s: float, progress: Callable[[float], None] | None):
        self.opts, self.progress = opts, progress
        self.grid = np.linspace(0.0, duration_s, n_samples(duration_s, opts.sample_rate_Hz))
        self.breaks = _distinct_breaks(breakpoints, duration_s)
        self.gen = gen
        self.atol = opts.rtol * self.gen.nominal
        self.held_max_step = min(opts.held_max_step_s, max_input_step_s)
        self.t = 0.0
        self.y, self.mode = self.gen.start()
        self.ts, self.ys, self.modes = [], [], []
        self.transitions: list[TransitionEvent] = []
        self.impact_loss_J = []  # (t, J): kinetic energy removed by inelastic impacts and velocity resets
        self.nfev = self.njev = self.n_segments = self.n_zero = self.n_stuck = self.next_sample = 0
        self.hold_until = math.inf  # end of a short hold after a slip too small to resolve (see _HOLD_S)
        # Over every integrator step and event, not the samples.
        self.low_x, self.peak_x = math.inf, -math.inf
        self.calls = 0
        # The step DOPRI5 proposed at the last segment's end (scipy's methods: the last step taken), to start
        # the next segment with: DOPRI5's, and a stiff restart's that follows another (see below).
        self.h_next = None
        # LSODA restarts with its non-stiff method.  After a jump that kept a held body's mode (an element
        # reaching its limit) the next segment is BDF's: what moves while the body is held is a massless
        # muscle end, a stiff node, where an element at rest on its limit, restarted non-stiff, crossed it
        # again at every few steps of noise (more than 20000 events in a second).  Where the last segment was
        # such a restart too, BDF starts with its last step (cut at its event), as the native engine's Rodas4
        # carries on: estimated afresh, its first steps were fractions of a microsecond whose noise crossed
        # the limit again at once (elements on both muscles of an elastic pair: more than 5000 events by
        # 0.82 s).  Not floored at 1 us as the native engine's is: floored, that pair took 517 events, not 220.
        self.stiff_restart = False
        self.stiff_before = False  # whether the last segment was such a stiff restart
        self.restarts = LsodaRestarts()
        self.reached = 0.0  # reported time: the RHS is also evaluated at trial points, which need not increase

    def report(self, t: float) -> None:
        """Tell the progress callback, if any, the simulated time reached (never less than before)."""
        if self.progress is not None:
            self.reached = max(self.reached, t)
            self.progress(self.reached)

    def _reporting(self, fun):
        def rhs(tt, yy):
            self.calls += 1
            if self.calls % PROGRESS_EVERY == 0:
                self.report(tt)
            return fun(tt, yy)
        return rhs

    def segment(self, t_break: float, sampled: bool = True):
        """Integrate the current mode from ``t`` to ``t_break`` or its first event, and read the output grid's
        samples on the way (none if not ``sampled``: a stepped run's caller reads the state)."""
        opts, mode, t, y = self.opts, self.mode, self.t, self.y
        named = self.gen.events(mode)
        if math.isfinite(self.hold_until):
            # A hold is the time the load is held whatever its forces do (see _HOLD_S): a release inside
            # it would start the same slip that just ended at its own start, and reset the hold's doubling.
            named = [e for e in named if not e[0].startswith("release")]
        # An input that jumps at t_break belongs to the next segment: this one sees its left limit,
        # so a jump cannot hide a crossing that happened before it.
        self.t_left = self.gen.t_left = float(np.nextafter(t_break, -math.inf))
        max_step = opts.max_step_s if mode.is_slip else min(opts.max_step_s, self.held_max_step)
        rhs = self.gen.rhs(mode) if self.progress is None else self._reporting(self.gen.rhs(mode))
        stiff = self.stiff_restart and opts.method == "LSODA"
        method = "BDF" if stiff else opts.method
        first_step = self.h_next if method == DOPRI5 or (stiff and self.stiff_before) else None
        self.stiff_before = stiff
        samples = self.grid[self.next_sample:np.searchsorted(self.grid, t_break, side="right") if sampled else 0]
        try:
            seg = integrate_segment(rhs, t, t_break, y, method, [_from_start(f, t, y) for _, f, _ in named],
                                    samples, rtol=opts.rtol, atol=self.atol, max_step=max_step, v_row=_V_ROW,
                                    first_step=first_step, restarts=self.restarts)
        except (InputError, SolverFailure):
            raise
        except Exception as exc:
            # The integrator and the root finder signal numerical trouble with plain exceptions (ValueError
            # from brentq, ZeroDivisionError, LinAlgError...); to the caller it is a solver failure (exit 3).
            raise SolverFailure(f"the integrator raised {type(exc).__name__} at t = {t:.6g} s in mode "
                                f"{mode.label}: {exc}") from exc
        self.nfev += seg.nfev
        self.njev += seg.njev
        self.n_segments += 1
        self.h_next = seg.h_next
        if seg.status == -1:
            raise SolverFailure(f"the integrator failed at t = {t:.6g} s in mode {mode.label}: {seg.message}")
        return seg, named

    def record(self, seg) -> None:
        """The segment's output samples and extremes (over its steps)."""
        if seg.samples_t.size:
            self.ts.append(seg.samples_t)
            self.ys.append(seg.samples_y)
            self.modes.append(np.full(seg.samples_t.size, int(self.mode)))
            self.next_sample += seg.samples_t.size
        # x is monotonic within a segment (the velocity keeps its sign between events), so its peak
        # is at a step; the pressure's peak is taken over the steps as well.
        self.low_x, self.peak_x = min(self.low_x, float(seg.y[0].min())), max(self.peak_x, float(seg.y[0].max()))

    def at_event(self, seg, named) -> None:
        """The jump at the segment's event, and the short hold of a slip too small to resolve."""
        kind, _, indicator = named[seg.event]
        t_event, y = seg.t_event, seg.y_event
        zero_length = t_event - self.t <= 1e-12 * max(1.0, self.t)
        # n_zero: zero-length slips since the load last moved (the holds' doubling); n_stuck: zero-length
        # events with no time passed between them (a hold that ran is progress).
        self.n_zero = self.n_zero + 1 if zero_length else 0
        self.n_stuck = self.n_stuck + 1 if zero_length else 0
        if self.n_stuck > _MAX_ZERO_LENGTH:
            raise SolverFailure(f"event switching made no progress at t = {t_event:.9g} s ({kind})")
        old = self.mode
        also = self.gen.also_fired(old, indicator, t_event, y)
        self.y, self.mode, lost_J = self.gen.jump(old, indicator, t_event, y, tuple(k for _, k in also))
        if not np.array_equal(self.y, y):
            self.impact_loss_J.append((t_event, lost_J))
        self.hold_until = math.inf
        if kind == "velocity_zero" and zero_length and self.mode.is_slip:
            self.mode = Mode.STICK
            self.hold_until = t_event + _HOLD_S * 2.0 ** (min(self.n_zero, _MAX_ZERO_LENGTH) - 1)
        self.stiff_restart = self.mode == old and not old.is_slip
        self.transitions.append(TransitionEvent(t_event, kind, old.label, self.mode.label, float(self.y[0])))
        self.transitions.extend(TransitionEvent(t_event, name, self.mode.label, self.mode.label, float(self.y[0]))
                                for name, _ in also)
        if len(self.transitions) > self.opts.max_events:
            raise too_many_events(self.opts.max_events, f" by t = {t_event:.6g} s{_in_place(self.transitions)}")
        self.t = t_event

    def at_breakpoint(self, seg, t_break: float) -> None:
        """The segment reached an input breakpoint: a held load's mode is decided again there."""
        self.t = t_break
        self.hold_until = math.inf
        self.stiff_restart = False
        self.n_stuck = 0
        self.y = seg.y[:, -1].copy()
        if self.mode in _REST:
            self.mode = self.gen.rest_mode(self.mode, self.t, self.y)

    def integrate(self, duration_s: float) -> None:
        """Integrate from where the run is to ``duration_s``, segment by segment, sampling each."""
        while self.t < duration_s:
            self.report(self.t)
            t_break = min(self.breaks[bisect.bisect_right(self.breaks, self.t)], self.hold_until)
            seg, named = self.segment(t_break)
            self.record(seg)
            if seg.status == 1:
                self.at_event(seg, named)
            else:
                self.at_breakpoint(seg, t_break)

    def trace(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The samples' times [s], states (one row per state) and modes."""
        return np.concatenate(self.ts), np.concatenate(self.ys, axis=1), np.concatenate(self.modes)

    def stats(self) -> dict:
        """Right-hand-side evaluations, events, segments, Jacobians, the method and its tolerance."""
        return {"rhs_evaluations": int(self.nfev), "events": len(self.transitions), "segments": self.n_segments,
                "jacobians": int(self.njev), "method": self.opts.method, "rtol": self.opts.rtol}


class _Run(HybridRun):
    """One run of :func:`simulate_model`: the one-muscle rig's, with the pressure's peak over every step."""

    def __init__(self, model: MuscleModel, duration_s: float, opts: SolverOptions, x0_m: float,
                 p0_gauge_Pa: float | None, progress: Callable[[float], None] | None, added: tuple = ()):
        self.model = model
        super().__init__(GeneratedCode.of_model(model, opts, x0_m, p0_gauge_Pa, added), duration_s, opts,
                         model.breakpoints, model.max_input_step_s, progress)
        self.peak_p = -math.inf

    def record(self, seg) -> None:
        """The segment's samples and extremes, the pressure's over its steps among them."""
        super().record(seg)
        self.peak_p = max(self.peak_p, float(np.max(self.model.pressure_trace_Pa(np.minimum(seg.t, self.t_left),
                                                                                  seg.y))))

    def result(self, name: str, wall_time_s: float) -> Result:
        t, Y, modes = self.trace()
        return Result.from_trace(self.model, name, t, Y, modes, self.transitions, self.impact_loss_J, self.stats(),
                                 wall_time_s, peaks={"x_m": self.peak_x, "p_gauge_Pa": self.peak_p,
                                                     "x_min_m": self.low_x},
                                 outputs=RigOutputs(self.gen.assembly, self.model, t, Y, modes))


def _in_place(transitions: list) -> str:
    """What the last hundred events were, where each left the mode as it was (an element reaching its limit
    again and again): "" otherwise."""
    last = transitions[-100:]
    if not last or any(e.from_mode != e.to_mode for e in last):
        return ""
    return (f"; the last {len(last)} are {', '.join(sorted({e.kind for e in last}))} in mode {last[-1].to_mode}: "
            "an element resting on its limit at a stiff node (a massless muscle end on an elastic tendon), which "
            "this integrator's restarts switch again and again; the native backend integrates it as stiff across "
            "those switches (docs/joints.md)")


def too_many_events(max_events: int, when: str = "") -> SolverFailure:
    """The failure of a run with more than ``max_events`` events (``when``: e.g. " by t = 1.2 s")."""
    noun = "event" if max_events == 1 else "events"
    return SolverFailure(f"more than {max_events} {noun}{when} (raise [solver] max_events if this is expected)")


__all__ = ["SolverFailure", "SolverOptions", "SteppedRun", "simulate_model", "n_samples"]
