"""The files ``pamsim run`` writes for one run: NAME.csv, NAME.json and the figure."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Callable


def write_run_files(out: Path, name: str, args: argparse.Namespace, to_csv: Callable, summary: dict,
                    figure: Callable) -> list[str]:
    """Write ``NAME.csv`` (``to_csv(path)``), ``NAME.json`` (``summary``) and, without ``--no-plot``, the figure
    ``figure()`` in ``--format`` at ``--dpi``, all or none (:func:`pamsim.atomic.atomic_outputs`); return the
    files' names."""
    from ..atomic import atomic_outputs
    from ..figure_style import save

    fmt, dpi = args.figures
    names = [f"{name}.csv", f"{name}.json"] + ([] if args.no_plot else [f"{name}.{fmt}"])
    with atomic_outputs(out, names) as tmp:
        to_csv(tmp[names[0]])
        tmp[names[1]].write_text(json.dumps(summary, indent=2) + "\n")
        if not args.no_plot:
            save(figure(), tmp[names[2]], fmt=fmt, dpi=dpi)
    return names


def rhs_text(rhs_evaluations: int, backend: str) -> str:
    """A run's right-hand-side evaluations for its summary line; an FMU's solver does not report its own."""
    if backend.startswith("fmu"):
        return "RHS evaluations not counted (the FMU's own solver)"
    return f"{rhs_evaluations} RHS evaluations"


def wall_time_text(wall_time_s: float) -> str:
    """A run's wall time for its summary line, to three figures: a native run takes a fraction of a
    millisecond, which whole milliseconds printed as 0 ms."""
    ms = wall_time_s * 1e3
    return f"{ms:.0f} ms" if ms >= 100.0 else f"{ms:.3g} ms"
