"""A measured (or tabulated) static force map ``F(x, p)`` read from a CSV file.

File format: comment lines start with ``#``; a header row names three columns
``contraction_m`` (x = L0 - L [m]), ``pressure_gauge_Pa`` [Pa] and ``force_N``
[N]; one row per point of a full rectangular grid (every contraction with every
pressure, any order, at least two values of each).  The force is interpolated by
a bicubic interpolating spline (:class:`pamsim.static_models.spline.SplineSurface`:
``scipy.interpolate.RectBivariateSpline``, ``s = 0``; degree lowered to ``n - 1``
along an axis with fewer than four values), which is exact for data that are
cubic in each variable and smooth (C2) in between; the native engine and the FMU
evaluate the same spline in generated C.  The domain is the table's extent: no
extrapolation (outside it the force is held at the nearest edge).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from ..errors import InputError
from .base import Domain, StaticForce, StaticModelSpec
from .spline import SplineSurface

COLUMNS = ("contraction_m", "pressure_gauge_Pa", "force_N")


class ForceMapError(InputError):
    """A force-map file that cannot be used; the message names file, row/column and value."""


def read_force_map(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Read and check a force-map CSV: ``(x_m [nx], p_Pa [np], F_N [nx, np])``.

    Raises
    ------
    ForceMapError
        Missing file or column, a non-numeric or non-finite value, a duplicate
        point, or points that do not form a full grid.
    """
    path = Path(path)
    reader = csv.DictReader(_data_lines(path))
    missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise ForceMapError(f"{path}: header = {reader.fieldnames!r}: missing column(s) {', '.join(missing)} "
                            f"(need {', '.join(COLUMNS)})")
    return _grid(path, _points(path, reader))


def _data_lines(path: Path) -> list[str]:
    """The file's lines that are neither blank nor comments.

    Raises
    ------
    ForceMapError
        A file that cannot be read as UTF-8 text.
    """
    try:
        return [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip() and not ln.startswith("#")]
    except (OSError, UnicodeDecodeError) as exc:
        raise ForceMapError(f"{path}: cannot read the force map: {exc}") from None


def _points(path: Path, reader: csv.DictReader) -> dict[tuple[float, float], float]:
    """``{(x_m, p_Pa): F_N}`` of the rows, in the file's order.

    Raises
    ------
    ForceMapError
        A value that is not a finite number, or a point given twice (naming its row).
    """
    points = {}
    for n, row in enumerate(reader, start=2):  # row 1 is the header
        x, p, F = (_finite(path, n, row, c) for c in COLUMNS)
        if (x, p) in points:
            raise ForceMapError(f"{path}: row {n}: (contraction_m, pressure_gauge_Pa) = {(x, p)}: duplicate point")
        points[(x, p)] = F
    return points


def _finite(path: Path, n: int, row: dict, column: str) -> float:
    """Column ``column`` of row ``n`` as a finite number.

    Raises
    ------
    ForceMapError
        A value that is missing, not a number or not finite.
    """
    try:
        v = float(row[column])
    except (TypeError, ValueError):
        raise ForceMapError(f"{path}: row {n}: {column} = {row[column]!r}: not a number") from None
    if not math.isfinite(v):
        raise ForceMapError(f"{path}: row {n}: {column} = {row[column]!r}: must be finite")
    return v


def _grid(path: Path, points: dict[tuple[float, float], float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(x_m, p_Pa, F_N)`` of points that form a full grid, the axes ascending.

    Raises
    ------
    ForceMapError
        Fewer than two values along an axis, or a grid point without a value (the first one).
    """
    xs = np.unique([k[0] for k in points])
    ps = np.unique([k[1] for k in points])
    if len(xs) < 2 or len(ps) < 2:
        raise ForceMapError(f"{path}: grid = {len(xs)} x {len(ps)}: needs at least two contractions and two pressures")
    if len(points) != len(xs) * len(ps):
        x, p = _first_absent(points, xs, ps)
        raise ForceMapError(f"{path}: (contraction_m, pressure_gauge_Pa) = ({x:g}, {p:g}): "
                            f"missing point (the table must be a full {len(xs)} x {len(ps)} grid)")
    F = np.array([[points[(x, p)] for p in ps] for x in xs])
    return xs, ps, F


def _first_absent(points: dict, xs: np.ndarray, ps: np.ndarray) -> tuple[float, float]:
    """The first grid point, contraction by contraction, that has no value."""
    return next((x, p) for x in xs for p in ps if (x, p) not in points)


class ForceMap(StaticForce):
    """Smooth interpolation of a tabulated ``F(x, p)``; see the module docstring."""

    name = "force_map"

    def __init__(self, x_m: np.ndarray, p_Pa: np.ndarray, F_N: np.ndarray, origin: str = "<table>"):
        self.origin = origin
        self.spline = SplineSurface(x_m, p_Pa, F_N)
        self.domain = Domain(float(x_m[0]), float(x_m[-1]), float(p_Pa[0]), float(p_Pa[-1]))

    @classmethod
    def from_csv(cls, path: str | Path) -> "ForceMap":
        """The force map of a CSV file of measured forces over contraction and pressure."""
        return cls(*read_force_map(path), origin=str(path))

    def force_N(self, x_m, p_gauge_Pa):
        return self.spline(x_m, p_gauge_Pa)


SPECS = (
    StaticModelSpec("force_map", "table", "a measured F(x, p) table given by the user (CSV, see docs/static_models.md)",
                    ("force_map_file",), lambda p, v: ForceMap.from_csv(p["force_map_file"]),
                    summary="bicubic interpolation of a measured force table; domain = the table's extent"),
)
