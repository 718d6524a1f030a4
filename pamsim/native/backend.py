"""The native backend: scenarios run in C (``pamsim.simulate(scenario, backend="native")``).

Every case's inputs are built here (parameters, element choices, and the
input signals as segments over which they are held); the generic engine compiled
with the case's assembly's generated C (:mod:`pamsim.native.engine`) then runs a
whole batch in one call, and the traces become the same :class:`Result` as the
Python backend's: columns, modes, events, work integrals and summary.

Differences from the Python backend, all documented in ``docs/scaling.md``:

- the integrator is the core's Dormand-Prince 5(4) at the scenario's ``rtol`` times
  ``solver.native_rtol_factor`` (:func:`native_rtol`; 0.01 unless the scenario says otherwise, so that
  it meets LSODA's accuracy at ``rtol``); with ``solver.method = "LSODA"``, the automatic choice, it
  switches to the stiff Rodas4 where a held model's steps are bound by stability (:func:`stiff_switch`),
  with ``RK45`` or ``DOPRI5`` it does not; the implicit methods are refused;
- a static force that has no form in symbols or in CasADi (a model a user writes for
  floats alone) runs as the FMU's spline table of it (:func:`force_table`), not the
  model itself; every other static force runs as the python backend runs it;
- the work integrals are Gauss-Legendre quadratures of each step's dense output
  (the Python backend integrates them as states);
- every input signal the FMU can carry (constant, step, steps, ramp, lag, trace) is exact: the
  run is cut at its knots and lag
  starts, and inside each piece the integrator evaluates it in closed form
  (:func:`exact_segments`); a signal of another kind (a Python function) is held at its midpoint
  value over intervals of at most :func:`hold_interval_s`, a second-order approximation.
"""

from __future__ import annotations

import bisect
import functools
import math
import threading
import time
import weakref
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Any, Sequence

import numpy as np

from ..assemblies import scenario_assembly
from ..assemblies.one_muscle import RigOutputs, input_signals
from ..components.hanging_load import event_name
from ..core_table import C_CHOICES
from ..elements.force_clip import with_negative_force
from ..elements.pressure_source import PrescribedPressure, ValveChamberSource
from ..errors import InputError, SolverFailure
from ..fmu.force_table import ForceTable
from ..fmu.preset import input_signal
from ..fmu.runner import REPRESENTED, tabulate_model, upper_stop_start
from ..gc_control import paused_gc
from ..model import Mode, MuscleModel
from ..result import Result, TransitionEvent
from ..scenario import Scenario
from ..signals import Constant, FirstOrderLag, PiecewiseConstant, Step
from ..simulator import MIN_RTOL, too_many_events
from . import library as lib
from .engine import EngineCase, engine_library

METHODS = ("LSODA", "RK45", "DOPRI5")
"""``solver.method`` values the native backend honours: its Dormand-Prince 5(4) is RK45's and DOPRI5's
method; LSODA, the automatic choice, is Dormand-Prince switching to the stiff Rodas4 where a held model's
steps are bound by stability (:func:`stiff_switch`).  Others are refused."""


def stiff_switch(opts) -> bool:
    """Whether the engine steps a held model whose Dormand-Prince steps are bound by stability with Rodas4:
    for ``solver.method = "LSODA"`` (the default, the automatic choice), not for ``RK45`` or ``DOPRI5``."""
    return opts.method == "LSODA"


BATCH_EVENT_CAPACITY = 1024
"""Events kept per case in a batch; a case with more is run again alone, with room for ``max_events``."""


def native_rtol(opts) -> float:
    """The relative tolerance the native backend integrates at: the scenario's ``solver.rtol`` times
    ``solver.native_rtol_factor`` (:data:`pamsim.simulator.NATIVE_RTOL_FACTOR`), and no finer than the
    finest ``solver.rtol`` a scenario may ask for (:data:`pamsim.simulator.MIN_RTOL`)."""
    return max(opts.rtol * opts.native_rtol_factor, MIN_RTOL)


