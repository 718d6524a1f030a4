"""Parameter sweeps: many cases of one base scenario, compared with measured steady states.

A sweep file (TOML) names a base scenario, the cases (axes of pressure and
load, an explicit list, or one case per row of a measured-data CSV), the
friction models to run every case with, and optionally a frequency study and
a set of scenarios whose time responses are plotted.  The format is described
in ``docs/validation.md`` and ``scenarios/acra2012_grid.toml``.

:func:`sweep` runs the cases on any :class:`concurrent.futures.Executor`
(a process pool, or ``distributed.Client(...).get_executor()``); a failed
case is recorded, not raised.  :meth:`SweepResult.write` writes
``summary.csv``, ``report.md`` and the figures atomically.
"""

from __future__ import annotations

import csv
import difflib
import math
import sys
import time
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .atomic import atomic_outputs
from .constants import PA_PER_BAR
from .elements.friction import FRICTION_MODELS, build_friction
from .elements.stops import EndStops
from .errors import InputError
from .oscillation import estimate_oscillation
from .scenario import Scenario, load_scenario, read_toml
from .static import friction_band_m, static_report

SETTLED_FRACTION = 0.05
"""The pressure counts as settled once it stays within 5 % of its step of its final value; the
oscillation is estimated from then on, so creep driven by a still-rising pressure is not counted."""

_TOP_KEYS = {"name", "description", "base_scenario", "friction_models", "capability_min_equilibrium_mm",
             "measured", "cases", "axes", "case", "frequency", "time_responses"}
_MEASURED_KEYS = {"file", "weight_column", "pressure_column", "contraction_column", "nominal_pressure_column"}
_AXES = {"pressure_bar", "weight_N"}
_FREQUENCY_KEYS = {"pressure_bar", "weight_N", "pressure"}
_MEASURED_DEFAULTS = {"weight_column": "weight_N", "pressure_column": "pressure_stable_bar",
                      "contraction_column": "contraction_stable_mm", "nominal_pressure_column": "pressure_step_bar"}
_MATCH_TOL_BAR = 1e-6
_MATCH_TOL_N = 1e-6

FIGURES = ("error_heatmap.png", "steady_state_vs_pressure.png", "time_responses.png", "frequency_vs_load.png")


class SweepError(InputError):
    """A sweep file that cannot be run; the message names the file, the key and the value."""


@dataclass(frozen=True)
class SweepCase:
    """One case of the sweep: a load stepped to a pressure, with its measurement if known."""

    name: str
    weight_N: float
    pressure_bar: float
    measured_contraction_m: float = math.nan
    pressure_stable_bar: float = math.nan
    pressure_step_bar: float = math.nan


@dataclass(frozen=True)
class FrequencyStudy:
    """Loads run at one pressure, with their own pressure source, to compare oscillation frequencies."""

    pressure_bar: float
    weights_N: tuple[float, ...]
    pressure_table: Mapping[str, Any] | None


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep file.  Build one with :func:`load_sweep`."""

    name: str
    description: str
    origin: str
    base: Scenario
    cases: tuple[SweepCase, ...]
    friction_models: tuple[str, ...]
    capability_min_equilibrium_m: float
    frequency: FrequencyStudy | None = None
    time_responses: tuple[Scenario, ...] = ()

    def case_scenario(self, case: SweepCase, friction: str) -> Scenario:
        """The base scenario with the case's load and pressure and the given friction model."""
        return _with_case(self.base, case.weight_N, case.pressure_bar, friction, f"{case.name}_{friction}",
                          self.origin)

    def frequency_scenario(self, weight_N: float, friction: str) -> Scenario:
        """The frequency study's scenario for one load and friction model."""
        study = self.frequency
        base = self.base
        if study.pressure_table is not None:
            spec = {**base.spec, "pressure": dict(study.pressure_table)}
            base = Scenario.from_dict(spec, base.name, base.base_dir, f"{self.origin} [frequency.pressure]")
        return _with_case(base, weight_N, study.pressure_bar, friction,
                          f"freq_{study.pressure_bar:g}bar_{weight_N:g}N_{friction}", self.origin)


# ---------------------------------------------------------------- loading
def load_sweep(path: str | Path) -> SweepSpec:
    """Read and validate a sweep file; every mistake raises :class:`SweepError` (exit code 2).

    Parameters
    ----------
    path : str or Path
        The sweep TOML file; relative paths inside it are relative to its folder.

    Returns
    -------
    SweepSpec
        Every case scenario has been built once, so a bad value fails here,
        before anything runs.
    """
    path = Path(path)
    spec = read_toml(path, "sweep", SweepError)
    return sweep_from_dict(spec, base_dir=path.parent, origin=str(path), default_name=path.stem)


