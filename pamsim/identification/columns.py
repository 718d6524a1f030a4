"""Measurement files for identification: CSV with a header row, ``#`` comment lines, and
columns that carry their unit in their name.

Static data need a pressure (``_bar``, ``_Pa``, ``_kPa`` or ``_psi``, gauge), a contraction
(``_mm`` or ``_m``) and a force (``force_N``, measured pull) or a hung weight (``weight_N``).
Traces need ``t_s``, a contraction and optionally a pressure and a ``weight_N``.
Other column names are mapped with ``columns={"pressure": "my_column_bar", ...}``; the mapped
column must still end in a unit suffix.  Everything is converted to SI here, at the edge.
"""

from __future__ import annotations

import hashlib
import io
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..errors import InputError
from ..table_checks import LENGTH_UNITS_M, PRESSURE_UNITS_PA, unit_column, unit_suffix  # noqa: F401 -- re-exported

QUANTITIES = ("pressure", "contraction", "force", "weight", "time", "sigma")
SIGMA_UNITS = {**LENGTH_UNITS_M, "_N": 1.0}
"""Suffixes of a static file's ``sigma`` column: the standard deviation of each test's contraction (``_mm``,
``_m``: the contraction objective's residual) or of its force (``_N``: the force objective's)."""


class DataError(InputError):
    """A measurement file that cannot be used; the message names the file, the column and the value."""


@dataclass(frozen=True)
class StaticData:
    """Static tests: one row per test, SI units.

    ``load_N`` is the measured pull (``kind == "force"``) or the hung weight (``kind == "weight"``).
    """

    pressure_gauge_Pa: np.ndarray
    contraction_m: np.ndarray
    load_N: np.ndarray
    kind: str
    origin: str = "<arrays>"
    sha256: str = ""
    columns: tuple[tuple[str, float], ...] = (("pressure_gauge_Pa", 1.0), ("contraction_m", 1.0), ("load_N", 1.0))
    """The file's column of the pressure, the contraction and the load (and of ``sigma``, if given), each with its
    factor to SI."""
    sigma: np.ndarray | None = None
    """Per test, the standard deviation [m or N, by ``sigma_kind``] of its measurement: the fit weighs each
    residual by its inverse (weighted least squares; relative, the residual variance scales them)."""
    sigma_kind: str = ""
    """``contraction`` or ``force``: what ``sigma`` is the standard deviation of."""

    def __len__(self) -> int:
        return len(self.load_N)

    def subset(self, rows) -> "StaticData":
        """The tests at ``rows`` (indices or a boolean mask)."""
        return replace(self, pressure_gauge_Pa=self.pressure_gauge_Pa[rows], contraction_m=self.contraction_m[rows],
                       load_N=self.load_N[rows], sigma=None if self.sigma is None else self.sigma[rows])


@dataclass(frozen=True)
class TraceData:
    """One step response: time [s], contraction [m], gauge pressure [Pa] if recorded, hung weight [N] if given."""

    t_s: np.ndarray
    x_m: np.ndarray
    p_gauge_Pa: np.ndarray | None
    weight_N: float | None
    origin: str = "<arrays>"
    sha256: str = ""
    columns: tuple[tuple[str, float], ...] = (("t_s", 1.0), ("x_m", 1.0), ("p_gauge_Pa", 1.0))
    """The file's column of the time, the contraction and the pressure, each with its factor to SI."""

    def window(self, t0_s: float, t1_s: float) -> np.ndarray:
        """Boolean mask of the samples inside ``[t0_s, t1_s]``."""
        return (self.t_s >= t0_s) & (self.t_s <= t1_s)


def _table(path: Path) -> tuple[list[str], np.ndarray, str]:
    """Header names, the numeric rows and the SHA-256 of the file."""
    raw, text = _file_text(path)
    lines = _content_lines(path, text)
    header = [h.strip() for h in lines[0][1].split(",")]
    rows = [_numbers(path, n, line, header) for n, line in lines[1:]]
    if not rows:
        raise DataError(f"{path}: no data rows below the header")
    return header, np.array(rows, dtype=float), hashlib.sha256(raw).hexdigest()


