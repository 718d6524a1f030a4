"""Running a sweep: :func:`run_sweep` on any :class:`concurrent.futures.Executor`
(a process pool, or ``distributed.Client(...).get_executor()``); a failed case is
recorded, not raised.  :meth:`SweepResult.write` writes ``summary.csv``,
``report.md`` and the figures atomically.
"""

from __future__ import annotations

import csv
import math
import sys
import time
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..atomic import atomic_outputs
from ..constants import PA_PER_BAR
from ..errors import InputError
from ..figure_style import check_format
from ..oscillation import estimate_oscillation
from ..scenario import Scenario
from ..static import friction_band_m, static_report
from .figures import SWEEP_FIGURES, UNCERTAINTY_FIGURES
from .gc_control import frozen_gc, paused_gc
from .spec import SweepCase, SweepSpec, load_sweep
from .uncertainty import Samples, UncertaintyResult

SETTLED_FRACTION = 0.05
"""The pressure counts as settled once it stays within 5 % of its step of its final value; the
oscillation is estimated from then on, so creep driven by a still-rising pressure is not counted."""

LAST_WINDOW_S = 1.0
"""Window at the end of each run over which the remaining motion (peak to peak) is reported [s]."""

UNCERTAINTY_TABLES = ("uncertainty_samples.csv", "uncertainty_summary.csv")

FIGURES = ("error_heatmap", "steady_state_vs_pressure", "time_responses", "frequency_vs_load")
"""File stems of a sweep's figures, in the order of the report (:data:`.figures.SWEEP_FIGURES` renders them);
the files are ``STEM.png``, ``.pdf`` or ``.svg``."""


@dataclass(frozen=True)
class _Task:
    """One scenario to run in a worker (it pickles to a process or a distributed worker)."""

    kind: str  # "case", "frequency", "response" or "sample"
    key: tuple
    scenario: Scenario
    keep_trace: bool
    backend: str = "python"
    # Parameter values applied in the worker, so that thousands of samples of one base scenario
    # send the scenario once per chunk (pickle shares it) and build their variants where they run.
    parameters: tuple[tuple[str, float], ...] = ()


def _task(kind: str, key: tuple, scenario: Scenario, keep_trace: bool = False, backend: str = "python",
          parameters: tuple[tuple[str, float], ...] = ()) -> _Task:
    return _Task(kind, key, scenario, keep_trace, backend, parameters)


MAX_AUTO_CHUNK = {"python": 50, "native": 1000}
"""Largest chunk chosen automatically, by backend: about a second of runs (the Python backend's take
about 20 ms, the native backend's about 1 ms), big enough to amortise the per-task overhead of a
scheduler (milliseconds), small enough to balance the load and lose little work when a worker dies.
A backend not listed (an FMU) takes the Python backend's."""

AUTO_CHUNKS = 32
"""Chunks the automatic size aims at (more when capped by :data:`MAX_AUTO_CHUNK`): 16 per worker on
2 workers, enough to balance the load, while a Dask task costs the sweep's process (which serves a
local cluster's scheduler and client) milliseconds of CPU each.  With more than 32 workers (a
large cluster, or a process pool on a machine with more CPUs), a sweep small enough to get only
32 chunks leaves some idle: give a smaller ``chunk_size``."""


def auto_chunk_size(n_tasks: int, backend: str = "python") -> int:
    """Runs per executor task when none is given: ``ceil(n / 32)``, between 1 and the backend's
    :data:`MAX_AUTO_CHUNK` (50 for the Python backend, 1000 for the native one)."""
    cap = MAX_AUTO_CHUNK.get(backend, MAX_AUTO_CHUNK["python"])
    return max(1, min(cap, math.ceil(n_tasks / AUTO_CHUNKS)))


NATIVE_BATCH = 16
"""Native runs per library call within a chunk: enough to amortise the call, few enough that the
batch's traces (about 0.6 MB per 8 s run at 1 kHz) stay in cache while they are reduced."""


class ChunkOutputs(tuple):
    """The outputs of a chunk's runs, in order: a tuple that a Dask worker sends in one piece.

    Dask sends the items of a plain list or tuple result one by one (each run's small dict
    pickled and unpickled on its own: ten thousand of them for the uncertainty study); a subclass
    is pickled whole, as a process pool does anyway.
    """

    __slots__ = ()


