"""The papers' numeric references shipped with pamsim (``pamsim/data/static_model_reference_points.csv``)."""

from __future__ import annotations

import csv
import io
from importlib import resources

REFERENCE_POINTS = "static_model_reference_points.csv"


def reference_points() -> list[dict[str, str]]:
    """Every row of the reference file as a dict of strings (columns as in the file's header)."""
    text = resources.files("pamsim.data").joinpath(REFERENCE_POINTS).read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))
