"""The simulations of a dynamic fit on the native backend: every trial point of one optimiser step
(every trace, every finite-difference column, a whole differential-evolution generation) in one
call of the C core's batch entry point, or in one call per worker with an executor.

Each trace's case is built once, at the start of the fit, exactly as the native backend builds a
scenario's (:func:`pamsim.native.backend.case_inputs`), with the trace's load, duration and the
fit's tolerance, and with the recorded pressure as the source when there is one.  A trial point
only changes the free coefficients, which are entries of the case's parameter vector, so a trial
case is that vector with the free entries replaced: no scenario or model is built per trial.  The
one input derived from a coefficient, the load mass ``weight_N / g_m_s2``, is recomputed from the
trial's ``g_m_s2``.

What this approximates (docs/identification.md has the measured effect on a fit): the C core holds
its inputs constant over segments, so the recorded pressure, linear between its knots, is held at
its midpoint value over every output-sample interval (:func:`pamsim.native.backend.hold_interval_s`;
a knot inside an interval is passed over, a turning knot is a segment boundary).  Over an interval
with no knot inside, the midpoint value is the interval's mean pressure, a second-order
approximation; the Python backend follows the polyline exactly.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from ..elements.pressure_source import PrescribedPressure
from ..errors import InputError
from ..native import library as lib
from ..native.backend import CaseInputs, case_inputs, event_capacity, outgrew_batch
from ..static_models import get as get_static_model
from .trials import trace_scenario

_X_ROW = lib.SAMPLE_COLUMNS.index("x_m")
_MASS = lib.INPUTS.index("load_mass_kg")
_G = lib.REAL_INDEX["g_m_s2"]


@dataclass(frozen=True)
class Chunk:
    """Trial cases sent to the library in one call (pickles to a worker process)."""

    reals: np.ndarray
    ints: np.ndarray
    duration_s: np.ndarray
    n_samples: np.ndarray
    segment_counts: np.ndarray
    segment_t_s: np.ndarray
    segment_u: np.ndarray
    max_events: np.ndarray
    sample_t_s: tuple[np.ndarray, ...]
    tables: tuple = ()


def _run(chunk: Chunk, capacity: np.ndarray) -> dict:
    """One library call; the cases share the fit's one force table, if its static model has one."""
    return lib.run_batch(chunk.reals, chunk.ints, chunk.duration_s, chunk.n_samples, chunk.segment_counts,
                         chunk.segment_t_s, chunk.segment_u, capacity, chunk.tables,
                         np.zeros(len(chunk.duration_s), dtype=np.int64) if chunk.tables else None)


def _sub(chunk: Chunk, a: int, b: int) -> Chunk:
    """Cases ``a`` to ``b - 1`` of ``chunk``."""
    seg = np.concatenate([[0], np.cumsum(chunk.segment_counts)])
    return Chunk(chunk.reals[a:b], chunk.ints[a:b], chunk.duration_s[a:b], chunk.n_samples[a:b],
                 chunk.segment_counts[a:b], chunk.segment_t_s[seg[a]:seg[b]], chunk.segment_u[seg[a]:seg[b]],
                 chunk.max_events[a:b], chunk.sample_t_s[a:b], chunk.tables)


def run_chunk(chunk: Chunk) -> list[np.ndarray]:
    """Contraction [m] of every case of ``chunk`` at its sample times; NaN for a case that failed.

    One library call for the chunk.  Events are kept up to :data:`pamsim.native.backend.BATCH_EVENT_CAPACITY` per case;
    a case that had more is run again alone with room for its ``max_events``, as
    :func:`pamsim.native.simulate_batch` does, so the event limit is the scenario's, as on the
    Python backend.
    """
    out = _run(chunk, event_capacity(chunk.max_events))
    xs = []
    for i in range(len(chunk.duration_s)):
        status, found, k = int(out["status"][i]), out, i
        if outgrew_batch(status, int(chunk.max_events[i])):
            found, k = _run(_sub(chunk, i, i + 1), chunk.max_events[i:i + 1] + 1), 0
            status = int(found["status"][0])
        if status != 0:  # bad input, solver failure or too many events: a bad trial point, as in Python
            xs.append(np.full(chunk.sample_t_s[i].shape, np.nan))
            continue
        first, m = int(found["sample_offset"][k]), int(chunk.n_samples[i])
        block = found["samples"][len(lib.SAMPLE_COLUMNS) * first:len(lib.SAMPLE_COLUMNS) * (first + m)]
        grid = np.linspace(0.0, chunk.duration_s[i], m)
        xs.append(np.interp(chunk.sample_t_s[i], grid, block.reshape(-1, m)[_X_ROW]))
    return xs


