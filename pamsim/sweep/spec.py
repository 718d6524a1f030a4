"""Sweep files: reading and validating them into a :class:`SweepSpec`.

A sweep file (TOML) names a base scenario, the cases (axes of pressure and
load, an explicit list, or one case per row of a measured-data CSV), the
friction models to run every case with, and optionally a frequency study and
a set of scenarios whose time responses are plotted.  The format is described
in ``docs/validation.md`` and ``scenarios/acra2012_grid.toml``.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from ..elements.friction import FRICTION_MODELS
from ..errors import InputError
from ..scenario import Scenario, load_scenario, read_toml
from ..scenario_components import refuse_added
from ..table_checks import TableChecker
from .uncertainty import UncertaintySpec, parse_uncertainty

_TOP_KEYS = {"name", "description", "base_scenario", "friction_models", "capability_min_equilibrium_mm",
             "backend", "measured", "cases", "axes", "case", "frequency", "time_responses", "uncertainty"}
_MEASURED_KEYS = {"file", "weight_column", "pressure_column", "contraction_column", "nominal_pressure_column"}
_AXES = {"pressure_bar", "weight_N"}
_FREQUENCY_KEYS = {"pressure_bar", "weight_N", "pressure"}
_MEASURED_DEFAULTS = {"weight_column": "weight_N", "pressure_column": "pressure_stable_bar",
                      "contraction_column": "contraction_stable_mm", "nominal_pressure_column": "pressure_step_bar"}
_MATCH_TOL_BAR = 1e-6
_MATCH_TOL_N = 1e-6


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
    backend: str = "python"
    """The backend that runs every case (:data:`pamsim.backends.BACKENDS`); ``pamsim sweep --backend`` overrides it."""
    uncertainty: UncertaintySpec | None = None

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
    check = TableChecker(origin, SweepError, "sweep")
    check.check_keys("the top level", "", spec, _TOP_KEYS)
    base_name = check.required(spec, "base_scenario", str)
    base = load_scenario(_resolve(base_dir, base_name))
    refuse_added(base, "a sweep's static analysis", SweepError, lines_allowed=True)
    frictions = _friction_models(check, spec.get("friction_models", [base.spec["model"]["friction"]]))
    threshold_mm = check.number("capability_min_equilibrium_mm", spec.get("capability_min_equilibrium_mm", 5.0))
    measured = _read_measured(check, base_dir, spec["measured"]) if "measured" in spec else None
    uncertainty = parse_uncertainty(check, spec["uncertainty"], base) if "uncertainty" in spec else None
    # An uncertainty study samples the base scenario itself and needs no cases.
    no_cases = uncertainty is not None and not any(k in spec for k in ("cases", "axes", "case"))
    cases = () if no_cases else _cases(check, spec, measured)
    frequency = _frequency(check, spec["frequency"]) if "frequency" in spec else None
    responses = _time_responses(check, base_dir, spec["time_responses"]) if "time_responses" in spec else ()
    result = SweepSpec(check.typed("name", spec.get("name", default_name), str),
                       check.typed("description", spec.get("description", ""), str), origin, base, cases,
                       frictions, threshold_mm * 1e-3, frequency, responses,
                       _backend(check, spec.get("backend", "python")), uncertainty)
    _build_every_scenario(result)
    return result


def _friction_models(check: TableChecker, names: Any) -> tuple[str, ...]:
    frictions = tuple(check.typed("friction_models", names, list))
    if not frictions:
        raise SweepError(f"{check.origin}: friction_models = []: name at least one friction model")
    for f in frictions:
        if not isinstance(f, str) or f not in FRICTION_MODELS:
            check.fail("friction_models", f, "unknown friction model", FRICTION_MODELS)
    return frictions


def _time_responses(check: TableChecker, base_dir: Path, table: Any) -> tuple[Scenario, ...]:
    """The scenarios ``[time_responses]`` names, read and validated."""
    check.check_keys("[time_responses]", "time_responses.", table, {"scenarios"})
    names = check.required(table, "scenarios", list, "time_responses.")
    return tuple(load_scenario(_resolve(base_dir, check.typed("time_responses.scenarios", n, str))) for n in names)


def _build_every_scenario(spec: SweepSpec) -> None:
    """Build every case's scenario once, so that a bad value (a pressure above the rating...) fails before the run."""
    first = spec.friction_models[0]
    try:
        for case in spec.cases:
            spec.case_scenario(case, first)
        if spec.frequency is not None:
            for w in spec.frequency.weights_N:
                spec.frequency_scenario(w, first)
    except SweepError:
        raise
    except InputError as exc:  # a ScenarioError names the base file; say which sweep produced the value
        raise SweepError(f"{spec.origin}: a case does not make a valid scenario: {exc}") from None