def event_capacity(max_events):
    """Events kept per case in a batch call (``max_events``: one case's limit, or an array of them)."""
    if isinstance(max_events, int):  # one case: numpy would cost more than the run's Python around it
        return min(max_events + 1, BATCH_EVENT_CAPACITY)
    return np.minimum(np.asarray(max_events) + 1, BATCH_EVENT_CAPACITY)


def outgrew_batch(status: int, max_events: int) -> bool:
    """Whether a case stopped on the batch's event room (status 3) below its own ``max_events``,
    and so is to be run again alone with room for ``max_events + 1`` events."""
    return status == 3 and max_events + 1 > BATCH_EVENT_CAPACITY


HOLD_STEPS_PER_TAU = 10
"""A first-order lag is held over at most tau / 10 (and never longer than one output sample)."""
METHOD_LABEL = "native DOPRI5(4)"
"""``Result.stats["method"]`` of a native run that keeps Dormand-Prince alone (:func:`method_label`)."""


def method_label(opts) -> str:
    """``Result.stats["method"]`` of a native run with solver options ``opts``: :data:`METHOD_LABEL`, and the
    stiff method it may switch to (:func:`stiff_switch`)."""
    return METHOD_LABEL + ", Rodas4 where stiff" if stiff_switch(opts) else METHOD_LABEL


def engine_stats(out: dict, i: int, opts, n_events: int) -> dict:
    """``Result.stats`` of case ``i`` of an engine batch's output ``out`` run with solver options ``opts``,
    with ``n_events`` events, in the python backend's order of keys."""
    counts = out["stats"][i]
    return {"rhs_evaluations": int(counts[0]), "events": n_events, "segments": int(counts[2]),
            "jacobians": int(counts[3]), "method": method_label(opts), "rtol": native_rtol(opts)}


_EXACT = (Constant, Step, PiecewiseConstant)  # constant between breakpoints: held exactly
_DEFAULT_MAX_STEP_S = float(lib.REAL_DEFAULTS[lib.REAL_INDEX["cs_max_step_s"]])


@dataclass(frozen=True)
class CaseInputs:
    """One case as the library takes it: variable values, grid, input segments, event room."""

    reals: np.ndarray
    ints: np.ndarray
    duration_s: float
    n_samples: int
    segment_t_s: np.ndarray
    segment_u: np.ndarray
    max_events: int
    model: MuscleModel
    assembly: object
    segment_du: np.ndarray | None = None  # exact inputs (EngineCase.segment_du), in segment_u's columns
    input_names: tuple[str, ...] = lib.INPUTS  # segment_u's columns
    stiff_switch: bool = True  # EngineCase.stiff_switch

    def engine_case(self, library, capacity: int) -> EngineCase:
        """This case as the generic engine takes it: the flat model's parameters and inputs (kept for the
        case's next run on ``library``: a case is kept for its scenario, :func:`case_inputs`)."""
        kept = self.__dict__.setdefault("_engine_cases", {})  # frozen: the cache is no field
        key = (id(library), int(capacity))
        if key not in kept or kept[key][0] is not library:
            case = self._engine_case(library, capacity)
            for array in (case.params, case.segment_u, case.segment_du):
                if array is not None:
                    array.flags.writeable = False  # shared by the runs of the case: a caller copies to change
            kept[key] = (library, case)
        return kept[key][1]

    def _engine_case(self, library, capacity: int) -> EngineCase:
        columns = _columns(self.input_names, tuple(library.names["inputs"]))
        # take: the same copy as indexing with a list, at a third of its cost on arrays this small
        u = self.segment_u.take(columns, axis=1)
        du = None if self.segment_du is None else self.segment_du.take(columns, axis=1)
        return EngineCase(np.array(self.assembly.parameter_values()), float(self.reals[lib.REAL_INDEX["cs_relative_tolerance"]]),
                          float(self.reals[lib.REAL_INDEX["cs_max_step_s"]]),
                          int(self.ints[lib.INT_INDEX["cs_max_internal_steps"]]), self.duration_s, self.n_samples,
                          self.segment_t_s, u, int(capacity), du, self.stiff_switch)