def sweep_from_dict(spec: Mapping[str, Any], base_dir: str | Path = ".", origin: str = "<dict>",
                    default_name: str = "sweep") -> SweepSpec:
    """Validate a sweep given as a dict (the structure of the TOML file)."""
    base_dir = Path(base_dir)
    _check_keys(origin, "the top level", "", spec, _TOP_KEYS)
    base_name = _required(origin, spec, "base_scenario", str)
    base = load_scenario(_resolve(base_dir, base_name))
    frictions = tuple(_typed(origin, "friction_models", spec.get("friction_models", [base.spec["model"]["friction"]]),
                             list))
    if not frictions:
        raise SweepError(f"{origin}: friction_models = []: name at least one friction model")
    for f in frictions:
        if f not in FRICTION_MODELS:
            _fail(origin, "friction_models", f, "unknown friction model", FRICTION_MODELS)
    threshold_mm = _number(origin, "capability_min_equilibrium_mm", spec.get("capability_min_equilibrium_mm", 5.0))
    measured = _read_measured(origin, base_dir, spec["measured"]) if "measured" in spec else None
    cases = _cases(origin, spec, measured)
    frequency = _frequency(origin, spec["frequency"]) if "frequency" in spec else None
    responses = ()
    if "time_responses" in spec:
        table = spec["time_responses"]
        _check_keys(origin, "[time_responses]", "time_responses.", table, {"scenarios"})
        names = _required(origin, table, "scenarios", list, "time_responses.")
        responses = tuple(load_scenario(_resolve(base_dir, _typed(origin, "time_responses.scenarios", n, str)))
                          for n in names)
    result = SweepSpec(_typed(origin, "name", spec.get("name", default_name), str),
                       _typed(origin, "description", spec.get("description", ""), str), origin, base, cases,
                       frictions, threshold_mm * 1e-3, frequency, responses)
    # Build every scenario once so a bad value (a pressure above the rating...) fails before the run.
    try:
        for case in cases:
            result.case_scenario(case, frictions[0])
        if frequency is not None:
            for w in frequency.weights_N:
                result.frequency_scenario(w, frictions[0])
    except SweepError:
        raise
    except InputError as exc:  # a ScenarioError names the base file; say which sweep produced the value
        raise SweepError(f"{origin}: a case does not make a valid scenario: {exc}") from None
    return result


def _cases(origin: str, spec: Mapping[str, Any], measured: list[dict] | None) -> tuple[SweepCase, ...]:
    given = [k for k in ("cases", "axes", "case") if k in spec]
    if len(given) != 1:
        raise SweepError(f"{origin}: give exactly one of [cases] from_measured = true, [axes] or [[case]] "
                         f"(found {', '.join(given) or 'none'})")
    if "cases" in spec:
        table = spec["cases"]
        _check_keys(origin, "[cases]", "cases.", table, {"from_measured"})
        if table.get("from_measured") is not True:
            _fail(origin, "cases.from_measured", table.get("from_measured"), "must be true (or use [axes] / [[case]])")
        if measured is None:
            raise SweepError(f"{origin}: cases.from_measured = true needs a [measured] file")
        return tuple(_named(row["weight_N"], row["pressure_stable_bar"], measured) for row in measured)
    if "axes" in spec:
        axes = spec["axes"]
        _check_keys(origin, "[axes]", "axes.", axes, _AXES, what="axis")
        values = {}
        for axis in sorted(_AXES):
            if axis not in axes:
                raise SweepError(f"{origin}: missing axis axes.{axis} (the sweep varies both pressure_bar and weight_N)")
            values[axis] = _number_list(origin, f"axes.{axis}", axes[axis])
        pairs = [(w, p) for p in values["pressure_bar"] for w in values["weight_N"]]
    else:
        rows = spec["case"]
        if not isinstance(rows, list) or not rows:
            _fail(origin, "case", rows, "must be a non-empty array of tables [[case]]")
        pairs = []
        for i, row in enumerate(rows):
            where = f"case[{i}]."
            _check_keys(origin, f"[[case]] number {i + 1}", where, row, _AXES)
            pairs.append((_positive(origin, where + "weight_N", _required(origin, row, "weight_N", float, where)),
                          _number(origin, where + "pressure_bar", _required(origin, row, "pressure_bar", float, where))))
    for w, p in pairs:
        if w <= 0:
            _fail(origin, "weight_N", w, "must be positive")
        if p < 0:
            _fail(origin, "pressure_bar", p, "must not be negative")
    return tuple(_named(w, p, measured or []) for w, p in pairs)