def _stack(cases: Sequence[CaseInputs], reals: np.ndarray, samples: Sequence[np.ndarray]) -> Chunk:
    return Chunk(reals, np.array([c.ints for c in cases]), np.array([c.duration_s for c in cases]),
                 np.array([c.n_samples for c in cases], dtype=np.int64),
                 np.array([len(c.segment_t_s) for c in cases], dtype=np.int64),
                 np.concatenate([c.segment_t_s for c in cases]), np.concatenate([c.segment_u for c in cases]),
                 np.array([c.max_events for c in cases], dtype=np.int64), tuple(samples),
                 (cases[0].table,) if cases[0].table is not None else ())  # one static model: one table


TABLE_SHAPERS = ("rated_pressure_gauge_Pa", "L0_m", "r0_m", "theta0_deg")
"""Parameters that set a force table's domain (the pressure rating and the stops) for any model."""


def _refuse_free_table_parameters(problem) -> None:
    """A static force other than the polynomial runs as a force table built once per fit: a free
    coefficient that shapes it (a parameter of the model, or of the table's domain) is refused."""
    m = problem.scenario.spec["model"]
    if m["static_force"] == "acra2012_polynomial":
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


class NativeTrials:
    """The fit's simulations on the C core: ``trials(thetas, executor)`` gives every trace's contraction
    at its sample times for every row of ``thetas``, theta-major (the Python backend's task order)."""

    def __init__(self, problem, rtol: float):
        _refuse_free_table_parameters(problem)
        self.cases = []
        for tr, w, sig in zip(problem.traces, problem.loads_N, problem.inputs):
            sc = trace_scenario(problem.scenario, {}, w, float(tr.t_s[-1] - tr.t_s[0]), rtol)
            model = sc.build_model()
            if sig is not None:
                model = replace(model, source=PrescribedPressure(sig))
            self.cases.append(case_inputs(sc, model))
        self.weights_N = np.array(problem.loads_N)
        self.samples = [tr.t_s - tr.t_s[0] for tr in problem.traces]
        self.free_index = np.array([lib.REAL_INDEX[n] for n in problem.free], dtype=int)

    def chunk(self, thetas: np.ndarray) -> Chunk:
        """Every trace at every row of ``thetas`` as one batch."""
        thetas = np.atleast_2d(np.asarray(thetas, dtype=float))
        n_tr = len(self.cases)
        reals = np.repeat(np.array([c.reals for c in self.cases])[None], len(thetas), axis=0)
        reals[:, :, self.free_index] = thetas[:, None, :]
        reals = reals.reshape(len(thetas) * n_tr, -1)
        cases = self.cases * len(thetas)
        chunk = _stack(cases, reals, self.samples * len(thetas))
        # The load mass is the only input a coefficient feeds (through g): the trial's own.
        mass = np.repeat(np.tile(self.weights_N, len(thetas)) / reals[:, _G], chunk.segment_counts)
        chunk.segment_u[:, _MASS] = mass
        return chunk

    def __call__(self, thetas: np.ndarray, executor=None) -> list[np.ndarray]:
        chunk = self.chunk(thetas)
        n = len(chunk.duration_s)
        parts = 1 if executor is None else min(executor_workers(executor), n)
        if parts <= 1:
            return run_chunk(chunk)
        bounds = np.linspace(0, n, parts + 1).round().astype(int)
        subs = [_sub(chunk, a, b) for a, b in zip(bounds[:-1], bounds[1:])]
        return [x for part in executor.map(run_chunk, subs) for x in part]