def _file_text(path: Path) -> tuple[bytes, str]:
    """The file's bytes (hashed as they are) and its text, refused if it cannot be read or is not UTF-8."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise DataError(f"{path}: cannot read it: {exc.strerror or exc}") from None
    try:
        return raw, raw.decode()
    except UnicodeDecodeError:
        raise DataError(f"{path}: not a text (UTF-8) CSV file") from None


def _content_lines(path: Path, text: str) -> list[tuple[int, str]]:
    """The lines that are neither blank nor ``#`` comments, with their line numbers; the first is the header."""
    lines = [(n, line) for n, line in enumerate(text.splitlines(), start=1) if line.strip() and not line.startswith("#")]
    if not lines:
        raise DataError(f"{path}: no header row (the file is empty or only comments)")
    return lines


def _numbers(path: Path, n: int, line: str, header: Sequence[str]) -> list[float]:
    """Data line ``n``'s values: as many fields as the ``header`` has, each a number."""
    cells = line.split(",")
    if len(cells) != len(header):
        raise DataError(f"{path}: line {n} has {len(cells)} fields, the header has {len(header)}")
    try:
        return [float(c) for c in cells]
    except ValueError:
        column, bad = next((h, c) for h, c in zip(header, cells) if not _is_number(c))
        raise DataError(f"{path}: line {n}, column {column.strip()!r}: value {bad.strip()!r} is not a number") from None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _unit_column(path: Path, header: list[str], quantity: str, units: Mapping[str, float], stems: tuple[str, ...],
                 columns: Mapping[str, str], required: bool = True) -> tuple[str, float] | None:
    """The column holding ``quantity`` and its factor to SI: the mapped name, or the first column whose
    name starts with one of ``stems`` and ends with one of ``units``."""
    if quantity in columns:
        name = columns[quantity]
        if name not in header:
            raise DataError(f"{path}: --columns {quantity}={name}: no such column (columns: {', '.join(header)})")
        suffix = unit_suffix(name, units)
        if suffix is None:
            raise DataError(f"{path}: --columns {quantity}={name}: the name must end in a unit "
                            f"({', '.join(units)})")
        return name, units[suffix]
    found = unit_column(header, stems, units)
    if found is not None:
        return found
    if required:
        want = " or ".join(f"{s}*" for s in stems)
        raise DataError(f"{path}: no {quantity} column: need {want} ending in {' / '.join(units)} "
                        f"(columns: {', '.join(header)}; map another with --columns {quantity}=NAME)")
    return None


def _check_columns_map(columns: Mapping[str, str], path: Path) -> None:
    for key in columns:
        if key not in QUANTITIES:
            raise DataError(f"{path}: --columns {key}=...: unknown quantity (choose from {', '.join(QUANTITIES)})")


def _finite(path: Path, name: str, values: np.ndarray) -> np.ndarray:
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise DataError(f"{path}: column {name}, data row {int(bad[0]) + 1}: value {values[bad[0]]} is not finite")
    return values


def read_static_data(path: str | Path, columns: Mapping[str, str] | None = None) -> StaticData:
    """Read static tests (pressure, contraction, force or weight) from a CSV file.

    Parameters
    ----------
    path : str or Path
        CSV file with a header row; ``#`` lines are comments.
    columns : mapping, optional
        ``{"pressure" | "contraction" | "force" | "weight": column name}`` for columns that are not
        found by their standard names.  A pressure column named ``pressure_stable_bar`` is
        preferred over other pressure columns (the ACRA tables record the stable pressure).

    Returns
    -------
    StaticData
    """
    path = Path(path)
    columns = dict(columns or {})
    _check_columns_map(columns, path)
    header, rows, digest = _table(path)
    if "pressure" not in columns and "pressure_stable_bar" in header:
        columns["pressure"] = "pressure_stable_bar"
    p_col, p_k = _unit_column(path, header, "pressure", PRESSURE_UNITS_PA, ("pressure", "p_"), columns)
    x_col, x_k = _unit_column(path, header, "contraction", LENGTH_UNITS_M, ("contraction", "x_"), columns)
    force = _unit_column(path, header, "force", {"_N": 1.0}, ("force",), columns, required=False)
    weight = _unit_column(path, header, "weight", {"_N": 1.0}, ("weight",), columns, required=False)
    if (force is None) == (weight is None):
        raise DataError(f"{path}: need exactly one of a force_N column (measured pull) or a weight_N column "
                        f"(hung weight); columns: {', '.join(header)}")
    (l_col, _), kind = (force, "force") if force is not None else (weight, "weight")
    p = _finite(path, p_col, rows[:, header.index(p_col)] * p_k)
    x = _finite(path, x_col, rows[:, header.index(x_col)] * x_k)
    load = _finite(path, l_col, rows[:, header.index(l_col)])
    if kind == "weight" and np.any(load <= 0):
        i = int(np.flatnonzero(load <= 0)[0])
        raise DataError(f"{path}: column {l_col}, data row {i + 1}: value {load[i]:g} must be positive")
    cols = ((p_col, p_k), (x_col, x_k), (l_col, 1.0))
    sigma = _unit_column(path, header, "sigma", SIGMA_UNITS, ("sigma",), columns, required=False)
    if sigma is None:
        return StaticData(p, x, load, kind, str(path), digest, cols)
    values = _positive(path, sigma[0], _finite(path, sigma[0], rows[:, header.index(sigma[0])]))
    return StaticData(p, x, load, kind, str(path), digest, (*cols, sigma), values * sigma[1],
                      "force" if sigma[0].endswith("_N") else "contraction")


