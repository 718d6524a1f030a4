"""A measured hysteresis loop: a CSV with time, pressure, contraction and force columns, read into SI units.

The loop is a prescribed-length cycle at one pressure: the contraction is the models' input (the test drives
it) and the force their output (the test measures it). Or it was measured at a hanging load, the pressure
cycled and the contraction measured: then the force is derived (:mod:`pamsim.hysteresis.hanging_load`). The
column names carry their units as the other measurement files do (:mod:`pamsim.identification.columns`):
``t_s``, a pressure (``p_*`` or ``pressure*`` ending in ``_Pa``, ``_kPa``, ``_bar`` or ``_psi``), a
contraction (``x_*`` or ``contraction*`` ending in ``_m`` or ``_mm``) and ``force_N`` (not read at a hanging
load).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from ..identification.columns import (LENGTH_UNITS_M, PRESSURE_UNITS_PA, DataError, _check_columns_map, _finite,
                                      _table, _unit_column)
from ..table_checks import unit_columns
from .play import reversals

MIN_ROWS = 20
"""Fewest samples of a loop: two reversals and the branches between them need more than a handful."""
MIN_REVERSALS = 2
"""A loop needs the input to turn back twice: one reversal shows a branch and its return, not a closed loop."""
REVERSAL_DEAD_BAND = 0.01
"""A reversal counts when the input moves back by more than this fraction of its range (noise does not)."""


@dataclass(frozen=True)
class LoopData:
    """One loop, SI units: the input ``x_m`` (contraction) and the output ``force_N`` at times ``t_s``."""

    t_s: np.ndarray
    p_gauge_Pa: np.ndarray
    x_m: np.ndarray
    force_N: np.ndarray
    origin: str = "<arrays>"
    sha256: str = ""
    columns: tuple[tuple[str, str], ...] = ()
    """``(quantity, column)`` pairs: the file's column each quantity was read from (none for arrays)."""
    window_s: tuple[float, float] | None = None
    """The time window the samples were taken from (:meth:`window`); None: the whole file."""
    level_N: np.ndarray | None = None
    """At a hanging load, the rig's friction law's level at each sample [N]: Maxwell-slip elements are then
    fitted as the rig's are, their slip forces shares of it (:func:`pamsim.hysteresis.fit.fit_maxwell_slip`);
    None: constant."""

    def __post_init__(self):
        check_loop(self)

    def __len__(self) -> int:
        return self.x_m.size

    def window(self, t0_s: float, t1_s: float) -> "LoopData":
        """The samples with ``t0_s <= t_s <= t1_s``, checked as a loop of their own (the models start relaxed
        at its first sample)."""
        keep = (self.t_s >= t0_s) & (self.t_s <= t1_s)
        if keep.sum() < MIN_ROWS:
            raise DataError(f"{self.origin}: --window {t0_s:g}:{t1_s:g}: {int(keep.sum())} samples in it (times "
                            f"{self.t_s[0]:g} to {self.t_s[-1]:g} s): a loop needs at least {MIN_ROWS}")
        try:
            return LoopData(self.t_s[keep], self.p_gauge_Pa[keep], self.x_m[keep], self.force_N[keep], self.origin,
                            self.sha256, self.columns, (float(t0_s), float(t1_s)),
                            None if self.level_N is None else self.level_N[keep])
        except DataError as exc:  # say which window the samples were cut to
            raise DataError(f"--window {t0_s:g}:{t1_s:g}: {exc}") from None


def check_loop(data: LoopData) -> None:
    """Refuse a loop whose columns are not finite 1-D arrays of one length, or too short, or without
    :data:`MIN_REVERSALS` reversals of its input, naming the file (the arrays are made float arrays)."""
    where = data.origin
    for key in ("t_s", "p_gauge_Pa", "x_m", "force_N") + (("level_N",) if data.level_N is not None else ()):
        values = np.asarray(getattr(data, key), dtype=float)
        object.__setattr__(data, key, values)
        if values.shape != (data.x_m.size,) or not np.all(np.isfinite(values)):
            raise DataError(f"{where}: {key}: need {np.size(data.x_m)} finite values, one per sample of x_m")
    if data.x_m.size < MIN_ROWS:
        raise DataError(f"{where}: {data.x_m.size} rows: a loop needs at least {MIN_ROWS}")
    span = float(np.ptp(data.x_m))
    turns = reversals(data.x_m, REVERSAL_DEAD_BAND * span)
    if turns < MIN_REVERSALS:
        raise DataError(f"{where}: the contraction (the input) reverses {turns} time(s) by more than "
                        f"{REVERSAL_DEAD_BAND:.0%} of its range: a loop needs at least {MIN_REVERSALS}")


def read_loop(path: str | Path, columns: Mapping[str, str] | None = None, hanging_load=None) -> LoopData:
    """Read a loop CSV (see the module's docstring); ``columns`` maps ``time``, ``pressure``, ``contraction``
    or ``force`` to other column names (which must still end in a unit).

    With ``hanging_load`` (a :class:`~pamsim.hysteresis.hanging_load.HangingWeight`) the loop was measured at a
    hanging load: no force column is read, and the force is its ``pull_N`` of the file's contraction and
    pressure."""
    path = Path(path)
    columns = dict(columns or {})
    _check_columns_map(columns, path)
    if hanging_load is not None and "force" in columns:
        raise DataError(f"{path}: --columns force={columns['force']}: the force of a loop at a hanging load is "
                        "derived from its scenario, not read")
    header, rows, digest = _table(path)
    rules = {"time": ({"_s": 1.0}, ("t_", "time")), "pressure": (PRESSURE_UNITS_PA, ("p_", "pressure")),
             "contraction": (LENGTH_UNITS_M, ("x_", "contraction")), "force": ({"_N": 1.0}, ("force", "F_"))}
    if hanging_load is not None:
        del rules["force"]
    for quantity, (units, stems) in rules.items():
        candidates = unit_columns(header, stems, units)
        if quantity not in columns and len(candidates) > 1:
            # a rig's CSV has F_static_N, F_friction_N, ...: the first would be fitted without a word
            raise DataError(f"{path}: {len(candidates)} columns could be the {quantity} ({', '.join(candidates)}): "
                            f"say which with --columns {quantity}=NAME")
    found = {q: _unit_column(path, header, q, units, stems, columns) for q, (units, stems) in rules.items()}
    values = {q: _finite(path, name, rows[:, header.index(name)] * k) for q, (name, k) in found.items()}
    t = values["time"]
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        raise DataError(f"{path}: column {found['time'][0]}, data row {int(bad[0]) + 2}: time {t[bad[0] + 1]:g} "
                        f"does not increase (previous {t[bad[0]]:g})")
    read = tuple((q, name) for q, (name, _) in found.items())
    level = None
    if hanging_load is not None:
        values["force"] = hanging_load.pull_N(values["contraction"], values["pressure"])
        level = hanging_load.level_N(values["contraction"], values["pressure"])
        read += (("force", hanging_load.label), ("level", hanging_load.level_label))
    return LoopData(t, values["pressure"], values["contraction"], values["force"], str(path), digest, read,
                    level_N=level)


def write_loop_csv(data: LoopData, path: str | Path) -> None:
    """Write ``data`` in the format :func:`read_loop` reads (SI columns)."""
    table = np.column_stack([data.t_s, data.p_gauge_Pa, data.x_m, data.force_N])
    np.savetxt(path, table, delimiter=",", header="t_s,p_gauge_Pa,x_m,force_N", comments="", fmt="%.10g")