def run_chunk(tasks: list[_Task]) -> ChunkOutputs:
    """Run a chunk of tasks in one worker (one executor task, one round trip).

    The native backend's runs go to the library in batch calls of :data:`NATIVE_BATCH`; the
    Python backend's run one after the other.  The numbers are the same either way.
    """
    if not tasks or any(t.backend != "native" for t in tasks):
        return ChunkOutputs(run_task(task) for task in tasks)
    batches = (tasks[i:i + NATIVE_BATCH] for i in range(0, len(tasks), NATIVE_BATCH))
    return ChunkOutputs(o for batch in batches for o in _run_native_batch(batch))


def _run_native_batch(tasks: list[_Task]) -> list[dict]:
    """:func:`run_chunk` of at most :data:`NATIVE_BATCH` native tasks: one library call."""
    from ..native import simulate_batch

    out: list[dict | None] = [None] * len(tasks)
    built = []
    for k, task in enumerate(tasks):
        try:
            built.append((k, _scenario(task)))
        except Exception as exc:  # noqa: BLE001 -- a sweep reports every failure and carries on
            out[k] = _failure(exc)
    try:
        results = simulate_batch([sc for _, sc in built], return_exceptions=True)
    except Exception:  # noqa: BLE001 -- one case the batch refuses: run them one by one to say which
        return [run_task(task) for task in tasks]
    for (k, _), result in zip(built, results):
        try:
            out[k] = _failure(result) if isinstance(result, Exception) else _reduce(tasks[k], result)
        except Exception as exc:  # noqa: BLE001 -- a sweep reports every failure and carries on
            out[k] = _failure(exc)
    return out


def _scenario(task: _Task) -> Scenario:
    """The task's scenario with its sampled parameter values applied."""
    if task.parameters:
        return task.scenario.with_changes({"parameters": dict(task.parameters)})
    return task.scenario


def _failure(exc: Exception) -> dict:
    return {"error": f"{type(exc).__name__}: {exc}"}


def run_task(task: _Task) -> dict:
    """Run one task in a worker and reduce its result to plain numbers (cheap to send back).

    Any exception is returned as ``{"error": ...}`` so one failing case does not end the sweep.
    """
    from ..backends import simulate

    try:
        return _reduce(task, simulate(_scenario(task), task.backend))
    except Exception as exc:  # noqa: BLE001 -- a sweep reports every failure and carries on
        return _failure(exc)


def _reduce(task: _Task, result) -> dict:
    """The figures a sweep keeps of one run (and its trace if the task asks for it)."""
    t_settled = settled_time_s(result.t_s, result.p_gauge_Pa)
    osc = estimate_oscillation(result.t_s, result.x_m, t_start_s=t_settled)
    last = result.t_s >= result.t_s[-1] - LAST_WINDOW_S
    out = {"final_contraction_m": float(result.x_m[-1]), "peak_contraction_m": result.peak_contraction_m,
           "at_rest": bool(result.at_rest_at_end), "final_mode": result.final_mode.label,
           "last_second_peak_to_peak_m": float(np.ptp(result.x_m[last])),
           "frequency_Hz": osc.frequency_Hz, "damping_ratio": osc.damping_ratio,
           "n_half_cycles": osc.n_half_cycles, "half_period_asymmetry": osc.half_period_asymmetry,
           "settled_time_s": t_settled,
           "contraction_settled_time_s": settled_time_s(result.t_s, result.x_m),
           "wall_time_s": float(result.wall_time_s), "error": ""}
    if task.keep_trace:
        out["t_s"] = result.t_s
        out["x_m"] = result.x_m
        out["p_gauge_Pa"] = result.p_gauge_Pa
    return out


def settled_time_s(t_s: np.ndarray, p_gauge_Pa: np.ndarray, fraction: float = SETTLED_FRACTION) -> float:
    """First time after which a signal stays within ``fraction`` of its step of its final value.

    Used for the pressure (``p_gauge_Pa``) and, in uncertainty studies, for the contraction.
    """
    step = abs(float(p_gauge_Pa[-1] - p_gauge_Pa[0]))
    if step == 0.0:
        return float(t_s[0])
    outside = np.flatnonzero(np.abs(p_gauge_Pa - p_gauge_Pa[-1]) > fraction * step)
    return float(t_s[outside[-1] + 1]) if outside.size else float(t_s[0])