@functools.lru_cache(maxsize=64)
def _columns(names: tuple[str, ...], wanted: tuple[str, ...]) -> tuple[int, ...]:
    """The column of each of ``wanted`` in ``names`` (a case's inputs as the library takes them), kept: a
    library's inputs and a case's columns are a few orders."""
    return tuple(names.index(n) for n in wanted)


def engine_parts(scenario: Scenario, model: MuscleModel | None = None) -> tuple[MuscleModel, object]:
    """``model`` (``scenario.build_model()`` if None) as the engine runs it, and its assembly: the model as it
    is where every element has generated C, else with a static force that has none (a model written for
    floats alone) replaced by its spline table (:func:`force_table`), clipped at zero as the dynamics apply it.

    Raises
    ------
    InputError
        For an element other than the static force that has no generated C (a law written for floats alone).
    """
    model = scenario.build_model() if model is None else model
    assembly = scenario_assembly(scenario, model)
    if not in_c(assembly, "muscle"):
        model = replace(model, static_force=with_negative_force(force_table(scenario), "clip"))
        assembly = scenario_assembly(scenario, model)
    lacking = [c.name for c in assembly.components if not in_c(assembly, c.name)]
    if lacking:
        raise InputError(f"{scenario.origin}: component {lacking[0]!r} is written for floats alone and has no C; "
                         "run it with the python backend")
    return model, assembly


def engine_assembly(scenario: Scenario, model: MuscleModel | None = None):
    """The assembly the engine runs for ``scenario`` (:func:`engine_parts`)."""
    return engine_parts(scenario, model)[1]


def needs_table(scenario: Scenario) -> bool:
    """Whether ``scenario``'s static force runs natively as its spline table (it has no generated C)."""
    return not in_c(scenario_assembly(scenario, scenario.build_model()), "muscle")


def in_c(assembly, name: str) -> bool:
    """Whether component ``name`` of ``assembly`` has generated C (written in symbols, or with a CasADi form)."""
    c = assembly.by_name[name]
    return c.has_c_form() if hasattr(c, "has_c_form") else getattr(c, "traces", True)


def refuse_unsupported(scenario: Scenario) -> None:
    """Raise :class:`InputError` naming the first setting of ``scenario`` the native backend cannot honour."""
    spec = scenario.spec
    where = scenario.origin
    for section, keys in REPRESENTED.items():
        table = spec if not section else spec.get(section, {})
        extra = table.keys() - keys  # most tables have none: sorted only when there are
        for key in sorted(extra) if extra else ():
            if not section and key in ("component", "hysteresis"):
                continue  # the generated model holds them
            name = f"{section}.{key}" if section else key
            raise InputError(f"{where}: {name}: the native backend cannot honour this key; "
                             "run it with the python backend")
    if spec["model"]["static_force_negative"] != "clip":
        raise InputError(f"{where}: model.static_force_negative = {spec['model']['static_force_negative']!r}: "
                         "the native backend clips a negative static force at zero; run it with the python backend")
    method = spec.get("solver", {}).get("method", "LSODA")
    if method not in METHODS:
        raise InputError(f"{where}: solver.method = {method!r}: the native backend integrates with Dormand-Prince "
                         f"5(4) and honours only {', '.join(METHODS)}; run it with the python backend")


TABLE_CACHE_SIZE = 32
"""Force tables kept per process: a sweep's cases share their muscle's table."""
_tables: "OrderedDict[tuple, ForceTable]" = OrderedDict()


