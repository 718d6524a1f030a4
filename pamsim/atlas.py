"""Static-model atlas of one muscle: isobaric force-contraction curves of every
applicable model, blocked force and free contraction per model and pressure,
and the muscle's measured points.

:func:`build_atlas` computes an :class:`Atlas`; :meth:`Atlas.write` writes its
CSV files, a Markdown table and the figures (:mod:`pamsim.atlas_plots`)
together or not at all.  ``pamsim atlas`` is the command-line face.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from .atomic import atomic_outputs
from .constants import PA_PER_BAR
from .elements.stops import EndStops
from .errors import InputError
from .figure_style import check_format
from .muscle_setup import model_inputs, muscle_parameters, prepare
from .muscles import Muscle
from .static_models import REGISTRY

N_POINTS = 201
"""Points per curve along the contraction."""
RATING_FRACTIONS = (0.25, 0.5, 0.75, 1.0)
"""Default pressures as fractions of the rating, for a muscle without measured points."""
MATCH_FRACTION = 0.1
"""A measured point is drawn on the figure of the nearest atlas pressure within 10 % of it."""

# Column sets of the measured-point files shipped with muscles: (pressure column, its scale to Pa,
# contraction column, its scale to m, force column).
_DATA_FORMATS = (
    ("pressure_stable_bar", PA_PER_BAR, "contraction_stable_mm", 1e-3, "weight_N"),
    ("pressure_gauge_Pa", 1.0, "contraction_mm", 1e-3, "load_N"),
)


@dataclass(frozen=True)
class Curve:
    """One model at one pressure: force [N] along contraction [m] over the model's domain."""

    model: str
    pressure_Pa: float
    x_m: np.ndarray = field(repr=False)
    F_N: np.ndarray = field(repr=False)
    blocked_force_N: float
    free_contraction_m: float
    free_contraction_note: str = ""
    """Why there is no free contraction (``free_contraction_m`` NaN), else empty."""

    def table_cell(self) -> str:
        """``blocked force / free contraction [mm]``, ``none`` for a free contraction the note explains."""
        free = "none" if self.free_contraction_note else f"{self.free_contraction_m * 1e3:.3g}"
        return f"{self.blocked_force_N:.4g} / {free}"


