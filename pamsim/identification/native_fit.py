"""The simulations of a dynamic fit on the native backend: every trial point of one optimiser step
(every trace, every finite-difference column, a whole differential-evolution generation) in one
library call, or in one call per worker with an executor.

Each trace's case is built once, at the start of the fit, exactly as the native backend builds a
scenario's (:func:`pamsim.native.backend.case_inputs`), with the trace's load, duration and the
fit's tolerance, and with the recorded pressure as the source when there is one.  Like the backend,
the fit runs such a case on the generic engine compiled with the case's generated model
(:mod:`pamsim.native.engine`).

**A trial point on the engine.**  The engine takes the flat model's parameter vector
(``assembly.parameter_values()``: ``friction.N0_N_per_bar``, ``load.mass_kg``, ...), whose entries are
not always the scenario's parameters: some are copies of one (``N0_N_per_bar`` is
``friction.N0_N_per_bar``), others are derived (the load's mass is the trace's weight over ``g_m_s2``;
the chamber's thread length and turns and the upper stop come from ``L0_m``, ``r0_m`` and
``theta0_deg``).  Which is which is found per trace, at set-up, by rebuilding the trace's model with
each free coefficient moved to two nearby values (:meth:`_EngineTrials._probe`):

- a coefficient that moves the same entries at both, each to the coefficient's value, is a *copy*:
  a trial writes its value into those entries, with no model built;
- any other is *derived*: one that moves an entry to another value (``g_m_s2``, the geometry), and
  one that moves none at the probes (a parameter the trace's elements do not read, such as the
  valve's conductance with a recorded pressure: it might at other values, and rebuilding costs
  little).  A trial rebuilds the trace's model with its derived coefficients, as ``case_inputs``
  builds it, so those entries are the backend's own by construction, then writes the copies in.
  A rebuild costs about 0.3 ms a trace (an 8 s simulation about 1 ms); the vectors are kept by the
  derived values, so a Jacobian's columns of the copied coefficients share one.  Should a derived
  coefficient move an entry a copy writes, or a probe fail, every coefficient is rebuilt.

A trial whose coefficients the parameter set refuses (a value outside its range, a pair out of order)
is refused without a run, NaN as on the Python backend, and so is one whose rebuilt scenario fails its
own checks.

**The recorded pressure** is a trace of its knots (:class:`.pressure_input.PiecewiseLinearInput`), which
the backend takes as it takes a scenario's trace: the run is cut at
every knot and the integrator evaluates the line between two knots exactly
(:func:`pamsim.native.backend.exact_segments`), so a trial's contraction is ``pamsim.simulate`` of the
trace's scenario with that trace on the native backend, and the output sample rate changes nothing but
the grid the contraction is interpolated from (docs/identification.md has the measured agreement with
the Python backend).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Sequence

import numpy as np

from ..elements.pressure_source import PrescribedPressure
from ..errors import InputError
from ..native.backend import CaseInputs, case_inputs, engine_assembly, event_capacity, needs_table, outgrew_batch
from ..native.engine import EngineCase, EngineLibrary, engine_library
from ..static_models import get as get_static_model
from .trials import trace_scenario

def _contractions(n_cases: int, max_events, sample_t_s, first_pass, alone, trace) -> list[np.ndarray]:
    """Each case's contraction [m] at its sample times, NaN for a case that failed.

    ``first_pass(i)`` is case i's batch output and its place in it; ``alone(i)`` runs case i again by
    itself with room for its ``max_events`` (a case that outgrew the batch's event room, as
    :func:`pamsim.native.simulate_batch` does, so the event limit is the scenario's, as on the Python
    backend); ``trace(out, k, i)`` is the contraction on the case's own sample grid and that grid.
    """
    xs = []
    for i in range(n_cases):
        found, k = first_pass(i)
        status = int(found["status"][k])
        if outgrew_batch(status, int(max_events[i])):
            found, k = alone(i), 0
            status = int(found["status"][0])
        if status != 0:  # bad input, solver failure or too many events: a bad trial point, as in Python
            xs.append(np.full(sample_t_s[i].shape, np.nan))
            continue
        grid, x = trace(found, k, i)
        xs.append(np.interp(sample_t_s[i], grid, x))
    return xs


# ------------------------------------------------------------------------------- the generic engine
_LIBRARIES: dict[str, EngineLibrary] = {}


def _library(path: str, names: dict) -> EngineLibrary:
    """The engine library at ``path``, loaded once per process: a worker re-creates it from the path and
    names a chunk carries (a ctypes library does not pickle)."""
    if path not in _LIBRARIES:
        _LIBRARIES[path] = EngineLibrary(Path(path), names)
    return _LIBRARIES[path]


def _run_engine(library: EngineLibrary, cases: Sequence[EngineCase]) -> dict:
    """One call of an engine library."""
    return library.run(cases)


@dataclass(frozen=True)
class EngineChunk:
    """Trial cases for the generic engine (pickles to a worker process: the libraries by path and names).

    ``library_of[i]`` indexes ``libraries`` (path, names), or is -1 for a trial point refused before
    running (its contraction is NaN); ``cases[i]`` is then None.
    """

    libraries: tuple[tuple[str, dict], ...]
    library_of: tuple[int, ...]
    cases: tuple[EngineCase | None, ...]
    max_events: tuple[int, ...]
    sample_t_s: tuple[np.ndarray, ...]

    def __len__(self) -> int:
        return len(self.cases)

    def sub(self, a: int, b: int) -> "EngineChunk":
        """Cases ``a`` to ``b - 1``."""
        return EngineChunk(self.libraries, self.library_of[a:b], self.cases[a:b], self.max_events[a:b],
                           self.sample_t_s[a:b])

    def run(self) -> list[np.ndarray]:
        """Contraction [m] of every case at its sample times; NaN for a case that failed."""
        where: list = [None] * len(self)
        for j, (path, names) in enumerate(self.libraries):
            members = [i for i, k in enumerate(self.library_of) if k == j]
            if members:
                out = _run_engine(_library(path, names), [self.cases[i] for i in members])
                for k, i in enumerate(members):
                    where[i] = (out, k)
        refused = {"status": np.array([1])}

        def alone(i):
            path, names = self.libraries[self.library_of[i]]
            return _run_engine(_library(path, names), [replace(self.cases[i], event_capacity=self.max_events[i] + 1)])

        def trace(found, k, i):
            names, case = self.libraries[self.library_of[i]][1], self.cases[i]
            ns, first, m = len(names["states"]), int(found["sample_offset"][k]), case.n_samples
            block = found["samples"][ns * first:ns * (first + m)].reshape(ns, m)
            return np.linspace(0.0, case.duration_s, m), block[names["states"].index("load.x_m")]

        return _contractions(len(self), self.max_events, self.sample_t_s,
                             lambda i: where[i] if where[i] is not None else (refused, 0), alone, trace)


def _probe_values(value: float, upper: float) -> tuple[float, float]:
    """Two values near ``value``, below it if its upper bound leaves no room above (a value at its lower
    bound, such as a restitution of 0, has room above)."""
    h = 1e-3 * abs(value) if value != 0.0 else 1e-3
    return (value + h, value + 2 * h) if value + 2 * h < upper else (value - h, value - 2 * h)


@dataclass
class _EngineTrace:
    """One trace on the engine: its case, its library, and how a trial's coefficients reach its vector.

    ``copies`` maps the position of a free coefficient that is copied into the flat model's parameters
    to the entries it is copied into; ``derived`` lists the positions of the others, with which a trial
    rebuilds the trace's model."""

    case: EngineCase
    library: EngineLibrary
    copies: dict[int, np.ndarray]
    derived: tuple[int, ...]
    max_events: int