def _named(weight_N: float, pressure_bar: float, measured: list[dict]) -> SweepCase:
    """A case, with the measured row of the same load and stable pressure if there is one."""
    row = next((r for r in measured if abs(r["weight_N"] - weight_N) <= _MATCH_TOL_N
                and abs(r["pressure_stable_bar"] - pressure_bar) <= _MATCH_TOL_BAR), None)
    name = f"{pressure_bar:g}bar_{weight_N:g}N"
    if row is None:
        return SweepCase(name, weight_N, pressure_bar)
    return SweepCase(name, weight_N, pressure_bar, row["contraction_mm"] * 1e-3, row["pressure_stable_bar"],
                     row.get("pressure_step_bar", math.nan))


def _frequency(origin: str, table: Any) -> FrequencyStudy:
    _check_keys(origin, "[frequency]", "frequency.", table, _FREQUENCY_KEYS)
    pressure = _number(origin, "frequency.pressure_bar", _required(origin, table, "pressure_bar", float, "frequency."))
    weights = _number_list(origin, "frequency.weight_N", _required(origin, table, "weight_N", list, "frequency."))
    for w in weights:
        if w <= 0:
            _fail(origin, "frequency.weight_N", w, "must be positive")
    ptable = table.get("pressure")
    if ptable is not None and not isinstance(ptable, dict):
        _fail(origin, "frequency.pressure", ptable, "must be a table (it replaces the base scenario's [pressure])")
    return FrequencyStudy(pressure, tuple(weights), ptable)


def _read_measured(origin: str, base_dir: Path, table: Any) -> list[dict]:
    """Rows ``{weight_N, pressure_stable_bar, contraction_mm[, pressure_step_bar]}`` of the measured CSV."""
    _check_keys(origin, "[measured]", "measured.", table, _MEASURED_KEYS)
    name = _required(origin, table, "file", str, "measured.")
    path = _resolve(base_dir, name)
    if not path.is_file():
        _fail(origin, "measured.file", name, f"no such file ({path})")
    cols = {k: _typed(origin, f"measured.{k}", table.get(k, d), str) for k, d in _MEASURED_DEFAULTS.items()}
    try:
        lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as exc:
        _fail(origin, "measured.file", name, f"cannot read: {exc}")
    if not lines:
        _fail(origin, "measured.file", name, "has no header row")
    reader = csv.DictReader(lines)
    header = reader.fieldnames or []
    required = [cols["weight_column"], cols["pressure_column"], cols["contraction_column"]]
    missing = [c for c in required if c not in header]
    if missing:
        raise SweepError(f"{origin}: measured.file = {name!r}: columns {', '.join(missing)} not found "
                         f"(its columns: {', '.join(header)}; set measured.weight_column, pressure_column, "
                         "contraction_column)")
    rows = []
    for line_no, raw in enumerate(reader, start=2):
        try:
            row = {"weight_N": float(raw[cols["weight_column"]]),
                   "pressure_stable_bar": float(raw[cols["pressure_column"]]),
                   "contraction_mm": float(raw[cols["contraction_column"]])}
            if cols["nominal_pressure_column"] in header:
                row["pressure_step_bar"] = float(raw[cols["nominal_pressure_column"]])
        except (TypeError, ValueError):
            raise SweepError(f"{origin}: measured.file = {name!r}: data row {line_no - 1} is not numeric: "
                             f"{dict(raw)}") from None
        if not all(math.isfinite(v) for v in row.values()):
            raise SweepError(f"{origin}: measured.file = {name!r}: data row {line_no - 1} has a non-finite value")
        rows.append(row)
    if not rows:
        _fail(origin, "measured.file", name, "has no data rows")
    return rows


def _with_case(base: Scenario, weight_N: float, pressure_bar: float, friction: str, name: str,
               origin: str) -> Scenario:
    """Set the load, final pressure and friction model of ``base``."""
    pr = base.spec["pressure"]
    if pr["source"] == "valve":
        pressure_change = {"supply_gauge_bar": pressure_bar}
    else:
        signal = dict(pr["prescribed"])
        kind = signal["kind"]
        if kind not in ("step", "ramp", "lag", "constant"):
            raise SweepError(f"{origin}: base scenario {base.origin}: cannot set the pressure of a "
                             f"prescribed {kind!r} signal; use a step, ramp, lag or the valve source")
        key = "value" if kind == "constant" else "final"
        signal.pop(f"{key}_gauge_Pa", None)
        signal[f"{key}_gauge_bar"] = pressure_bar
        pressure_change = {"prescribed": signal}
    return base.with_changes({"load": {"weight_N": weight_N}, "pressure": pressure_change,
                              "model": {"friction": friction}}, name=name)