@dataclass(frozen=True)
class Atlas:
    """Curves, summary table and measured points of one muscle."""

    muscle: Muscle
    pressures_Pa: tuple[float, ...]
    curves: tuple[Curve, ...]
    measured: np.ndarray = field(repr=False)  # rows (p_Pa, x_m, F_N)
    skipped: Mapping[str, str] = field(default_factory=dict)

    @property
    def models(self) -> list[str]:
        """The models drawn, each once, in the order of the curves."""
        return list(dict.fromkeys(c.model for c in self.curves))

    def measured_near(self, p_Pa: float) -> np.ndarray:
        """Measured points whose pressure is nearest to ``p_Pa`` among the atlas pressures (within 10 %)."""
        if not len(self.measured):
            return self.measured
        ps = np.array(self.pressures_Pa)
        nearest = ps[np.argmin(np.abs(self.measured[:, :1] - ps[None, :]), axis=1)]
        keep = (nearest == p_Pa) & (np.abs(self.measured[:, 0] - p_Pa) <= MATCH_FRACTION * p_Pa)
        return self.measured[keep]

    def table_rows(self) -> list[dict]:
        """One row per model and pressure: blocked force [N], free contraction [mm] and the note on it."""
        return [{"model": c.model, "pressure_bar": c.pressure_Pa / PA_PER_BAR, "blocked_force_N": c.blocked_force_N,
                 "free_contraction_mm": c.free_contraction_m * 1e3, "free_contraction_note": c.free_contraction_note}
                for c in self.curves]

    def markdown_table(self) -> str:
        """Blocked force and free contraction per model (rows) and pressure (columns)."""
        head = " | ".join(f"{p / PA_PER_BAR:g} bar" for p in self.pressures_Pa)
        lines = [f"Blocked force [N] / free contraction [mm] of `{self.muscle.name}`", "",
                 f"| model | {head} |", "| --- |" + " --- |" * len(self.pressures_Pa)]
        by = {(c.model, c.pressure_Pa): c for c in self.curves}
        for m in self.models:
            cells = []
            for p in self.pressures_Pa:
                c = by.get((m, p))
                cells.append("-" if c is None else c.table_cell())
            lines.append(f"| `{m}` | " + " | ".join(cells) + " |")
        for c in self.curves:
            if c.free_contraction_note:
                lines.append(f"\nNo free contraction: `{c.model}` at {c.pressure_Pa / PA_PER_BAR:g} bar: "
                             f"{c.free_contraction_note}")
        for m, why in self.skipped.items():
            lines.append(f"\nNot drawn: `{m}`: {why}")
        return "\n".join(lines) + "\n"

    def figure_names(self, figure_format: str = "png") -> list[str]:
        """File names of the figures :meth:`write` writes: one per pressure, then ``atlas_all``, in ``figure_format``."""
        stems = [f"atlas_{p / PA_PER_BAR:g}bar" for p in self.pressures_Pa] + ["atlas_all"]
        return [f"{stem}.{figure_format}" for stem in stems]

    def write(self, directory: str | Path, figure_format: str = "png", dpi: int | None = None) -> list[Path]:
        """Write ``atlas_curves.csv``, ``atlas_table.csv``, ``atlas_table.md`` and the figures (PNG, PDF or SVG by
        ``figure_format``, at ``dpi`` dots per inch; default 110, atlas_all 100)."""
        from .atlas_plots import plot_all, plot_pressure

        figures = self.figure_names(check_format(figure_format, label="figure format"))
        names = ["atlas_curves.csv", "atlas_table.csv", "atlas_table.md"] + figures
        with atomic_outputs(directory, names) as tmp:
            with open(tmp["atlas_curves.csv"], "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(["model", "pressure_bar", "contraction_mm", "force_N"])
                for c in self.curves:
                    for x, F in zip(c.x_m, c.F_N):
                        w.writerow([c.model, f"{c.pressure_Pa / PA_PER_BAR:g}", f"{x * 1e3:.6g}", f"{F:.6g}"])
            with open(tmp["atlas_table.csv"], "w", newline="") as fh:
                w = csv.DictWriter(fh, ["model", "pressure_bar", "blocked_force_N", "free_contraction_mm",
                                        "free_contraction_note"])
                w.writeheader()
                w.writerows(self.table_rows())
            tmp["atlas_table.md"].write_text(self.markdown_table())
            for p, name in zip(self.pressures_Pa, figures):
                plot_pressure(self, p, tmp[name], dpi)
            plot_all(self, tmp[figures[-1]], dpi)
        return [Path(directory) / n for n in names]


def measured_points(path: Path | None) -> np.ndarray:
    """Rows ``(p_Pa, x_m, F_N)`` of a muscle's measured-point file (empty if it has none).

    Raises
    ------
    InputError
        A file in none of the known column layouts.
    """
    if path is None:
        return np.empty((0, 3))
    lines = [ln for ln in Path(path).read_text().splitlines() if ln.strip() and not ln.startswith("#")]
    rows = list(csv.DictReader(lines))
    header = set(rows[0]) if rows else set()
    for p_col, p_scale, x_col, x_scale, f_col in _DATA_FORMATS:
        if {p_col, x_col, f_col} <= header:
            return np.array([(float(r[p_col]) * p_scale, float(r[x_col]) * x_scale, float(r[f_col])) for r in rows])
    raise InputError(f"{path}: no known columns for measured points (expected one of "
                     f"{'; '.join(', '.join((a, c, e)) for a, _, c, _, e in _DATA_FORMATS)})")


def default_pressures_Pa(measured: np.ndarray, rating_Pa: float) -> tuple[float, ...]:
    """The measured points' distinct pressures rounded to 0.01 bar (at most six, spread), else fractions
    of the rating."""
    if len(measured):
        ps = np.unique(np.round(measured[:, 0] / PA_PER_BAR, 2))
        ps = ps[ps > 0]
        if len(ps) > 6:
            ps = ps[np.round(np.linspace(0, len(ps) - 1, 6)).astype(int)]
        return tuple(float(p) * PA_PER_BAR for p in ps)
    return tuple(f * rating_Pa for f in RATING_FRACTIONS)


def build_atlas(muscle: str, models: Sequence[str] | None = None, pressures_bar: Sequence[float] | None = None,
                overrides: Mapping[str, float] | None = None, n_points: int = N_POINTS) -> Atlas:
    """Curves of ``models`` (default: every model whose parameters the muscle gives) at ``pressures_bar``.

    A model named explicitly that does not apply raises :class:`InputError`;
    a pressure above a model's domain leaves that curve out.
    """
    m, params = muscle_parameters(muscle, overrides)
    why = None if models else m.no_model_reason(model_inputs(m, params))
    if why:
        raise InputError(f"muscle {m.name!r}: {why}: nothing to draw")
    names = list(models) if models else [n for n, s in REGISTRY.items() if not s.missing(model_inputs(m, params))]
    for name in names:  # the same checks and messages as a scenario or `pamsim force`
        prepare(muscle, name, overrides)
    measured = measured_points(m.data_file)
    rating = params["rated_pressure_gauge_Pa"]
    if pressures_bar:
        for p in pressures_bar:
            if not 0.0 < p * PA_PER_BAR <= rating:
                raise InputError(f"pressure {p:g} bar: must lie in (0, {rating / PA_PER_BAR:g}] bar (the muscle's rating)")
        pressures = tuple(float(p) * PA_PER_BAR for p in pressures_bar)
    else:
        pressures = default_pressures_Pa(measured, rating)
    x_stop = EndStops.from_parameters(params).x_high_m if {"L0_m", "r0_m", "theta0_deg"} <= set(params) else math.inf
    curves, skipped = [], {}
    for name in names:
        model = REGISTRY[name].build(model_inputs(m, params))
        d = model.domain
        x_lo, x_hi = max(d.x_min_m, 0.0), min(d.x_max_m, x_stop)
        if not math.isfinite(x_hi) or x_hi <= x_lo:
            skipped[name] = f"no finite contraction range (domain {d.x_min_m:g} .. {d.x_max_m:g} m)"
            continue
        x = np.linspace(x_lo, x_hi, n_points)
        for p in pressures:
            if not d.p_min_Pa <= p <= d.p_max_Pa:
                continue
            F = np.asarray(model.force_N(x, p), dtype=float)
            free = model.free_contraction_m(p, 0.0)
            note = "" if math.isfinite(free) else (f"the force stays above zero up to the end of its domain "
                                                    f"({d.x_max_m * 1e3:.3g} mm)")
            curves.append(Curve(name, p, x, F, float(F[0]) if x_lo == 0.0 else math.nan, float(free), note))
    if not curves:
        raise InputError(f"muscle {m.name!r}: no curve to draw: the pressures "
                         f"{', '.join(f'{p / PA_PER_BAR:g}' for p in pressures)} bar lie outside the domain of "
                         f"{', '.join(names)}" + "".join(f"; {n}: {w}" for n, w in skipped.items()))
    return Atlas(m, pressures, tuple(curves), measured, skipped)