BUILT_SIZE = 256
"""Rebuilt parameter vectors kept per fit, by trace and derived values (a Jacobian's columns of the
copied coefficients share one)."""


class _EngineTrials:
    """Trial chunks of traces whose cases run on the generic engine."""

    def __init__(self, problem, rtol: float, cases: Sequence[CaseInputs], samples: Sequence[np.ndarray]):
        self.problem, self.rtol, self.samples = problem, rtol, list(samples)
        self._built: dict[tuple, tuple[EngineLibrary | None, np.ndarray | None]] = {}
        self.traces = [self._set_up(i, c) for i, c in enumerate(cases)]

    def _assembly(self, i: int, overrides: dict):
        """Trace ``i``'s assembly with ``overrides``, as :func:`case_inputs` builds it (with the
        components the scenario adds)."""
        return engine_assembly(*_trace_model(self.problem, i, overrides, self.rtol))

    def _set_up(self, i: int, case: CaseInputs) -> _EngineTrace:
        library = engine_library(case.assembly)
        _LIBRARIES.setdefault(str(library.path), library)
        base = case.engine_case(library, int(event_capacity(case.max_events)))
        copies, derived, touched = {}, [], []
        upper = self.problem.bounds[1]
        for j, name in enumerate(self.problem.free):
            value = float(self.problem.scenario.parameters[name])
            moved, copy = self._probe(i, name, _probe_values(value, upper[j]), base.params)
            if copy and np.all(base.params[moved] == value):
                copies[j] = moved
            else:
                derived.append(j)
                touched.append(moved)
        written = np.concatenate([np.zeros(0, dtype=int), *copies.values()])
        if any(m is None for m in touched) or np.intersect1d(written, np.concatenate([[], *touched])).size:
            # A derived entry a copy would overwrite, or one a probe could not find: rebuild with all.
            copies, derived = {}, list(range(len(self.problem.free)))
        return _EngineTrace(base, library, copies, tuple(derived), case.max_events)

    def _probe(self, i: int, name: str, values: Sequence[float], base: np.ndarray) -> tuple[np.ndarray | None, bool]:
        """The flat entries ``name`` moves when trace ``i``'s model is rebuilt at each of ``values``
        (None if it cannot be rebuilt there), and whether they are its copies: the same entries at
        every value, each holding the value."""
        moved, copy = None, True
        for value in values:
            try:
                p = np.array(self._assembly(i, {name: value}).parameter_values())
            except InputError:
                return None, False
            changed = np.flatnonzero(p != base)
            copy = (copy and changed.size > 0 and bool(np.all(p[changed] == value))
                    and (moved is None or np.array_equal(changed, moved)))
            moved = changed if moved is None else np.union1d(moved, changed)
        return moved, copy

    def _build(self, k: int, overrides: dict) -> tuple[EngineLibrary | None, np.ndarray | None]:
        """Trace ``k``'s library and parameter vector rebuilt with ``overrides``; (None, None) if the
        scenario refuses them or the model cannot be built."""
        try:
            assembly = self._assembly(k, overrides)
            return engine_library(assembly), np.array(assembly.parameter_values())
        except Exception:  # noqa: BLE001 -- a trial point that cannot be built is a bad point, as in Python
            return None, None

    def _trial(self, k: int, theta: np.ndarray) -> tuple[EngineLibrary | None, EngineCase | None]:
        """Trace ``k``'s case at ``theta`` (whose values the parameter set accepts) and the library to
        run it on, or (None, None) if the trial point is refused."""
        tr = self.traces[k]
        library, params = tr.library, tr.case.params
        if tr.derived:
            key = (k, *(float(theta[j]) for j in tr.derived))
            if key not in self._built:
                if len(self._built) >= BUILT_SIZE:
                    self._built.pop(next(iter(self._built)))
                self._built[key] = self._build(k, {self.problem.free[j]: float(theta[j]) for j in tr.derived})
            library, params = self._built[key]
            if library is None:
                return None, None
        params = params.copy()
        for j, entries in tr.copies.items():
            params[entries] = theta[j]
        return library, replace(tr.case, params=params)

    def chunk(self, thetas: np.ndarray) -> EngineChunk:
        params = self.problem.scenario.parameters
        paths: dict[str, int] = {}
        libraries, library_of, cases, max_events = [], [], [], []
        for theta in thetas:
            # The checks the scenario makes of its parameters (ranges, pairs in order), once per point.
            valid = not params.with_overrides(dict(zip(self.problem.free, map(float, theta)))).violations()
            for k, tr in enumerate(self.traces):
                library, case = self._trial(k, theta) if valid else (None, None)
                if library is not None and str(library.path) not in paths:
                    paths[str(library.path)] = len(libraries)
                    libraries.append((str(library.path), library.names))
                library_of.append(-1 if library is None else paths[str(library.path)])
                cases.append(case)
                max_events.append(tr.max_events)
        return EngineChunk(tuple(libraries), tuple(library_of), tuple(cases), tuple(max_events),
                           tuple(self.samples * len(thetas)))


