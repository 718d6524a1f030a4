"""Is a static-test file or a step response what its column names say?  Values no rig can give are refused (a
:class:`~pamsim.identification.columns.DataError` naming the column, the row and the value);
values a rig could give but that look like a unit mistake or a mix-up are returned as one-line
warnings.  The muscle the fit starts from sets the scale: its rest length, upper stop, rating and
blocked force.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .choices import CENSOR_THRESHOLD_M
from .columns import DataError, StaticData, TraceData

ATMOSPHERE_PA = 101325.0
"""Gauge pressure cannot fall below minus one atmosphere: the absolute pressure would be below vacuum."""
MAX_GAUGE_PA = 100e5
"""Above 100 bar gauge no pneumatic muscle holds: a value there is another unit (Pa or kPa as bar)."""
SMALL_PRESSURE_PA = 1e3
"""Every pressure below 1 kPa gauge: no muscle lifts a weight with that, the values are likely bar as Pa."""
SMALL_CONTRACTION_M = 1e-3
"""Every contraction below 1 mm while some loads are lifted (above the default censoring threshold):
likely metres labelled millimetres."""
NEGATIVE_CONTRACTION_M = -1e-3
"""A contraction below -1 mm is more than a zero offset of the length sensor."""
LOAD_FACTOR = 2.0
"""A load more than twice the starting muscle's blocked force at the file's highest pressure."""


@dataclass(frozen=True)
class Column:
    """One column of a measurement file: its name, its factor to SI and its values in SI, for messages that
    name the file, the column, the data row and the value as the file gives it."""

    origin: str
    name: str
    factor: float
    values: np.ndarray

    def where(self, rows: np.ndarray) -> str:
        """``FILE: column NAME, data row N: value V`` of the first row of the mask ``rows``."""
        i = int(np.flatnonzero(rows)[0])
        return f"{self.origin}: column {self.name}, data row {i + 1}: value {self.values[i] / self.factor:g}"


def refuse_impossible(pressure: Column | None, contraction: Column, L0_m: float) -> None:
    """Refuse (:class:`DataError`) a gauge pressure below vacuum or above 100 bar, and a contraction of at
    least the rest length."""
    if pressure is not None:
        p = pressure.values
        if np.any(p < -ATMOSPHERE_PA):
            raise DataError(f"{pressure.where(p < -ATMOSPHERE_PA)}: a gauge pressure below -1 atm (below vacuum)")
        if np.any(p > MAX_GAUGE_PA):
            raise DataError(f"{pressure.where(p > MAX_GAUGE_PA)}: above 100 bar gauge, which no pneumatic muscle "
                            "holds (Pa or kPa labelled bar?)")
    x = contraction.values
    if np.any(x >= L0_m):
        raise DataError(f"{contraction.where(x >= L0_m)}: a contraction of at least the muscle's rest length "
                        f"{L0_m * 1e3:g} mm ({_length_mixup(contraction)}?)")


def _length_mixup(contraction: Column) -> str:
    return "m labelled _mm" if contraction.name.endswith("_mm") else "mm labelled _m"


def pressure_warnings(pressure: Column, rated_pressure_Pa: float) -> list[str]:
    """Every pressure below 1 kPa gauge (bar labelled Pa), or one above the muscle's rating."""
    p = pressure.values
    if np.all(p < SMALL_PRESSURE_PA):
        return [f"{pressure.where(p == p.max())}: every pressure is below 1 kPa gauge (bar labelled _Pa?)"]
    if np.any(p > rated_pressure_Pa):
        return [f"{pressure.where(p > rated_pressure_Pa)}: above the muscle's rated pressure "
                f"{rated_pressure_Pa / 1e5:g} bar"]
    return []


def contraction_warnings(contraction: Column, x_max_m: float, lifted: bool) -> list[str]:
    """A lengthening beyond 1 mm; every contraction below 1 mm although ``lifted`` says a load rose (m labelled
    mm); a contraction beyond the upper stop."""
    x = contraction.values
    out = []
    if np.any(x < NEGATIVE_CONTRACTION_M):
        out.append(f"{contraction.where(x < NEGATIVE_CONTRACTION_M)}: the muscle lengthened by more than 1 mm "
                   "(sign, zero offset, or a length instead of a contraction?)")
    if np.all(x < SMALL_CONTRACTION_M) and lifted:
        out.append(f"{contraction.where(x == x.max())}: every contraction is below 1 mm ({_length_mixup(contraction)}?)")
    elif np.any(x > x_max_m):
        out.append(f"{contraction.where(x > x_max_m)}: beyond the muscle's upper stop {x_max_m * 1e3:.4g} mm")
    return out