def force_table(scenario: Scenario) -> ForceTable:
    """The static force table of ``scenario`` (:func:`pamsim.fmu.runner.tabulate_model`) over its stops and
    rating, where the python backend evaluates the model, for a static model without generated C
    (:func:`engine_parts`).  Tables are cached by the model,
    its variant, the parameters and the force-map file, so the cases of a sweep tabulate once."""
    m = scenario.spec["model"]
    key = (m["static_force"], m.get("static_force_variant"), tuple(sorted(scenario.parameters.items())),
           scenario.muscle.force_map_file if scenario.muscle is not None else None)
    if key in _tables:
        _tables.move_to_end(key)  # least recently used goes first
    else:
        _tables[key] = tabulate_model(scenario, narrow=False)
        if len(_tables) > TABLE_CACHE_SIZE:
            _tables.popitem(last=False)
    return _tables[key]


def _signals(model: MuscleModel) -> tuple[tuple[str, ...], tuple]:
    """The inputs' names and signals: the C core's inputs (:data:`library.INPUTS`, None where a source has
    no such input) for the sources the core has, else the flat model's (a source only the generic engine
    runs, such as a controller's)."""
    src = model.source
    if type(src) is ValveChamberSource:  # not a subclass with inputs of its own (an averaged PWM valve's)
        return lib.INPUTS, (src.command, src.supply_gauge_Pa, None, None, model.load.external_force_N)
    if isinstance(src, PrescribedPressure):
        return lib.INPUTS, (None, None, src.p_gauge_Pa, None, model.load.external_force_N)
    named = input_signals(model)
    return tuple(named), tuple(named.values())


def hold_interval_s(signals, sample_interval_s: float) -> float:
    """Longest interval a signal is held over: inf if every signal is constant or a step, else one output
    sample, shortened to tau / :data:`HOLD_STEPS_PER_TAU` for a first-order lag."""
    hold = math.inf
    for sig in signals:
        if sig is None or isinstance(sig, _EXACT):
            continue
        hold = min(hold, sample_interval_s)
        if isinstance(sig, FirstOrderLag):
            hold = min(hold, sig.tau_s / HOLD_STEPS_PER_TAU)
    return hold


def exact_segments(signals, duration_s: float):
    """The signals (None where an input has none) cut at every knot and lag start before
    ``duration_s``: ``(starts, u, du)`` with each signal's value at each piece's start and its change
    over the piece (:class:`pamsim.native.engine.EngineCase`), exactly; None if a signal is of a kind
    the FMU cannot carry (a Python callable), which is then held piecewise instead."""
    pieces = []
    for sig in signals:
        try:
            pieces.append(None if sig is None else input_signal(sig, ""))
        except InputError:
            return None
    bounds = {0.0}
    for piece in pieces:
        if piece is not None:
            times = (piece.lag[0],) if piece.lag is not None else piece.knots_t_s
            bounds |= {float(t) for t in times if 0.0 < t < duration_s}
    starts = sorted(bounds)
    return (np.array(starts), *_piece_starts(pieces, starts))