def _backend(check: TableChecker, name: Any) -> str:
    from ..backends import BACKENDS

    if name not in BACKENDS:
        check.fail("backend", name, "unknown backend", BACKENDS)
    return name


def _cases(check: TableChecker, spec: Mapping[str, Any], measured: list[dict] | None) -> tuple[SweepCase, ...]:
    """The cases of the one table that lists them: ``[cases]``, ``[axes]`` or ``[[case]]``."""
    given = [k for k in ("cases", "axes", "case") if k in spec]
    if len(given) != 1:
        raise SweepError(f"{check.origin}: give exactly one of [cases] from_measured = true, [axes] or [[case]] "
                         f"(found {', '.join(given) or 'none'})")
    if "cases" in spec:
        return _cases_from_measured(check, spec["cases"], measured)
    pairs = _axes_pairs(check, spec["axes"]) if "axes" in spec else _listed_pairs(check, spec["case"])
    _check_loads_and_pressures(check, pairs)
    return tuple(_named(w, p, measured or []) for w, p in pairs)


def _check_loads_and_pressures(check: TableChecker, pairs: list[tuple[float, float]]) -> None:
    for w, p in pairs:
        if w <= 0:
            check.fail("weight_N", w, "must be positive")
        if p < 0:
            check.fail("pressure_bar", p, "must not be negative")


def _cases_from_measured(check: TableChecker, table: Any, measured: list[dict] | None) -> tuple[SweepCase, ...]:
    """``[cases] from_measured = true``: one case per measured row, at its load and stable pressure."""
    check.check_keys("[cases]", "cases.", table, {"from_measured"})
    if table.get("from_measured") is not True:
        check.fail("cases.from_measured", table.get("from_measured"), "must be true (or use [axes] / [[case]])")
    if measured is None:
        raise SweepError(f"{check.origin}: cases.from_measured = true needs a [measured] file")
    return tuple(_named(row["weight_N"], row["pressure_stable_bar"], measured) for row in measured)


def _axes_pairs(check: TableChecker, axes: Any) -> list[tuple[float, float]]:
    """``[axes]``: every (weight, pressure) of the two axes, pressure by pressure."""
    check.check_keys("[axes]", "axes.", axes, _AXES, what="axis")
    values = {}
    for axis in sorted(_AXES):
        if axis not in axes:
            raise SweepError(f"{check.origin}: missing axis axes.{axis} "
                             "(the sweep varies both pressure_bar and weight_N)")
        values[axis] = check.number_list(f"axes.{axis}", axes[axis])
    return [(w, p) for p in values["pressure_bar"] for w in values["weight_N"]]


def _listed_pairs(check: TableChecker, rows: Any) -> list[tuple[float, float]]:
    """``[[case]]``: the (weight, pressure) of each table."""
    if not isinstance(rows, list) or not rows:
        check.fail("case", rows, "must be a non-empty array of tables [[case]]")
    pairs = []
    for i, row in enumerate(rows):
        where = f"case[{i}]."
        check.check_keys(f"[[case]] number {i + 1}", where, row, _AXES)
        pairs.append((check.positive(where + "weight_N", check.required(row, "weight_N", float, where)),
                      check.number(where + "pressure_bar", check.required(row, "pressure_bar", float, where))))
    return pairs