def run_chunk(chunk: EngineChunk) -> list[np.ndarray]:
    """Contraction [m] of every case of ``chunk`` at its sample times; NaN for a case that failed.

    One library call for the chunk (one per engine library: traces with and without a recorded
    pressure are two structures).  Events are kept up to
    :data:`pamsim.native.backend.BATCH_EVENT_CAPACITY` per case; a case that had more is run again
    alone with room for its ``max_events``.
    """
    return chunk.run()


TABLE_SHAPERS = ("rated_pressure_gauge_Pa", "L0_m", "r0_m", "theta0_deg")
"""Parameters that set a force table's domain (the pressure rating and the stops) for any model."""


def _refuse_free_table_parameters(problem) -> None:
    """A static force without generated C runs as a force table built once per fit: a free coefficient
    that shapes it (a parameter of the model, or of the table's domain) is refused."""
    m = problem.scenario.spec["model"]
    if not needs_table(problem.scenario):
        return
    spec = get_static_model(m["static_force"])
    shapers = set(spec.parameters) | set(spec.optional) | set(TABLE_SHAPERS)
    for name in problem.free:
        if name in shapers:
            raise InputError(f"--free: {name!r} shapes the force table of static model {m['static_force']!r}, "
                             "which the native backend builds once per fit; fit it with --backend python")


