"""Running a sweep: :func:`run_sweep` on any :class:`concurrent.futures.Executor`
(a process pool, or ``distributed.Client(...).get_executor()``); a failed case is
recorded, not raised.  :meth:`SweepResult.write` writes ``summary.csv``,
``report.md`` and the figures atomically.
"""

from __future__ import annotations

import csv
import math
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Sequence
from concurrent.futures import FIRST_COMPLETED, CancelledError, Executor, Future, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..atomic import atomic_outputs, check_output_dir, existing_folder
from ..constants import PA_PER_BAR
from ..errors import InputError, RunFailure
from ..figure_style import check_format
from ..oscillation import estimate_oscillation
from ..scenario import Scenario
from ..static import friction_band_m, static_report
from .dask_cluster import executor_watch, executor_workers
from .figures import SWEEP_FIGURES, UNCERTAINTY_FIGURES
from ..gc_control import frozen_gc
from .spec import SweepCase, SweepSpec, load_sweep
from .sample_table import ChunkOrder, SampleTable, row_bytes
from .uncertainty import LOST, QUANTITIES, RunColumns, Samples, UncertaintyResult

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
    lost: int = 0
    """Runs the executor lost (only with ``allow_incomplete``): rows whose failure begins ``lost:``."""
    failed_runs: int = 0
    """Failed runs, the lost ones included: ``failures`` names at most
    :data:`~.uncertainty.MAX_KEPT_MESSAGES` of an uncertainty study's per friction model."""

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

    def close(self) -> None:
        """Remove the temporary file of the uncertainty study's samples table (once written, or not wanted)."""
        if self.uncertainty is not None:
            self.uncertainty.close()

    def __enter__(self) -> "SweepResult":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

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
              backend: str | None = None, chunk_size: int | None = None,
              allow_incomplete: bool = False, output_dir: str | Path | None = None) -> SweepResult:
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
    allow_incomplete : bool
        Runs lost to the executor (a worker or cluster gone, so no result at all) stop the sweep with
        :class:`~pamsim.errors.RunFailure` unless this is true; then they become failed rows whose
        message begins ``lost:``, and the uncertainty study says that its sample is incomplete.
    output_dir : str or Path, optional
        The folder the results will be written to (:meth:`SweepResult.write`).  An uncertainty study writes
        its per-run table to disk as its runs finish, into a hidden temporary file there (in the folder it
        will be made in while it does not exist), removed again if the sweep stops.  Default: the
        system's temporary folder (the table is then copied when written elsewhere).

    Returns
    -------
    SweepResult
        Failed runs appear as rows with an ``error`` message and NaN numbers.  With an uncertainty study,
        :meth:`SweepResult.close` (or leaving its ``with`` block) removes the table's temporary file.

    Raises
    ------
    InputError
        An uncertainty study too large for this machine's memory (:func:`check_memory`) or for the disk of
        ``output_dir`` (:func:`check_disk`), an output folder that cannot be written, or a bad chunk size.
    RunFailure
        Runs lost (unless ``allow_incomplete``), a Dask cluster whose scheduler or last worker went away.
    """
    if not isinstance(spec, SweepSpec):
        spec = load_sweep(spec)
    backend = backend or spec.backend
    check_backend(spec, backend)
    _check_chunk_size(chunk_size)
    check_memory(spec)
    folder = check_output_dir(tempfile.gettempdir() if output_dir is None else output_dir)
    check_disk(spec, folder)
    start = time.perf_counter()
    samples = spec.uncertainty.draw() if spec.uncertainty is not None else None
    tasks = _Tasks(_study_tasks(spec, backend), spec, samples, backend)
    kept = _Kept(tasks, folder)
    from tqdm import tqdm

    try:
        with tqdm(total=len(tasks), unit="run", desc=spec.name, file=sys.stderr, disable=not progress,
                  dynamic_ncols=True) as bar:
            _execute(tasks, executor, _Progress(kept, bar), chunk_size or auto_chunk_size(len(tasks), backend),
                     allow_incomplete)
        kept.finish()
    except BaseException:  # an error or an interrupt: no samples table, not even its temporary file
        kept.discard()
        raise
    return _result(spec, kept, samples, time.perf_counter() - start)


BYTES_PER_SAMPLE_RUN = 8 * len(QUANTITIES)
"""Memory an uncertainty study keeps per sample and friction model: a float of each summarised quantity, for
the quantiles and the figures (:class:`.uncertainty.RunColumns`); the rest of each run is on disk."""

BYTES_PER_SAMPLE_VALUE = 40
"""Memory per sample and sampled parameter while the samples are drawn: the uniform numbers, the values
and numpy's temporaries of the Latin hypercube (the values, 8 bytes, are kept for the table's rows)."""

BYTES_PER_SAMPLE_DRAW = 64
"""Memory per sample, whatever the parameter count, while the samples are drawn: the temporaries of one
parameter's transform (a draw of 1,000,000 samples peaked at 58 + 16 x parameters bytes per sample in
``tracemalloc``; see ``benchmarks/bench_uncertainty_memory.py`` for the whole study's)."""