def _positive(path: Path, name: str, values: np.ndarray) -> np.ndarray:
    """``values``, refused where one is not positive (a standard deviation is)."""
    bad = np.flatnonzero(~(values > 0))
    if bad.size:
        raise DataError(f"{path}: column {name}, data row {int(bad[0]) + 1}: value {values[bad[0]]:g} must be "
                        "positive (a standard deviation)")
    return values


def read_trace(path: str | Path, columns: Mapping[str, str] | None = None) -> TraceData:
    """Read one step response: ``t_s``, a contraction, optionally a gauge pressure and ``weight_N``.

    The weight column, if present, must hold one value (the load of the whole trace).
    """
    path = Path(path)
    columns = dict(columns or {})
    _check_columns_map(columns, path)
    header, rows, digest = _table(path)
    t_col, _ = _unit_column(path, header, "time", {"_s": 1.0}, ("t_", "time"), columns)
    x_col, x_k = _unit_column(path, header, "contraction", LENGTH_UNITS_M, ("x_", "contraction"), columns)
    p = _unit_column(path, header, "pressure", PRESSURE_UNITS_PA, ("p_", "pressure"), columns, required=False)
    w = _unit_column(path, header, "weight", {"_N": 1.0}, ("weight",), columns, required=False)
    t = _finite(path, t_col, rows[:, header.index(t_col)])
    x = _finite(path, x_col, rows[:, header.index(x_col)] * x_k)
    if len(t) < 3:
        raise DataError(f"{path}: a trace needs at least three rows, got {len(t)}")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        raise DataError(f"{path}: column {t_col}, data row {int(bad[0]) + 2}: time {t[bad[0] + 1]:g} does not "
                        f"increase (previous {t[bad[0]]:g})")
    p_Pa = None if p is None else _finite(path, p[0], rows[:, header.index(p[0])] * p[1])
    weight = None
    if w is not None:
        values = _finite(path, w[0], rows[:, header.index(w[0])])
        if not np.all(values == values[0]) or not values[0] > 0:
            raise DataError(f"{path}: column {w[0]}: value {values[0]:g}: the hung weight must be one positive "
                            "value for the whole trace")
        weight = float(values[0])
    cols = ((t_col, 1.0), (x_col, x_k), (p if p is not None else ("p_gauge_Pa", 1.0)))
    return TraceData(t, x, p_Pa, weight, str(path), digest, cols)


def write_trace_csv(trace: TraceData, path: str | Path) -> None:
    """Write a trace in the format :func:`read_trace` reads (SI columns)."""
    cols = {"t_s": trace.t_s, "x_m": trace.x_m}
    if trace.p_gauge_Pa is not None:
        cols["p_gauge_Pa"] = trace.p_gauge_Pa
    if trace.weight_N is not None:
        cols["weight_N"] = np.full_like(trace.t_s, trace.weight_N)
    buf = io.StringIO()
    np.savetxt(buf, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols), comments="",
               fmt="%.10g")
    Path(path).write_text(buf.getvalue())


__all__ = ["StaticData", "TraceData", "DataError", "read_static_data", "read_trace", "write_trace_csv",
           "PRESSURE_UNITS_PA", "LENGTH_UNITS_M"]