@dataclass
class SweepResult:
    """Everything a sweep produced: one row per case, the frequency study, the time responses."""

    spec: SweepSpec
    rows: list[dict]
    frequency_rows: list[dict]
    responses: dict[str, dict[str, dict]]
    wall_time_s: float
    failures: list[str] = field(default_factory=list)
    uncertainty: UncertaintyResult | None = None

    def columns(self) -> list[str]:
        """Column names of ``summary.csv``."""
        return list(self.rows[0]) if self.rows else []

    def write(self, directory: str | Path, executor: Executor | None = None, figure_format: str = "png",
              dpi: int | None = None) -> list[str]:
        """Write ``summary.csv``, ``report.md`` and the figures into ``directory``, all or nothing.

        Parameters
        ----------
        directory : str or Path
            The output folder.
        executor : concurrent.futures.Executor, optional
            Render the figures on its workers (they are most of the time of a fast sweep);
            ``None`` renders them here.  The files do not depend on it.
        figure_format : {"png", "pdf", "svg"}
            The figures' file format (the reports link to these files).
        dpi : int, optional
            The figures' resolution in dots per inch (default 110).

        Returns
        -------
        list of str
            The names written.
        """
        from .figures import render_all
        from .report import write_report

        fmt = check_format(figure_format, label="figure format")
        study = self.uncertainty
        jobs = {}
        # A pure uncertainty study (no cases) writes only its own outputs.
        if self.spec.cases or study is None:
            jobs = {f"{stem}.{fmt}": (maker, self) for stem, maker in SWEEP_FIGURES.items()}
        names = ["summary.csv", "report.md", *(f"{stem}.{fmt}" for stem in FIGURES)] if jobs else []
        if study is not None:
            jobs.update({f"{stem}.{fmt}": (maker, study) for stem, maker in UNCERTAINTY_FIGURES.items()})
            names += [*UNCERTAINTY_TABLES, "uncertainty.md", *(f"{stem}.{fmt}" for stem in UNCERTAINTY_FIGURES)]
        figures = render_all(jobs, executor, fmt, dpi)
        with atomic_outputs(directory, names) as tmp:
            if "summary.csv" in names:
                self.to_csv(tmp["summary.csv"])
                tmp["report.md"].write_text(write_report(self, fmt))
            if study is not None:
                study.write_tables(*(tmp[n] for n in UNCERTAINTY_TABLES))
                tmp["uncertainty.md"].write_text(study.report(self.spec.name, fmt))
            for name, data in figures.items():
                tmp[name].write_bytes(data)
        return names

    def to_csv(self, path: str | Path) -> None:
        """Write the per-case table (not atomic on its own; :meth:`write` stages it)."""
        cols = self.columns()
        with open(path, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=cols)
            w.writeheader()
            for row in self.rows:
                w.writerow({k: _fmt(v) for k, v in row.items()})


def _fmt(value: Any) -> Any:
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, float):
        return f"{value:.9g}"
    return value


def run_sweep(spec: SweepSpec | str | Path, executor: Executor | None = None, progress: bool = False,
              backend: str | None = None, chunk_size: int | None = None) -> SweepResult:
    """Run every case of a sweep under every friction model, and the frequency and response studies.

    Parameters
    ----------
    spec : SweepSpec, str or Path
        A validated sweep or the path of a sweep file.
    executor : concurrent.futures.Executor, optional
        Where to run the simulations: a ``ProcessPoolExecutor``, or for a
        cluster ``distributed.Client(...).get_executor()``.  ``None`` runs them
        one after the other in this process.  The numbers do not depend on it.
    progress : bool
        Show a progress bar with an ETA on stderr.
    backend : str, optional
        The backend of every run (:data:`pamsim.backends.BACKENDS`); default: the sweep file's
        ``backend`` key, else ``"python"``.  Every scenario is checked against it before anything runs.
    chunk_size : int, optional
        Runs sent to the executor as one task (default :func:`auto_chunk_size`).
        Larger chunks amortise the per-task cost of a cluster scheduler; smaller
        ones balance the load better.  Ignored without an executor.

    Returns
    -------
    SweepResult
        Failed runs appear as rows with an ``error`` message and NaN numbers.
    """
    if not isinstance(spec, SweepSpec):
        spec = load_sweep(spec)
    backend = backend or spec.backend
    check_backend(spec, backend)
    tasks = _study_tasks(spec, backend)
    start = time.perf_counter()
    samples = spec.uncertainty.draw() if spec.uncertainty is not None else None
    if samples is not None:
        tasks += _sample_tasks(spec, samples, backend)
    _check_chunk_size(chunk_size)
    from tqdm import tqdm

    with tqdm(total=len(tasks), unit="run", desc=spec.name, file=sys.stderr, disable=not progress,
              dynamic_ncols=True) as bar:
        outputs = _execute(tasks, executor, bar, chunk_size or auto_chunk_size(len(tasks), backend))
    return _result(spec, tasks, outputs, samples, time.perf_counter() - start)