def _named(weight_N: float, pressure_bar: float, measured: list[dict]) -> SweepCase:
    """A case, with the measured row of the same load and stable pressure if there is one."""
    row = next((r for r in measured if abs(r["weight_N"] - weight_N) <= _MATCH_TOL_N
                and abs(r["pressure_stable_bar"] - pressure_bar) <= _MATCH_TOL_BAR), None)
    name = f"{pressure_bar:g}bar_{weight_N:g}N"
    if row is None:
        return SweepCase(name, weight_N, pressure_bar)
    return SweepCase(name, weight_N, pressure_bar, row["contraction_mm"] * 1e-3, row["pressure_stable_bar"],
                     row.get("pressure_step_bar", math.nan))


def _frequency(check: TableChecker, table: Any) -> FrequencyStudy:
    check.check_keys("[frequency]", "frequency.", table, _FREQUENCY_KEYS)
    pressure = check.number("frequency.pressure_bar", check.required(table, "pressure_bar", float, "frequency."))
    weights = check.number_list("frequency.weight_N", check.required(table, "weight_N", list, "frequency."))
    for w in weights:
        if w <= 0:
            check.fail("frequency.weight_N", w, "must be positive")
    ptable = table.get("pressure")
    if ptable is not None and not isinstance(ptable, dict):
        check.fail("frequency.pressure", ptable, "must be a table (it replaces the base scenario's [pressure])")
    return FrequencyStudy(pressure, tuple(weights), ptable)


def _read_measured(check: TableChecker, base_dir: Path, table: Any) -> list[dict]:
    """Rows ``{weight_N, pressure_stable_bar, contraction_mm[, pressure_step_bar]}`` of the measured CSV."""
    check.check_keys("[measured]", "measured.", table, _MEASURED_KEYS)
    name = check.required(table, "file", str, "measured.")
    path = _resolve(base_dir, name)
    if not path.is_file():
        check.fail("measured.file", name, f"no such file ({path})")
    cols = {k: check.typed(f"measured.{k}", table.get(k, d), str) for k, d in _MEASURED_DEFAULTS.items()}
    reader = csv.DictReader(_data_lines(check, name, path))
    header = reader.fieldnames or []
    required = [cols["weight_column"], cols["pressure_column"], cols["contraction_column"]]
    missing = [c for c in required if c not in header]
    if missing:
        raise SweepError(f"{check.origin}: measured.file = {name!r}: columns {', '.join(missing)} not found "
                         f"(its columns: {', '.join(header)}; set measured.weight_column, pressure_column, "
                         "contraction_column)")
    where = f"{check.origin}: measured.file = {name!r}: data row"
    rows = [_measured_row(raw, cols, header, f"{where} {k}") for k, raw in enumerate(reader, start=1)]
    if not rows:
        check.fail("measured.file", name, "has no data rows")
    return rows


def _data_lines(check: TableChecker, name: str, path: Path) -> list[str]:
    """The CSV's header and data lines, without blank lines and ``#`` comments."""
    try:
        lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as exc:
        check.fail("measured.file", name, f"cannot read: {exc}")
    if not lines:
        check.fail("measured.file", name, "has no header row")
    return lines


def _measured_row(raw: Mapping[str, str], cols: Mapping[str, str], header: list[str], where: str) -> dict:
    """One data row of the measured CSV as finite numbers under the sweep's own names; ``where`` names the
    row in an error."""
    try:
        row = {"weight_N": float(raw[cols["weight_column"]]),
               "pressure_stable_bar": float(raw[cols["pressure_column"]]),
               "contraction_mm": float(raw[cols["contraction_column"]])}
        if cols["nominal_pressure_column"] in header:
            row["pressure_step_bar"] = float(raw[cols["nominal_pressure_column"]])
    except (TypeError, ValueError):
        raise SweepError(f"{where} is not numeric: {dict(raw)}") from None
    if not all(math.isfinite(v) for v in row.values()):
        raise SweepError(f"{where} has a non-finite value")
    return row


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


def _resolve(base_dir: Path, name: str) -> Path:
    p = Path(name)
    return p if p.is_absolute() else base_dir / p