MEMORY_SHARE = 0.8
"""The share of the memory available at the start that a study may plan to use."""


def sample_memory_bytes(spec: SweepSpec) -> int:
    """Memory the uncertainty study of ``spec`` needs that grows with its sample count [bytes]: drawing the
    samples and, per friction model, the summarised quantities of every run (0 without a study).  The chunks
    out on the executor add a constant (:func:`chunks_in_flight`)."""
    study = spec.uncertainty
    if study is None:
        return 0
    per_sample = BYTES_PER_SAMPLE_VALUE * len(study.parameters) + BYTES_PER_SAMPLE_DRAW \
        + BYTES_PER_SAMPLE_RUN * len(spec.friction_models)
    return study.samples * per_sample


def available_memory_bytes() -> int | None:
    """Memory available to new work on this machine [bytes] (``MemAvailable`` of ``/proc/meminfo``, else the
    free physical pages), or None where neither can be read."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def check_memory(spec: SweepSpec) -> None:
    """Raise ``InputError`` naming ``uncertainty.samples`` when the study would need more than
    :data:`MEMORY_SHARE` of the memory available now (before anything is drawn or run)."""
    need = sample_memory_bytes(spec)
    have = available_memory_bytes()
    if have is None or need <= MEMORY_SHARE * have:
        return
    raise InputError(f"{spec.origin}: uncertainty.samples = {spec.uncertainty.samples}: the study needs about "
                     f"{_bytes(need)} of memory and {_bytes(have)} is available; take at most "
                     f"{int(MEMORY_SHARE * have / (need / spec.uncertainty.samples)):,} samples or split the study "
                     "(different seeds)")


def sample_table_bytes(spec: SweepSpec) -> int:
    """Most disk the samples table of the uncertainty study of ``spec`` takes if every run succeeds [bytes]
    (:func:`.sample_table.row_bytes` per run; 0 without a study)."""
    study = spec.uncertainty
    if study is None:
        return 0
    return study.samples * sum(row_bytes(study.samples, len(study.parameters), f) for f in spec.friction_models)


def free_disk_bytes(folder: str | Path) -> int:
    """Disk space free to this user in ``folder``, or in the folder it will be made in [bytes]."""
    return shutil.disk_usage(existing_folder(folder)).free


def check_disk(spec: SweepSpec, folder: str | Path) -> None:
    """Raise ``InputError`` naming ``uncertainty.samples`` when the study's samples table would not fit in the
    disk space free in ``folder`` (or the folder it will be made in), before anything is drawn or run."""
    need = sample_table_bytes(spec)
    have = free_disk_bytes(folder)
    if need <= have:
        return
    n = spec.uncertainty.samples
    raise InputError(f"{spec.origin}: uncertainty.samples = {n}: the samples table needs up to {_bytes(need)} of "
                     f"disk in {folder} and {_bytes(have)} is free; take at most {int(have / (need / n)):,} "
                     "samples, split the study (different seeds) or write elsewhere")


def _bytes(n: float) -> str:
    """``n`` bytes in words: ``29.1 TB``, ``512 MB``."""
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1000
    raise AssertionError("unreachable")


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


class _Tasks(Sequence):
    """The runs of a sweep in order: its study's tasks, then one per uncertainty sample under each friction
    model (friction by friction).  A sample's task is made when its chunk is sent, so a study of millions
    of samples never holds its tasks at once."""

    def __init__(self, study: list[_Task], spec: SweepSpec, samples: Samples | None, backend: str):
        self.study = study
        self.samples = samples
        self.frictions = list(spec.friction_models) if samples is not None else []
        self.backend = backend
        self.n_samples = len(samples.values) if samples is not None else 0
        # Every sample's task carries its friction model's base scenario (pickled once per chunk).
        self.bases = [spec.base.with_changes({"model": {"friction": f}}) for f in self.frictions]

    def __len__(self) -> int:
        return len(self.study) + self.n_samples * len(self.frictions)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        if index < len(self.study):
            return self.study[index]
        f, k = divmod(index - len(self.study), self.n_samples)
        values = self.samples.values[k]
        return _task("sample", (k, self.frictions[f]), self.bases[f], backend=self.backend,
                     parameters=tuple(zip(self.samples.names, map(float, values))))


class _Kept:
    """What a sweep keeps of its runs as they finish: the study's outputs whole (few, and the case rows,
    frequency study and responses need them), the uncertainty samples' quantities in columns
    (:class:`RunColumns`) and their rows in the samples table on disk (:class:`.sample_table.SampleTable`, made
    in ``folder``), in the order of the runs (:class:`.sample_table.ChunkOrder`)."""

    def __init__(self, tasks: _Tasks, folder: Path):
        self.tasks = tasks
        self.study: list[dict | None] = [None] * len(tasks.study)
        self.runs = {f: RunColumns.empty(tasks.n_samples) for f in tasks.frictions}
        self.order = ChunkOrder()
        self.table = SampleTable(folder, tasks.samples.names) if tasks.samples is not None else None

    def record(self, start: int, outputs: Sequence[dict]) -> None:
        """Keep the outputs of the runs from index ``start`` on (their indices in :class:`_Tasks`); their rows
        reach the samples table once every earlier run's have."""
        rows = []
        for i, output in enumerate(outputs, start):
            if i < len(self.study):
                self.study[i] = output
                continue
            f, k = divmod(i - len(self.study), self.tasks.n_samples)
            self.runs[self.tasks.frictions[f]].put(k, output)
            rows.append((k, self.tasks.frictions[f], self.tasks.samples.values[k], output))
        for text in self.order.add(start, len(outputs), SampleTable.rows_text(rows) if rows else ""):
            if text:
                self.table.write(text)

    def finish(self) -> None:
        """Close the samples table, every run recorded."""
        if self.order.next != len(self.tasks):
            raise RuntimeError(f"the sweep recorded runs up to {self.order.next} of {len(self.tasks)} in order")
        if self.table is not None:
            self.table.finish()

    def discard(self) -> None:
        """Remove the samples table's temporary file (the sweep stopped)."""
        if self.table is not None:
            self.table.discard()

    def lost(self) -> int:
        """Runs the executor lost (with ``allow_incomplete``: rows whose message begins ``lost:``)."""
        return sum(o["error"].startswith(LOST) for o in self.study) + sum(r.lost() for r in self.runs.values())

    def failed(self) -> int:
        """Failed runs, the lost ones included."""
        return sum(bool(o["error"]) for o in self.study) + sum(r.n_failed for r in self.runs.values())

    def failures(self) -> list[str]:
        """The message of every failed run of the study and of the first failed samples
        (:data:`~.uncertainty.MAX_KEPT_MESSAGES` per friction model), naming its scenario (and its sample), in
        the order of the runs."""
        out = [f"{t.scenario.name}: {o['error']}" for t, o in zip(self.tasks.study, self.study) if o["error"]]
        for base, runs in zip(self.tasks.bases, self.runs.values()):
            out += [f"{base.name} sample {k}: {e}" for k, e in sorted(runs.errors.items())]
        return out


