"""A muscle alone driven by its length (``[motion]``), on the python backend (scipy's integrators), the native engine and
the muscle-only FMU: the one generated assembly (:mod:`pamsim.assemblies.muscle_only`) on each.

Its inputs are exactly linear between the knots of the motion and of the pressure's signals, so each backend
integrates from knot to knot; an element's reaching its slip displacement is an event inside a leg, located by
the integrator and followed by the element's jump onto its limit (the rig's treatment).  The muscle-only
assembly has no hybrid component, so there are no modes: the python loop below integrates its one set of
generated functions and applies the jump of whichever indicator crossed.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..assemblies.muscle_only import MOTION_INPUTS, muscle_only_assembly
from ..assemblies.one_muscle import RUN_FUNCTIONS, input_signals, source_parts
from ..errors import InputError, SolverFailure
from ..modeling.pygen import compiled_by_mode, outputs_by_mode
from ..simulator import _distinct_breaks, _event, _from_start, fired_together, n_samples, too_many_events
from ..stepping import LsodaRestarts, integrate_segment
from .motion import Motion, motion_of
from .result import LengthDrivenResult

BACKENDS = ("python", "native", "fmu-cs", "fmu-me")
"""The backends that run a muscle driven by its length."""

MAX_INTERNAL_STEPS = 1_000_000
"""Integrator steps the native engine may take per input segment before it gives up."""


@dataclass
class LengthDrive:
    """A scenario's muscle alone, driven along its ``[motion]``: the motion, the model, the assembly and the
    model's inputs by name (signals of time, in the flat model's order)."""

    scenario: object
    motion: Motion = field(init=False)

    def __post_init__(self):
        sc = self.scenario
        self.motion = motion_of(sc)
        self.model = sc.build_model()
        try:
            self.assembly = muscle_only_assembly(self.model, sc.parameters["L0_m"], sc.parameters["g_m_s2"],
                                                 sc.initial_pressure_gauge_Pa, sc.added_components)
        except ValueError as exc:
            raise InputError(f"{sc.origin}: component: {exc}") from None
        self.pressure_output = f"{source_parts(self.model.source, None).pressure}.p_gauge_Pa"
        source = {k: s for k, s in input_signals(self.model).items() if k != "external_force_N"}
        signals = {**source, "length_m": self.motion.length_signal(), "lengthening_velocity_m_s":
                   self.motion.velocity_signal()}
        names = list(self.assembly.inputs)
        if sorted(names) != sorted(signals) or names[-2:] != list(MOTION_INPUTS):
            raise ValueError(f"the muscle-only assembly's inputs {names} are not the signals' {list(signals)}")
        self.signals = [signals[n] for n in names]
        self.breakpoints = (*self.motion.breakpoints, *self.model.source.breakpoints)

    def inputs(self, t) -> list:
        """The model's inputs at ``t`` [s] (a float, or an array of times: one row each)."""
        return [s(t) for s in self.signals]

    def code(self) -> dict:
        """The generated python code of the assembly, ``{0: GeneratedModel}`` (no modes)."""
        return compiled_by_mode(self.assembly, None, RUN_FUNCTIONS)

    def result(self, backend: str, t: np.ndarray, Y: np.ndarray, events: list, stats: dict,
               wall_s: float) -> LengthDrivenResult:
        """The run's :class:`LengthDrivenResult`: every state sampled and every output computed from the states
        and inputs at the samples by the python backend's generated code."""
        code = self.code()
        outputs = outputs_by_mode(code, self.assembly.parameter_values(), list(Y), self.inputs(t),
                                  np.zeros(len(t), dtype=int))
        states = dict(zip(code[0].names["states"], Y))
        return LengthDrivenResult(self.scenario.name, backend, self.motion, t, {**states, **outputs},
                                  self.pressure_output, events, stats, wall_s)