# ---------------------------------------------------------------- validation helpers
def _fail(origin: str, key: str, value: Any, why: str, choices=None):
    msg = f"{origin}: {key} = {value!r}: {why}"
    if choices is not None:
        close = difflib.get_close_matches(str(value), [str(c) for c in choices], n=1)
        msg += f" (did you mean {close[0]!r}?)" if close else f" (choose from {', '.join(map(str, choices))})"
    raise SweepError(msg)


def _check_keys(origin: str, where: str, prefix: str, table: Any, known: set[str], what: str = "key"):
    if not isinstance(table, dict):
        _fail(origin, prefix.rstrip(".") or "sweep", table, "must be a table")
    for key in table:
        if key not in known:
            close = difflib.get_close_matches(key, sorted(known), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else f" (known: {', '.join(sorted(known))})"
            raise SweepError(f"{origin}: unknown {what} {prefix}{key!s} in {where}{hint}")


def _required(origin: str, table: Mapping, key: str, kind: type, prefix: str = ""):
    if key not in table:
        raise SweepError(f"{origin}: missing key {prefix}{key}")
    return _typed(origin, prefix + key, table[key], kind)


def _typed(origin: str, key: str, value: Any, kind: type):
    if kind is float:
        return _number(origin, key, value)
    if not isinstance(value, kind):
        _fail(origin, key, value, f"must be a {kind.__name__}, not {type(value).__name__}")
    return value


def _number(origin: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        _fail(origin, key, value, "must be a finite number")
    return float(value)


def _positive(origin: str, key: str, value: float) -> float:
    if value <= 0:
        _fail(origin, key, value, "must be positive")
    return value


def _number_list(origin: str, key: str, value: Any) -> list[float]:
    if not isinstance(value, list):
        _fail(origin, key, value, "must be a list of numbers")
    if not value:
        _fail(origin, key, value, "is empty: give at least one value")
    return [_number(origin, key, v) for v in value]


def _resolve(base_dir: Path, name: str) -> Path:
    p = Path(name)
    return p if p.is_absolute() else base_dir / p


# ---------------------------------------------------------------- running
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
    from .api import simulate

    try:
        result = simulate(task.scenario)
        t_settled = settled_time_s(result.t_s, result.p_gauge_Pa)
        osc = estimate_oscillation(result.t_s, result.x_m, t_start_s=t_settled)
        out = {"final_contraction_m": float(result.x_m[-1]), "peak_contraction_m": float(result.x_m.max()),
               "at_rest": bool(result.at_rest_at_end), "final_mode": result.final_mode.label,
               "frequency_Hz": osc.frequency_Hz, "damping_ratio": osc.damping_ratio,
               "n_half_cycles": osc.n_half_cycles, "settled_time_s": t_settled,
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
        from .sweep_report import write_report
        from .sweep_plots import write_figures

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


def sweep(spec: SweepSpec | str | Path, executor: Executor | None = None, progress: bool = False) -> SweepResult:
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
                for k in ("frequency_Hz", "damping_ratio", "n_half_cycles", "final_contraction_m",
                          "peak_contraction_m", "at_rest"):
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


_RUN_COLUMNS = ("final_contraction_m", "peak_contraction_m", "error_m", "at_rest", "final_mode", "frequency_Hz",
                "damping_ratio", "n_half_cycles", "failure")


def _case_row(spec: SweepSpec, i: int, case: SweepCase, by_key: Mapping) -> dict:
    """One summary row: inputs, static analysis, measurement, and each friction model's run."""
    params = spec.base.parameters
    static = spec.base.static_model()
    p_Pa = case.pressure_bar * PA_PER_BAR
    x_eq = static_report(params, static, p_Pa, case.weight_N)["equilibrium_contraction_m"]
    x_hi = EndStops.from_parameters(params).x_high_m
    row = {"case": case.name, "weight_N": case.weight_N, "pressure_bar": case.pressure_bar,
           "pressure_step_bar": case.pressure_step_bar, "pressure_stable_bar": case.pressure_stable_bar,
           "measured_contraction_m": case.measured_contraction_m, "equilibrium_contraction_m": x_eq,
           "equilibrium_error_m": x_eq - case.measured_contraction_m,
           "within_capability": bool(x_eq >= spec.capability_min_equilibrium_m)}
    for n, f in enumerate(spec.friction_models):
        friction = build_friction(f, params, spec.base.spec["model"]["friction_negative_level"])
        lo, hi = friction_band_m(static, friction, p_Pa, case.weight_N / params["g_m_s2"], params["g_m_s2"], x_hi)
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