@dataclass
class _Progress:
    """Hands each finished chunk's outputs to :class:`_Kept` and advances the tqdm ``bar``."""

    kept: _Kept
    bar: Any
    failed: int = 0
    done: int = 0

    def record(self, start: int, outputs: Sequence[dict]) -> None:
        """Keep the outputs of the runs from index ``start`` on."""
        self.kept.record(start, outputs)
        self.failed += sum(bool(o["error"]) for o in outputs)
        self.done += len(outputs)
        self.bar.set_postfix(failed=self.failed, refresh=False)
        self.bar.update(len(outputs))


def _result(spec: SweepSpec, kept: _Kept, samples: Samples | None, wall_time_s: float) -> SweepResult:
    """The sweep's tables from its kept outputs."""
    tasks = kept.tasks.study
    by_key = {(t.kind, t.key): o for t, o in zip(tasks, kept.study)}
    case_scenarios = {t.key: t.scenario for t in tasks if t.kind == "case"}
    rows = [_case_row(spec, i, case, by_key, case_scenarios) for i, case in enumerate(spec.cases)]
    responses = {s.name: {f: by_key[("response", (s.name, f))] for f in spec.friction_models}
                 for s in spec.time_responses}
    study = UncertaintyResult(spec.uncertainty, samples, kept.runs, kept.table) if samples is not None else None
    return SweepResult(spec, rows, _frequency_rows(spec, by_key), responses, wall_time_s, kept.failures(), study,
                       kept.lost(), kept.failed())