def simulate_length_drive(scenario, backend: str = "python") -> LengthDrivenResult:
    """Run the muscle of ``scenario`` along its ``[motion]`` on ``backend`` (:data:`BACKENDS`).

    Raises
    ------
    InputError
        A bad ``[motion]`` table, a backend that does not run it, a model the backend cannot carry.
    SolverFailure
        The integrator failed, or the run had more than ``solver.max_events`` events.
    """
    if backend not in BACKENDS:
        raise InputError(f"{scenario.origin}: --backend {backend}: a muscle driven by its length runs on "
                         f"{', '.join(BACKENDS)}")
    drive = LengthDrive(scenario)
    run = {"python": _python, "native": _native, "fmu-cs": _fmu, "fmu-me": _fmu}[backend]
    return run(drive, backend)


def _segment(drive: LengthDrive, gen, p, t: float, y: np.ndarray, t_break: float, atol: np.ndarray, samples,
             restarts: LsodaRestarts):
    """The generated model integrated from ``t`` to ``t_break`` or its first indicator's crossing
    (:func:`pamsim.stepping.integrate_segment`, its LSODA kept in ``restarts``), read at ``samples`` on the
    way, its inputs at their left limit at ``t_break`` (a jump there belongs to the next segment)."""
    opts = drive.scenario.solver
    t_left = float(np.nextafter(t_break, -math.inf))

    def rhs(tt, yy):
        return np.array(gen.f(yy.tolist(), drive.inputs(min(tt, t_left)), p, ())[0])

    def indicator(k):
        return _event(lambda tt, yy: gen.z(yy.tolist(), drive.inputs(min(tt, t_left)), p, ())[0][k], -1.0)

    n = len(drive.assembly.indicator_names())
    try:
        # No step is looked into between its ends: the muscle's length is driven, and nothing turns inside one.
        seg = integrate_segment(rhs, t, t_break, y, opts.method, [_from_start(indicator(k), t, y) for k in range(n)],
                                samples, rtol=opts.rtol, atol=atol, max_step=opts.max_step_s, long_step_s=math.inf,
                                restarts=restarts)
    except Exception as exc:  # numerical trouble comes as plain exceptions: a solver failure (exit 3)
        raise SolverFailure(f"the integrator raised {type(exc).__name__} at t = {t:.6g} s: {exc}") from exc
    if seg.status == -1:
        raise SolverFailure(f"the integrator failed at t = {t:.6g} s: {seg.message}")
    return seg


def _python(drive: LengthDrive, backend: str) -> LengthDrivenResult:
    """Integrated from knot to knot, stopping at each indicator's crossing for its jump."""
    sc, opts = drive.scenario, drive.scenario.solver
    wall0 = time.perf_counter()
    gen, p = drive.code()[0], drive.assembly.parameter_values()
    names = [f"{c}.{n}" for c, n in drive.assembly.indicator_names()]
    atol = opts.rtol * np.array([v.nominal for v in drive.assembly.flatten().states])
    grid = np.linspace(0.0, sc.duration_s, n_samples(sc.duration_s, opts.sample_rate_Hz))
    t, y = 0.0, np.array(gen.x0(drive.inputs(0.0), p)[0], dtype=float)
    ys, events, nfev, njev, segments, next_sample = [], [], 0, 0, 0, 0
    restarts = LsodaRestarts()
    for t_break in _distinct_breaks(drive.breakpoints, sc.duration_s):
        while t < t_break:
            samples = grid[next_sample:np.searchsorted(grid, t_break, side="right")]
            seg = _segment(drive, gen, p, t, y, t_break, atol, samples, restarts)
            nfev, njev, segments = nfev + seg.nfev, njev + seg.njev, segments + 1
            if seg.samples_t.size:  # slips closer together than the samples leave pieces without one
                ys.append(seg.samples_y)
            next_sample += seg.samples_t.size
            if seg.status != 1:
                t, y = t_break, seg.y[:, -1].copy()
                continue
            k, t = seg.event, seg.t_event
            y_event, u = list(seg.y_event), drive.inputs(t)
            crossed = fired_together(gen.z(y_event, u, p, ())[0], k, range(len(names)))
            fired = [1.0 if i in crossed else 0.0 for i in range(len(names))]
            y = np.array(gen.transition(y_event, u, p, (), fired)[0])
            events.extend((t, names[i]) for i in crossed)
            if len(events) > opts.max_events:
                raise too_many_events(opts.max_events, f" by t = {t:.6g} s")
    stats = {"rhs_evaluations": int(nfev), "events": len(events), "segments": segments, "jacobians": int(njev),
             "method": opts.method, "rtol": opts.rtol}
    return drive.result(backend, grid, np.concatenate(ys, axis=1), events, stats, time.perf_counter() - wall0)


