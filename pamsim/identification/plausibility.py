"""Is a static-test file what its column names say?  Values no rig can give are refused (a
:class:`~pamsim.identification.columns.DataError` naming the column, the row and the value);
values a rig could give but that look like a unit mistake or a mix-up are returned as one-line
warnings.  The muscle the fit starts from sets the scale: its rest length, upper stop, rating and
blocked force.
"""

from __future__ import annotations

import numpy as np

from .choices import CENSOR_THRESHOLD_M
from .columns import DataError, StaticData

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


def _where(data: StaticData, q: int, rows: np.ndarray, si: np.ndarray) -> str:
    name, factor = data.columns[q]
    i = int(np.flatnonzero(rows)[0])
    return f"{data.origin}: column {name}, data row {i + 1}: value {si[i] / factor:g}"


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
    p, x, w = data.pressure_gauge_Pa, data.contraction_m, data.load_N
    x_unit = "m labelled _mm" if data.columns[1][0].endswith("_mm") else "mm labelled _m"
    if np.any(p < -ATMOSPHERE_PA):
        raise DataError(f"{_where(data, 0, p < -ATMOSPHERE_PA, p)}: a gauge pressure below -1 atm (below vacuum)")
    if np.any(p > MAX_GAUGE_PA):
        raise DataError(f"{_where(data, 0, p > MAX_GAUGE_PA, p)}: above 100 bar gauge, which no pneumatic muscle "
                        "holds (Pa or kPa labelled bar?)")
    if np.any(x >= L0_m):
        raise DataError(f"{_where(data, 1, x >= L0_m, x)}: a contraction of at least the muscle's rest length "
                        f"{L0_m * 1e3:g} mm ({x_unit}?)")
    out = []
    tiny_pressures = bool(np.all(p < SMALL_PRESSURE_PA))
    if tiny_pressures:
        out.append(f"{_where(data, 0, p == p.max(), p)}: every pressure is below 1 kPa gauge (bar labelled _Pa?)")
    elif np.any(p > rated_pressure_Pa):
        out.append(f"{_where(data, 0, p > rated_pressure_Pa, p)}: above the muscle's rated pressure "
                   f"{rated_pressure_Pa / 1e5:g} bar")
    if np.any(x < NEGATIVE_CONTRACTION_M):
        out.append(f"{_where(data, 1, x < NEGATIVE_CONTRACTION_M, x)}: the muscle lengthened by more than 1 mm "
                   "(sign, zero offset, or a length instead of a contraction?)")
    if np.all(x < SMALL_CONTRACTION_M) and np.any(x > CENSOR_THRESHOLD_M):
        out.append(f"{_where(data, 1, x == x.max(), x)}: every contraction is below 1 mm ({x_unit}?)")
    elif np.any(x > x_max_m):
        out.append(f"{_where(data, 1, x > x_max_m, x)}: beyond the muscle's upper stop {x_max_m * 1e3:.4g} mm")
    blocked = float(blocked_force_N(float(p.max())))
    if not tiny_pressures and blocked > 0.0 and np.any(w > LOAD_FACTOR * blocked):  # tiny pressures: said above
        out.append(f"{_where(data, 2, w > LOAD_FACTOR * blocked, w)}: more than twice the starting muscle's blocked "
                   f"force {blocked:.4g} N at the file's highest pressure")
    groups = duplicate_groups(data)
    if len(np.unique(groups)) < len(data):
        first = np.flatnonzero(np.bincount(groups)[groups] > 1)
        out.append(f"{data.origin}: data rows {', '.join(str(i + 1) for i in first[:4])}"
                   f"{' ...' if first.size > 4 else ''}: repeated tests (same pressure, contraction and load); "
                   "cross-validation keeps copies in one fold")
    return out


def duplicate_groups(data: StaticData) -> np.ndarray:
    """One label per test, shared by tests with the same pressure, contraction and load."""
    rows = np.column_stack([data.pressure_gauge_Pa, data.contraction_m, data.load_N])
    _, labels = np.unique(rows, axis=0, return_inverse=True)
    return labels.ravel()