def _check_chunk_size(chunk_size: Any) -> None:
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1):
        raise InputError(f"chunk_size = {chunk_size!r}: must be a positive integer")


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


IN_FLIGHT_PER_WORKER = 4
"""Chunks a sweep keeps out per worker of its executor: one running and three queued behind it, so a worker
never waits for the sweep's process, which records each chunk as it comes back."""

MIN_IN_FLIGHT = 8
"""Chunks kept out while a Dask cluster reports fewer than 2 workers (none connected yet, say)."""

MAX_IN_FLIGHT = 64
"""Most chunks kept out (16 workers' worth), and the number for an executor whose workers are not known."""

WATCH_INTERVAL_S = 0.5
"""How often the sweep looks at a Dask cluster's health while it waits for chunks [s]."""


def _execute(tasks: _Tasks, executor: Executor | None, progress: _Progress, chunk_size: int = 1,
             allow_incomplete: bool = False) -> None:
    """Run the tasks (here, or on ``executor`` in chunks of ``chunk_size``), handing each chunk's outputs to
    ``progress`` as it finishes."""
    if executor is None:
        # In batches of NATIVE_BATCH, as a worker runs its chunk (the native backend's runs share library calls).
        for i in range(0, len(tasks), NATIVE_BATCH):
            progress.record(i, run_chunk(tasks[i:i + NATIVE_BATCH]))
        return
    # The tasks, the imported modules and a local cluster's scheduler stay out of the collector's
    # passes while this process waits on the workers and serves the scheduler.
    with frozen_gc():
        _execute_on(executor, tasks, progress, chunk_size, allow_incomplete)


def chunks_in_flight(executor: Executor) -> int:
    """Chunks a sweep keeps out on ``executor``: :data:`IN_FLIGHT_PER_WORKER` per worker, between
    :data:`MIN_IN_FLIGHT` and :data:`MAX_IN_FLIGHT` (a Dask cluster's workers as it last reported them, so the
    number follows workers that come and go)."""
    workers = executor_workers(executor)
    if workers is None:
        return MAX_IN_FLIGHT
    return min(MAX_IN_FLIGHT, max(MIN_IN_FLIGHT, IN_FLIGHT_PER_WORKER * workers))


def _submit_window(executor: Executor, tasks: _Tasks, first: int, chunk_size: int, order: ChunkOrder,
                   pending: dict) -> int:
    """Send the chunks from index ``first`` on that fit in the window of :func:`chunks_in_flight` chunks from the
    first run not yet recorded in order (``order.next``): the chunks running and those finished but held back
    for the samples table together stay within it.  Returns the index of the first chunk not sent."""
    end = min(len(tasks), order.next + chunks_in_flight(executor) * chunk_size)
    for i in range(first, end, chunk_size):
        pending[_submit(executor, tasks[i:i + chunk_size])] = i
        first = i + chunk_size
    return first


