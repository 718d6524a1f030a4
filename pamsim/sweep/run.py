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
from ..oscillation import estimate_oscillation
from ..scenario import Scenario
from ..static import friction_band_m, static_report
from .spec import SweepCase, SweepSpec, load_sweep

SETTLED_FRACTION = 0.05
"""The pressure counts as settled once it stays within 5 % of its step of its final value; the
oscillation is estimated from then on, so creep driven by a still-rising pressure is not counted."""

LAST_WINDOW_S = 1.0
"""Window at the end of each run over which the remaining motion (peak to peak) is reported [s]."""

FIGURES = ("error_heatmap.png", "steady_state_vs_pressure.png", "time_responses.png", "frequency_vs_load.png")


@dataclass(frozen=True)
class _Task:
    """One scenario to run in a worker (it pickles to a process or a distributed worker)."""

    kind: str  # "case", "frequency" or "response"
    key: tuple
    scenario: Scenario
    keep_trace: bool


def _task(kind: str, key: tuple, scenario: Scenario, keep_trace: bool = False) -> _Task:
    return _Task(kind, key, scenario, keep_trace)


def run_task(task: _Task) -> dict:
    """Run one task in a worker and reduce its result to plain numbers (cheap to send back).

    Any exception is returned as ``{"error": ...}`` so one failing case does not end the sweep.
    """
    from ..api import simulate

    try:
        result = simulate(task.scenario)
        t_settled = settled_time_s(result.t_s, result.p_gauge_Pa)
        osc = estimate_oscillation(result.t_s, result.x_m, t_start_s=t_settled)
        last = result.t_s >= result.t_s[-1] - LAST_WINDOW_S
        out = {"final_contraction_m": float(result.x_m[-1]), "peak_contraction_m": float(result.x_m.max()),
               "at_rest": bool(result.at_rest_at_end), "final_mode": result.final_mode.label,
               "last_second_peak_to_peak_m": float(np.ptp(result.x_m[last])),
               "frequency_Hz": osc.frequency_Hz, "damping_ratio": osc.damping_ratio,
               "n_half_cycles": osc.n_half_cycles, "half_period_asymmetry": osc.half_period_asymmetry,
               "settled_time_s": t_settled,
               "wall_time_s": float(result.wall_time_s), "error": ""}
        if task.keep_trace:
            out["t_s"] = result.t_s
            out["x_m"] = result.x_m
            out["p_gauge_Pa"] = result.p_gauge_Pa
        return out
    except Exception as exc:  # noqa: BLE001 -- a sweep reports every failure and carries on
        return {"error": f"{type(exc).__name__}: {exc}"}


def settled_time_s(t_s: np.ndarray, p_gauge_Pa: np.ndarray, fraction: float = SETTLED_FRACTION) -> float:
    """First time after which the pressure stays within ``fraction`` of its step of its final value."""
    step = abs(float(p_gauge_Pa[-1] - p_gauge_Pa[0]))
    if step == 0.0:
        return float(t_s[0])
    outside = np.flatnonzero(np.abs(p_gauge_Pa - p_gauge_Pa[-1]) > fraction * step)
    return float(t_s[outside[-1] + 1]) if outside.size else float(t_s[0])


class ProgressBar:
    """A one-line text progress bar with an ETA, redrawn on a terminal and printed every 10 % otherwise."""

    def __init__(self, total: int, stream=None, width: int = 30):
        self.total = total
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.start = time.perf_counter()
        self.interactive = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last_decile = -1

    def update(self, done: int, failed: int) -> None:
        """Show ``done`` of ``total`` finished, ``failed`` of them failed."""
        elapsed = time.perf_counter() - self.start
        eta = elapsed / done * (self.total - done) if done else math.nan
        filled = int(self.width * done / self.total) if self.total else self.width
        line = (f"[{'#' * filled}{'.' * (self.width - filled)}] {done}/{self.total} runs, {failed} failed, "
                f"{elapsed:.1f} s elapsed, ETA {eta:.1f} s")
        decile = 10 * done // max(self.total, 1)
        if self.interactive:
            self.stream.write("\r" + line + ("\n" if done == self.total else ""))
        elif decile != self._last_decile:
            self.stream.write(line + "\n")
        self._last_decile = decile
        self.stream.flush()


@dataclass
class SweepResult:
    """Everything a sweep produced: one row per case, the frequency study, the time responses."""

    spec: SweepSpec
    rows: list[dict]
    frequency_rows: list[dict]
    responses: dict[str, dict[str, dict]]
    wall_time_s: float
    failures: list[str] = field(default_factory=list)

    def columns(self) -> list[str]:
        """Column names of ``summary.csv``."""
        return list(self.rows[0]) if self.rows else []

    def write(self, directory: str | Path) -> list[str]:
        """Write ``summary.csv``, ``report.md`` and the figures into ``directory``, all or nothing.

        Returns
        -------
        list of str
            The names written.
        """
        from .report import write_report
        from .plots import write_figures

        names = ["summary.csv", "report.md", *FIGURES]
        with atomic_outputs(directory, names) as tmp:
            self.to_csv(tmp["summary.csv"])
            tmp["report.md"].write_text(write_report(self))
            write_figures(self, {n: tmp[n] for n in FIGURES})
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