def executor_workers(executor) -> int:
    """Worker count of ``executor``: ``concurrent.futures`` pools keep it as ``_max_workers`` (there is
    no public attribute); for other executors, the machine's CPU count."""
    return int(getattr(executor, "_max_workers", None) or os.cpu_count() or 1)


def _trace_model(problem, i: int, overrides: dict, rtol: float):
    """Trace ``i``'s scenario with ``overrides`` and its model, driven by the recorded pressure if any."""
    tr, w, sig = problem.traces[i], problem.loads_N[i], problem.inputs[i]
    sc = trace_scenario(problem.scenario, overrides, w, float(tr.t_s[-1] - tr.t_s[0]), rtol)
    model = sc.build_model()
    return sc, (model if sig is None else replace(model, source=PrescribedPressure(sig)))


class NativeTrials:
    """The fit's simulations on the native backend: ``trials(thetas, executor)`` gives every trace's
    contraction at its sample times for every row of ``thetas``, theta-major (the Python backend's task
    order)."""

    def __init__(self, problem, rtol: float):
        _refuse_free_table_parameters(problem)
        cases = [case_inputs(*_trace_model(problem, i, {}, rtol)) for i in range(len(problem.traces))]
        samples = [tr.t_s - tr.t_s[0] for tr in problem.traces]
        self.trials = _EngineTrials(problem, rtol, cases, samples)

    def chunk(self, thetas: np.ndarray) -> EngineChunk:
        """Every trace at every row of ``thetas`` as one batch."""
        return self.trials.chunk(np.atleast_2d(np.asarray(thetas, dtype=float)))

    def __call__(self, thetas: np.ndarray, executor=None) -> list[np.ndarray]:
        chunk = self.chunk(thetas)
        n = len(chunk)
        parts = 1 if executor is None else min(executor_workers(executor), n)
        if parts <= 1:
            return run_chunk(chunk)
        bounds = np.linspace(0, n, parts + 1).round().astype(int)
        subs = [chunk.sub(a, b) for a, b in zip(bounds[:-1], bounds[1:])]
        return [x for part in executor.map(run_chunk, subs) for x in part]