def _study_tasks(spec: SweepSpec, backend: str) -> list[_Task]:
    """The runs of the cases, the frequency study and the time responses, under every friction model."""
    models = spec.friction_models
    tasks = [_task("case", (i, f), spec.case_scenario(c, f), backend=backend) for i, c in enumerate(spec.cases)
             for f in models]
    if spec.frequency is not None:
        tasks += [_task("frequency", (w, f), spec.frequency_scenario(w, f), backend=backend)
                  for w in spec.frequency.weights_N for f in models]
    tasks += [_task("response", (s.name, f), s.with_changes({"model": {"friction": f}}), True, backend)
              for s in spec.time_responses for f in models]
    return tasks


def _sample_tasks(spec: SweepSpec, samples: Samples, backend: str) -> list[_Task]:
    """One run per uncertainty sample and friction model, each carrying its parameter values."""
    tasks = []
    # Thousands of small objects that live until the end: no garbage for the collector to find.
    with paused_gc():
        for f in spec.friction_models:
            base = spec.base.with_changes({"model": {"friction": f}})
            tasks += [_task("sample", (k, f), base, backend=backend,
                            parameters=tuple(zip(samples.names, map(float, values))))
                      for k, values in enumerate(samples.values)]
    return tasks


def _result(spec: SweepSpec, tasks: list[_Task], outputs: list[dict], samples: Samples | None,
            wall_time_s: float) -> SweepResult:
    """The sweep's tables from its runs' outputs (``outputs[k]`` is the output of ``tasks[k]``)."""
    by_key = {(t.kind, t.key): o for t, o in zip(tasks, outputs)}
    case_scenarios = {t.key: t.scenario for t in tasks if t.kind == "case"}
    rows = [_case_row(spec, i, case, by_key, case_scenarios) for i, case in enumerate(spec.cases)]
    responses = {s.name: {f: by_key[("response", (s.name, f))] for f in spec.friction_models}
                 for s in spec.time_responses}
    return SweepResult(spec, rows, _frequency_rows(spec, by_key), responses, wall_time_s, _failures(tasks, outputs),
                       _uncertainty_result(spec, samples, by_key))


def _check_chunk_size(chunk_size: Any) -> None:
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1):
        raise InputError(f"chunk_size = {chunk_size!r}: must be a positive integer")


def _failures(tasks: list[_Task], outputs: list[dict]) -> list[str]:
    """The message of every failed run, naming its scenario (and its sample)."""
    return [f"{t.scenario.name}{f' sample {t.key[0]}' if t.kind == 'sample' else ''}: {o['error']}"
            for t, o in zip(tasks, outputs) if o["error"]]


_FREQUENCY_COLUMNS = ("frequency_Hz", "damping_ratio", "n_half_cycles", "half_period_asymmetry",
                      "final_contraction_m", "peak_contraction_m", "at_rest")


def _frequency_rows(spec: SweepSpec, by_key: Mapping) -> list[dict]:
    """One row per load of the frequency study, with each friction model's columns prefixed by its name."""
    if spec.frequency is None:
        return []
    rows = []
    for w in spec.frequency.weights_N:
        row = {"weight_N": w, "pressure_bar": spec.frequency.pressure_bar}
        for f in spec.friction_models:
            o = by_key[("frequency", (w, f))]
            row.update({f"{f}_{k}": o.get(k, math.nan) for k in _FREQUENCY_COLUMNS})
        rows.append(row)
    return rows


def _uncertainty_result(spec: SweepSpec, samples: Samples | None, by_key: Mapping) -> UncertaintyResult | None:
    """The uncertainty study's outputs, sample by sample for each friction model (None without a study)."""
    if samples is None:
        return None
    return UncertaintyResult(spec.uncertainty, samples, {
        f: [by_key[("sample", (k, f))] for k in range(len(samples.values))] for f in spec.friction_models})