def _submit(executor: Executor, chunk: list[_Task]) -> Future:
    """The future of ``chunk`` run on ``executor``; an executor that refuses it (a process pool broken by a
    worker that died) gives a future holding its error, so the chunk counts as lost like the chunks that
    were running."""
    try:
        return executor.submit(run_chunk, chunk)
    except Exception as exc:  # noqa: BLE001 -- whatever the executor raises, the chunk has no result
        future = Future()
        future.set_exception(exc)
        return future


def _execute_on(executor: Executor, tasks: _Tasks, progress: _Progress, chunk_size: int,
                allow_incomplete: bool) -> None:
    """:func:`_execute` on an executor: a window of :func:`chunks_in_flight` chunks sent ahead, and a Dask
    cluster's health checked every :data:`WATCH_INTERVAL_S` while the sweep waits."""
    watch = executor_watch(executor)
    first = 0
    pending: dict = {}
    try:
        while True:
            first = _submit_window(executor, tasks, first, chunk_size, progress.kept.order, pending)
            if not pending:
                return
            done, _ = wait(pending, timeout=WATCH_INTERVAL_S, return_when=FIRST_COMPLETED)
            for fut in done:
                i = pending.pop(fut)
                n = min(chunk_size, len(tasks) - i)
                progress.record(i, _chunk_outputs(fut, n, allow_incomplete, progress, len(tasks)))
            problem = watch() if watch is not None else None
            if problem:
                raise RunFailure(f"{problem}; {_stopped(progress, len(tasks))}")
    finally:
        for fut in pending:  # an error or an interrupt: what has not started never will
            fut.cancel()


def _chunk_outputs(fut, n: int, allow_incomplete: bool, progress: _Progress, total: int) -> Sequence[dict]:
    """The outputs of a finished chunk of ``n`` runs; a chunk the executor lost stops the sweep, or with
    ``allow_incomplete`` gives ``n`` failed rows marked :data:`~.uncertainty.LOST`."""
    try:
        return fut.result()
    except Exception as exc:  # noqa: BLE001 -- a worker or cluster lost: run_chunk itself catches every run's error
        why = _lost_reason(exc)
    if not allow_incomplete:
        raise RunFailure(f"{n} runs lost to the executor ({why}); {_stopped(progress, total)}; rerun, or allow "
                         "an incomplete sweep (--allow-incomplete) to keep the runs that finished") from None
    return [{"error": LOST + why}] * n


def _lost_reason(exc: BaseException) -> str:
    """One line on why a chunk has no result; Dask's cancelled tasks carry no message."""
    if isinstance(exc, CancelledError):
        return "CancelledError: the executor shut down or lost its scheduler"
    return f"{type(exc).__name__}: {exc}".splitlines()[0]


def _stopped(progress: _Progress, total: int) -> str:
    return f"the sweep stopped after {progress.done} of {total} runs and wrote nothing"


_RUN_COLUMNS = ("final_contraction_m", "peak_contraction_m", "error_m", "at_rest", "final_mode",
                "last_second_peak_to_peak_m", "frequency_Hz", "damping_ratio", "n_half_cycles",
                "settled_time_s", "contraction_settled_time_s", "failure")


def _case_row(spec: SweepSpec, i: int, case: SweepCase, by_key: Mapping, scenarios: Mapping) -> dict:
    """One summary row: inputs, static analysis, measurement, and each friction model's run.

    ``scenarios`` maps ``(i, friction)`` to the case scenarios the runs used (built once, in
    :func:`_study_tasks`), so the row's static analysis describes the very model that ran.
    """
    params = spec.base.parameters
    models = {f: scenarios[(i, f)].build_model() for f in spec.friction_models}
    model = models[spec.friction_models[0]]
    p_Pa = case.pressure_bar * PA_PER_BAR
    x_eq = static_report(params, model.static_force, p_Pa, case.weight_N, model.stops)["equilibrium_contraction_m"]
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