def run_sweep(spec: SweepSpec | str | Path, executor: Executor | None = None, progress: bool = False) -> SweepResult:
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

    Returns
    -------
    SweepResult
        Failed runs appear as rows with an ``error`` message and NaN numbers.
    """
    if not isinstance(spec, SweepSpec):
        spec = load_sweep(spec)
    tasks = [_task("case", (i, f), spec.case_scenario(c, f)) for i, c in enumerate(spec.cases)
             for f in spec.friction_models]
    if spec.frequency is not None:
        tasks += [_task("frequency", (w, f), spec.frequency_scenario(w, f))
                  for w in spec.frequency.weights_N for f in spec.friction_models]
    tasks += [_task("response", (s.name, f), s.with_changes({"model": {"friction": f}}), keep_trace=True)
              for s in spec.time_responses for f in spec.friction_models]
    start = time.perf_counter()
    outputs = _execute(tasks, executor, ProgressBar(len(tasks)) if progress else None)
    wall = time.perf_counter() - start
    by_key = {(t.kind, t.key): o for t, o in zip(tasks, outputs)}
    failures = [f"{t.scenario.name}: {o['error']}" for t, o in zip(tasks, outputs) if o["error"]]
    rows = [_case_row(spec, i, case, by_key) for i, case in enumerate(spec.cases)]
    freq_rows = []
    if spec.frequency is not None:
        for w in spec.frequency.weights_N:
            row = {"weight_N": w, "pressure_bar": spec.frequency.pressure_bar}
            for f in spec.friction_models:
                o = by_key[("frequency", (w, f))]
                for k in ("frequency_Hz", "damping_ratio", "n_half_cycles", "half_period_asymmetry",
                          "final_contraction_m", "peak_contraction_m", "at_rest"):
                    row[f"{f}_{k}"] = o.get(k, math.nan)
            freq_rows.append(row)
    responses = {s.name: {f: by_key[("response", (s.name, f))] for f in spec.friction_models}
                 for s in spec.time_responses}
    return SweepResult(spec, rows, freq_rows, responses, wall, failures)


def _execute(tasks: list[_Task], executor: Executor | None, bar: ProgressBar | None) -> list[dict]:
    outputs: list[dict | None] = [None] * len(tasks)
    failed = 0
    if executor is None:
        for i, task in enumerate(tasks):
            outputs[i] = run_task(task)
            failed += bool(outputs[i]["error"])
            if bar:
                bar.update(i + 1, failed)
        return outputs
    futures = {executor.submit(run_task, task): i for i, task in enumerate(tasks)}
    for done, fut in enumerate(as_completed(futures), start=1):
        i = futures[fut]
        try:
            outputs[i] = fut.result()
        except Exception as exc:  # noqa: BLE001 -- a dead worker fails its case, not the sweep
            outputs[i] = {"error": f"{type(exc).__name__}: {exc}"}
        failed += bool(outputs[i]["error"])
        if bar:
            bar.update(done, failed)
    return outputs


_RUN_COLUMNS = ("final_contraction_m", "peak_contraction_m", "error_m", "at_rest", "final_mode",
                "last_second_peak_to_peak_m", "frequency_Hz", "damping_ratio", "n_half_cycles", "failure")


def _case_row(spec: SweepSpec, i: int, case: SweepCase, by_key: Mapping) -> dict:
    """One summary row: inputs, static analysis, measurement, and each friction model's run."""
    params = spec.base.parameters
    model = spec.case_scenario(case, spec.friction_models[0]).build_model()
    p_Pa = case.pressure_bar * PA_PER_BAR
    x_eq = static_report(params, model.static_force, p_Pa, case.weight_N)["equilibrium_contraction_m"]
    row = {"case": case.name, "weight_N": case.weight_N, "pressure_bar": case.pressure_bar,
           "pressure_step_bar": case.pressure_step_bar, "pressure_stable_bar": case.pressure_stable_bar,
           "measured_contraction_m": case.measured_contraction_m, "equilibrium_contraction_m": x_eq,
           "equilibrium_error_m": x_eq - case.measured_contraction_m,
           "within_capability": bool(x_eq >= spec.capability_min_equilibrium_m)}
    for n, f in enumerate(spec.friction_models):
        friction = spec.case_scenario(case, f).build_model().friction
        lo, hi = friction_band_m(model.static_force, friction, p_Pa, model.load.mass_kg, model.load.g_m_s2,
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
