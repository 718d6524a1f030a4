"""The papers' numeric references shipped with pamsim (``pamsim/data/static_model_reference_points.csv``)."""

from __future__ import annotations

import csv
import io
import re
from importlib import resources

REFERENCE_POINTS = "static_model_reference_points.csv"


def reference_points() -> list[dict[str, str]]:
    """Every row of the reference file as a dict of strings (columns as in the file's header)."""
    text = resources.files("pamsim.data").joinpath(REFERENCE_POINTS).read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


def is_acra_point(row: dict[str, str]) -> bool:
    """Whether a row is one of the ACRA 2012 steady states (a numeric pressure and a contraction)."""
    return row["model"].startswith("A-2") and row["pressure_value"].replace(".", "", 1).isdigit()


def acra_point(row: dict[str, str]) -> tuple[float, float]:
    """Gauge pressure [Pa] and contraction [m] of an ACRA 2012 row (the file gives bar and mm)."""
    x_mm = float(re.search(r"x=(-?[\d.]+) mm", row["contraction_or_length"]).group(1))
    return float(row["pressure_value"]) * 1e5, x_mm * 1e-3


def table3_estimate_N(row: dict[str, str]) -> float | None:
    """The paper's Table 3 estimate quoted in an ACRA 2012 row, if any [N]."""
    m = re.search(r"estimate (-?[\d.]+)", row["tolerance_or_reported_error"])
    return float(m.group(1)) if m else None