def _piece_starts(pieces, starts: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """Each piece's value at each of ``starts`` and its change from there (:func:`exact_segments`' ``u`` and
    ``du``), zero for an input without a signal (None)."""
    values, changes = [], []
    for t0 in starts:
        for piece in pieces:
            values.append(0.0 if piece is None else piece(t0))
            changes += _NO_CHANGE if piece is None else _change_after(piece, t0)
    # Flat lists made arrays once, then shaped: numpy costs more per element set, or per nested list it
    # parses, than per array made.
    shape = (len(starts), len(pieces))
    return np.array(values, dtype=float).reshape(shape), np.array(changes, dtype=float).reshape(*shape, 3)


_NO_CHANGE = (0.0, 0.0, 0.0)


def _change_after(piece, t0: float) -> tuple[float, float, float]:
    """(slope, lag amplitude, lag time constant) of ``piece`` from ``t0`` to its next knot or lag start."""
    if piece.lag is not None:
        time_s, initial, final, tau_s = piece.lag
        return (0.0, 0.0, 0.0) if t0 < time_s else (0.0, (initial - final) * math.exp(-(t0 - time_s) / tau_s), tau_s)
    ts, vs = piece.knots_t_s, piece.knots
    k = bisect.bisect_right(ts, t0) - 1  # the last knot at or before t0 (numpy's searchsorted costs more on a tuple)
    if 0 <= k < len(ts) - 1 and ts[k + 1] > ts[k]:
        return ((vs[k + 1] - vs[k]) / (ts[k + 1] - ts[k]), 0.0, 0.0)
    return (0.0, 0.0, 0.0)


SCENARIO_CACHE_SIZE = 256
"""Cases kept per process, by scenario object (:func:`case_inputs`)."""


class KeptByObject:
    """Values kept for the last ``size`` objects, by the object itself (not by equality, which would take
    ``1`` for ``1.0``), for immutable objects whose value costs more to build than to keep; threads may
    share it."""

    def __init__(self, size: int):
        self.size, self._kept, self._lock = size, {}, threading.Lock()

    def get(self, obj):
        """The value kept for ``obj``, or None."""
        kept = self._kept.get(id(obj))
        if kept is not None and kept[0]() is obj:  # an object's id is reused only after it is gone
            return kept[1]
        return None

    def put(self, obj, value) -> None:
        """Keep ``value`` for ``obj``, dropping the oldest beyond :attr:`size`."""
        with self._lock:
            self._kept[id(obj)] = (weakref.ref(obj), value)
            while len(self._kept) > self.size:
                del self._kept[next(iter(self._kept))]


_cases = KeptByObject(SCENARIO_CACHE_SIZE)


def case_inputs(scenario: Scenario, model: MuscleModel | None = None) -> CaseInputs:
    """The library's inputs for ``scenario``; refuses (``InputError``) what the backend cannot honour.

    ``model`` is ``scenario.build_model()`` (built here if not given), or that model with its pressure
    source replaced (a fit drives it with a recorded pressure): the source choice follows the model.
    A scenario is immutable, so the case of its own model is kept (its arrays read-only) for its next
    run, by the scenario object (not by equality, which would take ``1`` for ``1.0``), for the last
    :data:`SCENARIO_CACHE_SIZE` scenarios.
    """
    if model is None:
        kept = _cases.get(scenario)
        if kept is not None:
            return kept
    case = _new_case(scenario, model)
    if model is None:
        for array in (case.reals, case.ints, case.segment_t_s, case.segment_u, case.segment_du):
            if array is not None:
                array.flags.writeable = False
        _cases.put(scenario, case)  # the pool's runs may share this process's cases
    return case


def _new_case(scenario: Scenario, model: MuscleModel | None) -> CaseInputs:
    """:func:`case_inputs`, built."""
    refuse_unsupported(scenario)
    model = scenario.build_model() if model is None else model
    opts = scenario.solver
    T = scenario.duration_s
    n_samples = int(round(T * opts.sample_rate_Hz)) + 1
    model, assembly = engine_parts(scenario, model)
    names, signals = _signals(model)
    reals, ints = core_values(scenario, model)
    pieces = exact_segments(signals, T)
    starts, u, du = pieces if pieces is not None else (*held_segments(signals, model, T, n_samples), None)
    _set_mass(u, names, model)
    return CaseInputs(reals, ints, T, n_samples, starts, u, opts.max_events, model, assembly, du, names,
                      stiff_switch(opts))


def core_values(scenario: Scenario, model: MuscleModel) -> tuple[np.ndarray, np.ndarray]:
    """The one-muscle FMU's variables for ``scenario`` run with ``model``: the reals (parameters, start,
    margins, solver settings) and the ints (element choices).  The engine reads the solver settings from
    them, and a fit the parameters it moves."""
    opts = scenario.solver
    reals = lib.REAL_DEFAULTS.copy()
    # the parameters the FMU has (the others shape the force table: refuse_unsupported)
    _put(reals, lib.REAL_INDEX, {name: p.value for name, p in scenario.parameters.entries.items()})
    _put(reals, lib.REAL_INDEX, {
        "initial_contraction_m": scenario.initial_contraction_m, "x_high_m": upper_stop_start(model),
        "initial_pressure_gauge_Pa": scenario.initial_pressure_gauge_Pa or 0.0,
        "stick_margin_N": opts.stick_margin_N, "release_margin_N": opts.release_margin_N,
        "cs_relative_tolerance": native_rtol(opts),
        "cs_max_step_s": opts.max_step_s if math.isfinite(opts.max_step_s) else _DEFAULT_MAX_STEP_S})
    ints = lib.INT_DEFAULTS.copy()
    spec = scenario.spec["model"]
    choices = {"friction_model": ("friction", spec["friction"]), "damping_model": ("damping", spec["damping"]),
               "pressure_source": ("source", "valve" if isinstance(model.source, ValveChamberSource) else "prescribed"),
               "friction_negative_level": ("friction_negative_level", spec["friction_negative_level"])}
    # the core's choices (the engine reads none of them)
    _put(ints, lib.INT_INDEX, {name: C_CHOICES[key].index(value) for name, (key, value) in choices.items()
                               if value in C_CHOICES[key]})
    return reals, ints


def _put(array: np.ndarray, index: dict[str, int], values: dict) -> None:
    """``array[index[name]] = value`` for each of ``values`` that ``index`` names."""
    for name, value in values.items():
        if name in index:
            array[index[name]] = value


def held_segments(signals, model: MuscleModel, duration_s: float, n_samples: int) -> tuple[np.ndarray, np.ndarray]:
    """Segments over which ``signals`` (None where an input has none) are held, for a signal
    :func:`exact_segments` cannot carry: cut at the model's breakpoints and every
    :func:`hold_interval_s`, each signal at its segment's midpoint.  Returns the segments' starts and
    the inputs over them."""
    T = duration_s
    hold = hold_interval_s(signals, T / max(n_samples - 1, 1))
    bounds = {0.0} | {float(b) for b in model.breakpoints if 0.0 < b < T}
    if math.isfinite(hold):
        bounds |= set(np.linspace(0.0, T, int(math.ceil(T / hold)) + 1)[:-1].tolist())
    starts = np.array(sorted(bounds))
    mid = 0.5 * (starts + np.append(starts[1:], T))  # a step's value is constant inside its segment
    u = np.zeros((len(starts), len(signals)))
    for k, sig in enumerate(signals):
        if sig is not None:
            u[:, k] = sig(mid)
    return starts, u


def _set_mass(u: np.ndarray, names: Sequence[str], model: MuscleModel) -> None:
    """The load's mass in the C core's input column of it (the flat model has it as a parameter)."""
    if "load_mass_kg" in names:
        u[:, list(names).index("load_mass_kg")] = model.load.mass_kg


def _engines(cases: Sequence[CaseInputs]) -> list[tuple[Any, list[int]]]:
    """The engine of each assembly structure among ``cases`` (compiled on its first use) and the indices of
    the cases it runs."""
    groups: dict = {}
    for i, c in enumerate(cases):
        groups.setdefault(c.assembly.structure_key(), []).append(i)
    return [(engine_library(cases[members[0]].assembly), members) for members in groups.values()]


def _run(cases: Sequence[CaseInputs], capacity: Sequence[int], engines=None) -> list[tuple[dict, int]]:
    """Each case's batch output and its index in it: the cases of one assembly structure in one engine call
    (``engines``: :func:`_engines` of ``cases``, found here if None)."""
    where: list = [None] * len(cases)
    for library, members in engines if engines is not None else _engines(cases):
        out = library.run([cases[i].engine_case(library, capacity[i]) for i in members])
        out["library"] = library
        for j, i in enumerate(members):
            where[i] = (out, j)
    return where


_MODE_LABELS = {int(m): m.label for m in Mode}
_MODES = {int(m): m for m in Mode}  # a dict look-up costs less than calling the enum


def check_status(out: dict, i: int, origin: str, max_events: int) -> None:
    """Raise what case ``i`` of an engine's output ended with, if not a run: :class:`InputError` for a bad value
    the engine found (naming ``origin``), :class:`SolverFailure` for a failed integration or more than
    ``max_events`` events."""
    status, message = int(out["status"][i]), out["messages"][i]
    if status == 1:
        raise InputError(f"{origin}: {message}")
    if status == 2:
        raise SolverFailure(f"native backend: {message}")
    if status == 3 or int(out["n_events"][i]) > max_events:
        raise too_many_events(max_events)


_event_names: dict[tuple, str] = {}  # a few modes, indicators and added components: a few names
_EVENT_NAMES_KEPT = 4096
"""Most event names kept (a sweep over many added components' names would otherwise grow the table)."""


def _event_name(mode: int, fired: int, to: int, others: tuple[str, ...]) -> str:
    """:func:`event_name` of an event by the modes' and mask's numbers and the added components' indicators'
    names ``others``, kept for the next event."""
    key = (mode, fired, to, others)
    name = _event_names.get(key)
    if name is None:
        name = event_name(_MODES[mode], fired, _MODES[to], others)
        if len(_event_names) >= _EVENT_NAMES_KEPT:
            _event_names.clear()
        _event_names[key] = name
    return name


def _result(scenario: Scenario, case: CaseInputs, out: dict, i: int, wall_time_s: float,
            t: np.ndarray | None = None) -> Result:
    """Case ``i`` of a batch's output as a :class:`Result`, or the error it ended with.

    ``t`` is the sample grid if the caller has it already (cases of one batch share equal grids).
    """
    status = int(out["status"][i])
    message = out["messages"][i]
    if status == 1:
        raise InputError(f"{scenario.origin}: {message}")
    if status == 2:
        raise SolverFailure(f"native backend: {message}")
    if status == 3:
        raise too_many_events(case.max_events)
    if t is None:
        t = np.linspace(0.0, case.duration_s, case.n_samples)
    stats = engine_stats(out, i, scenario.solver, 0)  # its events counted from the transitions
    return _engine_result(scenario, case, out, i, wall_time_s, t, stats)


def _engine_result(scenario: Scenario, case: CaseInputs, out: dict, i: int, wall_time_s: float, t: np.ndarray,
                   stats: dict) -> Result:
    """Case ``i`` of a generic engine's batch as a :class:`Result`: its states in the flat model's order
    (the model's, which :class:`pamsim.simulator.GeneratedCode` checks), events named from the indicators
    that fired, the kinetic energy an event removed from the load's output."""
    names = out["library"].names
    outputs, n_y, n = names["outputs"], len(names["outputs"]), case.n_samples
    first, ns = int(out["sample_offset"][i]), len(names["states"])
    Y = out["samples"][ns * first:ns * (first + n)].reshape(ns, n)
    first_event = int(out["event_offset"][i])
    x_at, ke_at = outputs.index("load.x_m"), outputs.index("load.kinetic_energy_J")
    after = 4 + n_y  # a row: t, modes before and after, fired mask, outputs before, after
    # Column by column, as Python numbers (no numpy scalars): the rows' other outputs stay unread.
    rows = out["events"][first_event:first_event + int(out["n_events"][i])]
    t_s, x_m = rows[:, 0].tolist(), rows[:, after + x_at].tolist()
    lost = (rows[:, 4 + ke_at] - rows[:, after + ke_at]).tolist()
    modes, tos, fired = (rows[:, k].astype(np.int64).tolist() for k in (1, 2, 3))
    # The added components' indicators' names (an element's slip), once per run rather than per event.
    others = tuple(f"{c}.{n}" for c, n in case.assembly.indicator_names()[2:]) if t_s else ()
    labels = _MODE_LABELS
    transitions = [TransitionEvent(t, _event_name(m, f, to, others), labels[m], labels[to], x)
                   for t, m, to, f, x in zip(t_s, modes, tos, fired, x_m)]
    losses = list(zip(t_s, lost))
    stats["events"] = len(transitions)
    high, low = out["extremes"][i][:n_y], out["extremes"][i][n_y:]
    pressure = next(a for a, b in case.assembly.connections if b == "muscle.p_gauge_Pa")
    peaks = {"x_m": float(high[x_at]), "x_min_m": float(low[x_at]),
             "p_gauge_Pa": float(high[outputs.index(pressure)])}
    # In the run's buffer (SAMPLE_ROOM), not in new arrays: the same values, without a page fault per 4 KiB.
    modes, p = out["modes_int64"][first:first + n], out["column_f64"][first:first + n]
    np.copyto(modes, out["modes"][first:first + n])  # int32 to int64: exact
    p[:] = case.model.pressure_trace_Pa(t, Y)
    return Result.from_trace(case.model, scenario.name, t, Y, modes, transitions, losses, stats, wall_time_s,
                             peaks=peaks, outputs=RigOutputs(case.assembly, case.model, t, Y, modes), p_gauge_Pa=p)


GRID_CACHE_SIZE = 32
"""Sample grids kept per process: the runs of a sweep share a few."""
_grids: "OrderedDict[tuple[float, int], np.ndarray]" = OrderedDict()


def _sample_grids(cases: Sequence[CaseInputs]) -> list[np.ndarray]:
    """Each case's sample times [s]: ``linspace(0, duration_s, n_samples)``, one read-only array per grid,
    kept for the next calls."""
    out = []
    for c in cases:
        key = (c.duration_s, c.n_samples)
        if key in _grids:
            _grids.move_to_end(key)  # least recently used goes first
        else:
            _grids[key] = np.linspace(0.0, c.duration_s, c.n_samples)
            _grids[key].flags.writeable = False
            if len(_grids) > GRID_CACHE_SIZE:
                _grids.popitem(last=False)
        out.append(_grids[key])
    return out


def simulate_batch(scenarios: Sequence[Scenario], return_exceptions: bool = False,
                   models: Sequence[MuscleModel | None] | None = None) -> list:
    """Run many scenarios in one library call and return their :class:`Result` s, in order.

    Parameters
    ----------
    scenarios : sequence of Scenario
        Each is checked first: a setting the native backend cannot honour raises
        :class:`~pamsim.errors.InputError` naming it, before anything runs.
    return_exceptions : bool
        Put a failed case's exception in its place in the list instead of raising it.
    models : sequence of MuscleModel or None, optional
        Each scenario's model, as :func:`case_inputs` takes it (None: the scenario's own).
    """
    # The collector paused: a batch makes objects by the thousand (components, events, results), few of them
    # in cycles, and its passes over them cost a fortieth of a 66-case batch.
    with paused_gc():
        return _simulate_batch(scenarios, return_exceptions, models)


def _simulate_batch(scenarios: Sequence[Scenario], return_exceptions: bool,
                    models: Sequence[MuscleModel | None] | None) -> list:
    """:func:`simulate_batch`, with the collector paused."""
    cases = [case_inputs(s, m) for s, m in zip(scenarios, models or [None] * len(scenarios))]
    engines = _engines(cases)  # before the clock starts: a first run's compilation is no part of its time
    wall0 = time.perf_counter()
    found = _run(cases, [event_capacity(c.max_events) for c in cases], engines)
    wall = (time.perf_counter() - wall0) / max(len(cases), 1)
    results = []
    for (out, i), scenario, case, t in zip(found, scenarios, cases, _sample_grids(cases)):
        try:
            if outgrew_batch(int(out["status"][i]), case.max_events):
                again = time.perf_counter()
                [(alone, k)] = _run([case], [case.max_events + 1])
                results.append(_result(scenario, case, alone, k, time.perf_counter() - again, t))
            else:
                results.append(_result(scenario, case, out, i, wall, t))
        except (InputError, SolverFailure) as exc:
            if not return_exceptions:
                raise
            results.append(exc)
    return results


def simulate(scenario: Scenario, model: MuscleModel | None = None) -> Result:
    """Backend ``native``: run ``scenario`` with the C core and return its :class:`Result`.

    ``model``: the scenario's model with its pressure source replaced (a controller's), as
    :func:`case_inputs` takes it; None runs the scenario's own.
    """
    return simulate_batch([scenario], models=[model])[0]