def _native(drive: LengthDrive, backend: str) -> LengthDrivenResult:
    """The generic C engine compiled with the assembly's generated C, its inputs cut into exact segments."""
    from ..native.backend import check_status, engine_stats, event_capacity, exact_segments, native_rtol, stiff_switch
    from ..native.engine import EngineCase, engine_library

    sc, opts = drive.scenario, drive.scenario.solver
    try:
        library = engine_library(drive.assembly)
    except NotImplementedError as exc:
        raise InputError(f"{sc.origin}: the native backend cannot run this muscle: {exc}") from None
    pieces = exact_segments(drive.signals, sc.duration_s)
    if pieces is None:
        raise InputError(f"{sc.origin}: a pressure input is a Python function, which the native backend cannot "
                         "carry; run it with the python backend")
    starts, u, du = pieces
    n = n_samples(sc.duration_s, opts.sample_rate_Hz)
    max_step = opts.max_step_s if math.isfinite(opts.max_step_s) else sc.duration_s
    case = EngineCase(np.array(drive.assembly.parameter_values()), native_rtol(opts), max_step, MAX_INTERNAL_STEPS,
                      sc.duration_s, n, starts, u, event_capacity(opts.max_events), du, stiff_switch(opts))
    wall0 = time.perf_counter()
    out = library.run([case])
    wall = time.perf_counter() - wall0
    check_status(out, 0, sc.origin, opts.max_events)
    ns = len(library.names["states"])
    Y = np.array(out["samples"][:ns * n].reshape(ns, n))
    names = [f"{c}.{k}" for c, k in drive.assembly.indicator_names()]
    # e[3] is the bit mask of the indicators that fired: one event each, as the python loop reports them
    events = [(float(e[0]), name) for e in out["events"][:int(out["n_events"][0])].tolist()
              for k, name in enumerate(names) if int(e[3]) >> k & 1]
    stats = engine_stats(out, 0, opts, len(events))
    return drive.result(backend, np.linspace(0.0, sc.duration_s, n), Y, events, stats, wall)


def _fmu(drive: LengthDrive, backend: str) -> LengthDrivenResult:
    """The muscle-only FMU following the scenario's signals and the motion itself (``input_source =
    scenario``), run by fmpy; the FMU does not report its events, so an element's slip is counted where its
    ``slipping`` output rises between two samples."""
    from ..fmu.assembly_runner import run_trace
    from ..fmu.build import build_spec, temp_fmu
    from ..fmu.muscle_only import muscle_only_spec

    sc = drive.scenario
    spec = muscle_only_spec(sc, motion=drive.motion)
    path = temp_fmu(spec.token, f"{spec.identifier}_fmi2.fmu", lambda out: build_spec(out, spec))
    interface = backend.split("-")[1]
    t, Y, _, wall = run_trace(path, interface, sc.duration_s, sc.solver, spec.states, None)
    result = drive.result(backend, t, Y, [], {}, wall)
    slipping = [k for k in result.signals if k.split(".")[-1].startswith("slipping")]
    events = [(float(t[j + 1]), name.replace("slipping", "slip")) for name in slipping
              for j in np.flatnonzero(np.diff(result.signals[name]) > 0.5)]
    result.events = sorted(events)
    result.stats = {"rhs_evaluations": None, "events": len(events), "segments": 0, "jacobians": 0, "method": backend,
                    "rtol": sc.solver.rtol}
    return result