def check_backend(spec: SweepSpec, backend: str) -> None:
    """Raise ``InputError`` naming the first setting of the sweep that ``backend`` cannot honour.

    The cases differ from their base scenario only in load and pressure, so the base, the
    frequency study and the time responses under each friction model stand for all of them.
    """
    from ..backends import check_backend as check_scenario

    scenarios = [spec.base] + [s for s in spec.time_responses]
    if spec.frequency is not None:
        scenarios.append(spec.frequency_scenario(spec.frequency.weights_N[0], spec.friction_models[0]))
    for scenario in scenarios:
        for friction in spec.friction_models:
            check_scenario(backend, scenario.with_changes({"model": {"friction": friction}}))


def _execute(tasks: list[_Task], executor: Executor | None, bar, chunk_size: int = 1) -> list[dict]:
    """Run the tasks (here, or on ``executor`` in chunks of ``chunk_size``), advancing the tqdm ``bar``
    by one per finished run."""
    outputs: list[dict | None] = [None] * len(tasks)
    failed = 0
    if executor is None:
        # In batches of NATIVE_BATCH, as a worker runs its chunk (the native backend's runs share library calls).
        for i in range(0, len(tasks), NATIVE_BATCH):
            chunk = run_chunk(tasks[i:i + NATIVE_BATCH])
            outputs[i:i + len(chunk)] = chunk
            failed += sum(bool(o["error"]) for o in chunk)
            bar.set_postfix(failed=failed, refresh=False)
            bar.update(len(chunk))
        return outputs
    starts = range(0, len(tasks), chunk_size)
    # The tasks, the imported modules and a local cluster's scheduler stay out of the collector's
    # passes while this process waits on the workers and serves the scheduler.
    with frozen_gc():
        futures = {executor.submit(run_chunk, tasks[i:i + chunk_size]): i for i in starts}
        for fut in as_completed(futures):
            i = futures[fut]
            n = min(chunk_size, len(tasks) - i)
            try:
                chunk = fut.result()
            except Exception as exc:  # noqa: BLE001 -- a dead worker fails its chunk's cases, not the sweep
                chunk = [{"error": f"{type(exc).__name__}: {exc}"}] * n
            outputs[i:i + n] = chunk
            failed += sum(bool(o["error"]) for o in chunk)
            bar.set_postfix(failed=failed, refresh=False)
            bar.update(n)
    return outputs


_RUN_COLUMNS = ("final_contraction_m", "peak_contraction_m", "error_m", "at_rest", "final_mode",
                "last_second_peak_to_peak_m", "frequency_Hz", "damping_ratio", "n_half_cycles", "failure")


def _case_row(spec: SweepSpec, i: int, case: SweepCase, by_key: Mapping, scenarios: Mapping) -> dict:
    """One summary row: inputs, static analysis, measurement, and each friction model's run.

    ``scenarios`` maps ``(i, friction)`` to the case scenarios the runs used (built once, in
    :func:`_study_tasks`), so the row's static analysis describes the very model that ran.
    """
    params = spec.base.parameters
    models = {f: scenarios[(i, f)].build_model() for f in spec.friction_models}
    model = models[spec.friction_models[0]]
    p_Pa = case.pressure_bar * PA_PER_BAR
    x_eq = static_report(params, model.static_force, p_Pa, case.weight_N)["equilibrium_contraction_m"]
    row = {"case": case.name, "weight_N": case.weight_N, "pressure_bar": case.pressure_bar,
           "pressure_step_bar": case.pressure_step_bar, "pressure_stable_bar": case.pressure_stable_bar,
           "measured_contraction_m": case.measured_contraction_m, "equilibrium_contraction_m": x_eq,
           "equilibrium_error_m": x_eq - case.measured_contraction_m,
           "within_capability": bool(x_eq >= spec.capability_min_equilibrium_m)}
    for n, f in enumerate(spec.friction_models):
        lo, hi = friction_band_m(model.static_force, models[f].friction, p_Pa, model.load.mass_kg, model.load.g_m_s2,
                                 model.stops.x_high_m)
        o = by_key[("case", (i, f))]
        # The first model's columns carry the plain names; the others are prefixed with the model name.
        prefix = "" if n == 0 else f"{f}_"
        row[f"{prefix}friction_band_low_m"] = lo
        row[f"{prefix}friction_band_high_m"] = hi
        for k in _RUN_COLUMNS:
            if k == "error_m":
                row[prefix + k] = o.get("final_contraction_m", math.nan) - case.measured_contraction_m
            elif k == "failure":
                row[prefix + k] = o["error"]
            else:
                row[prefix + k] = o.get(k, math.nan)
    return row