def _beyond_blocked(blocked_N: float, at: str) -> str:
    return f"more than twice the starting muscle's blocked force {blocked_N:.4g} N at {at}"


def _static_columns(data: StaticData) -> tuple[Column, Column, Column]:
    values = (data.pressure_gauge_Pa, data.contraction_m, data.load_N)
    return tuple(Column(data.origin, name, factor, v) for (name, factor), v in zip(data.columns, values))


def check_static_data(data: StaticData, L0_m: float, x_max_m: float, rated_pressure_Pa: float,
                      blocked_force_N) -> list[str]:
    """Refuse the impossible; return one line for each implausible finding.

    Parameters
    ----------
    data : the static tests.
    L0_m, x_max_m : rest length and upper stop [m] of the starting muscle.
    rated_pressure_Pa : its rated gauge pressure (inf when it gives none).
    blocked_force_N : callable ``(p_gauge_Pa) -> N``, its pull at rest.
    """
    pressure, contraction, load = _static_columns(data)
    refuse_impossible(pressure, contraction, L0_m)
    out = pressure_warnings(pressure, rated_pressure_Pa)
    out += contraction_warnings(contraction, x_max_m, bool(np.any(data.contraction_m > CENSOR_THRESHOLD_M)))
    tiny_pressures = bool(np.all(data.pressure_gauge_Pa < SMALL_PRESSURE_PA))
    blocked = float(blocked_force_N(float(data.pressure_gauge_Pa.max())))
    heavy = data.load_N > LOAD_FACTOR * blocked
    if not tiny_pressures and blocked > 0.0 and heavy.any():  # tiny pressures: said above
        reason = _beyond_blocked(blocked, "the file's highest pressure")
        out.append(f"{load.where(heavy)}: {reason}")
    groups = duplicate_groups(data)
    if len(np.unique(groups)) < len(data):
        first = np.flatnonzero(np.bincount(groups)[groups] > 1)
        out.append(f"{data.origin}: data rows {', '.join(str(i + 1) for i in first[:4])}"
                   f"{' ...' if first.size > 4 else ''}: repeated tests (same pressure, contraction and load); "
                   "cross-validation keeps copies in one fold")
    return out


def check_trace(trace: TraceData, load_N: float, L0_m: float, x_max_m: float, rated_pressure_Pa: float,
                blocked_force_N) -> list[str]:
    """A step response's :func:`check_static_data`: refuse the impossible (pressure below vacuum or above
    100 bar, contraction of at least the rest length), return one line for each implausible finding (the
    pressure's and the contraction's scale, a pressure above the rating, a lengthening, a contraction beyond
    the upper stop, a load above twice the blocked force at the trace's highest pressure; without a
    recorded pressure, at the scenario's final one, ``blocked_force_N(None)``)."""
    (x_name, x_factor), pressure = trace.columns[1], None
    contraction = Column(trace.origin, x_name, x_factor, trace.x_m)
    if trace.p_gauge_Pa is not None:
        pressure = Column(trace.origin, *trace.columns[2], trace.p_gauge_Pa)
    refuse_impossible(pressure, contraction, L0_m)
    out = [] if pressure is None else pressure_warnings(pressure, rated_pressure_Pa)
    out += contraction_warnings(contraction, x_max_m, lifted=True)
    p_top = None if pressure is None else float(trace.p_gauge_Pa.max())
    blocked = float(blocked_force_N(p_top))
    if (p_top is None or p_top >= SMALL_PRESSURE_PA) and 0.0 < LOAD_FACTOR * blocked < load_N:
        at = "the scenario's supply pressure" if p_top is None else "the trace's highest pressure"
        out.append(f"{trace.origin}: load {load_N:g} N: {_beyond_blocked(blocked, at)}")
    return out


def duplicate_groups(data: StaticData) -> np.ndarray:
    """One label per test, shared by tests with the same pressure, contraction and load."""
    rows = np.column_stack([data.pressure_gauge_Pa, data.contraction_m, data.load_N])
    _, labels = np.unique(rows, axis=0, return_inverse=True)
    return labels.ravel()
