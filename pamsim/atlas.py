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
from .table_checks import LENGTH_UNITS_M, PRESSURE_UNITS_PA, unit_column

N_POINTS = 201
"""Points per curve along the contraction."""
RATING_FRACTIONS = (0.25, 0.5, 0.75, 1.0)
"""Default pressures as fractions of the rating, for a muscle without measured points."""
MATCH_FRACTION = 0.1
"""A measured point is drawn on the figure of the nearest atlas pressure within 10 % of it."""
SAME_CURVE_FRACTION = 1e-9
"""Two models' curves are the same curve when they agree at every point to this fraction of their largest
force (equal but for rounding: Gaylord's model and those that reduce to it give curves 1e-15 apart)."""

# How a muscle's measured-point file names its columns: the rule of the fits' measurement files
# (pamsim.table_checks.unit_column), the stable pressure preferred where the file has one (the ACRA tables).
_POINT_COLUMNS = (("pressure", ("pressure", "p_"), PRESSURE_UNITS_PA),
                  ("contraction", ("contraction", "x_"), LENGTH_UNITS_M),
                  ("force or hung weight", ("force", "weight", "load"), {"_N": 1.0}))
_PREFERRED_PRESSURE = "pressure_stable_bar"


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

    @property
    def groups(self) -> list[tuple[str, ...]]:
        """The models in groups that give the same curve at every pressure (:func:`same_curve`), each
        group and the models in it in the order of the curves: the figures draw one line per group."""
        by_model = {m: {c.pressure_Pa: c for c in self.curves if c.model == m} for m in self.models}
        groups: list[list[str]] = []
        for m in self.models:
            mine = by_model[m]
            for group in groups:
                first = by_model[group[0]]
                if first.keys() == mine.keys() and all(same_curve(first[p], mine[p]) for p in mine):
                    group.append(m)
                    break
            else:
                groups.append([m])
        return [tuple(g) for g in groups]

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
        same = [" = ".join(f"`{m}`" for m in g) for g in self.groups if len(g) > 1]
        if same:
            lines.append("\nSame curves at every pressure, drawn as one line: " + "; ".join(same))
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


def same_curve(a: Curve, b: Curve) -> bool:
    """Whether two curves are one: the same contractions, and forces within :data:`SAME_CURVE_FRACTION` of
    the larger curve's largest force at every point."""
    if a.pressure_Pa != b.pressure_Pa or a.x_m.shape != b.x_m.shape or not np.array_equal(a.x_m, b.x_m):
        return False
    with np.errstate(invalid="ignore"):
        scale = max(np.nanmax(np.abs(a.F_N), initial=0.0), np.nanmax(np.abs(b.F_N), initial=0.0))
    return bool(np.allclose(a.F_N, b.F_N, rtol=0.0, atol=SAME_CURVE_FRACTION * scale, equal_nan=True))


def measured_points(path: Path | None) -> np.ndarray:
    """Rows ``(p_Pa, x_m, F_N)`` of a muscle's measured-point file (empty if it has none).

    The columns are found by their names' units, as a fit's measurement file's are
    (:func:`pamsim.identification.read_static_data`): a gauge pressure (``pressure*`` or ``p_*`` in
    ``_bar``, ``_Pa``, ``_kPa``, ``_psi``; ``pressure_stable_bar`` first), a contraction (``contraction*``
    or ``x_*`` in ``_mm`` or ``_m``) and a force (``force*``, ``weight*`` or ``load*`` in ``_N``), so the
    ``data.csv`` that ``pamsim fit static`` copies beside its ``muscle.toml`` is read as it was fitted.

    Raises
    ------
    InputError
        A file without such columns, or with a value that is not a number.
    """
    if path is None:
        return np.empty((0, 3))
    lines = [ln for ln in Path(path).read_text().splitlines() if ln.strip() and not ln.startswith("#")]
    reader = csv.DictReader(lines)
    header = [h.strip() for h in reader.fieldnames or []]
    reader.fieldnames = header
    rows = list(reader)
    found = _point_columns(path, header)
    try:
        return np.array([[float(r[name]) * k for name, k in found] for r in rows], dtype=float).reshape(-1, 3)
    except (TypeError, ValueError):
        raise InputError(f"{path}: a measured point is not a number (columns {', '.join(n for n, _ in found)})") from None


def _point_columns(path: Path, header: list[str]) -> list[tuple[str, float]]:
    """``[(column, factor to SI)]`` of the pressure, contraction and force in a measured-point file's header.

    Raises
    ------
    InputError
        Naming every quantity without a column, and the columns there are.
    """
    found = [unit_column(header, stems, units) for _, stems, units in _POINT_COLUMNS]
    if _PREFERRED_PRESSURE in header:
        found[0] = (_PREFERRED_PRESSURE, PA_PER_BAR)
    missing = [f"a {what} column ({' or '.join(s + '*' for s in stems)} ending in {' / '.join(units)})"
               for (what, stems, units), col in zip(_POINT_COLUMNS, found) if col is None]
    if missing:
        raise InputError(f"{path}: no measured points: need {', '.join(missing)} (columns: {', '.join(header)})")
    return found


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
    names = _models_to_draw(muscle, m, params, models, overrides)
    measured = measured_points(m.data_file)
    pressures = _pressures_Pa(pressures_bar, measured, params["rated_pressure_gauge_Pa"])
    x_stop = EndStops.from_parameters(params).x_high_m if {"L0_m", "r0_m", "theta0_deg"} <= set(params) else math.inf
    curves, skipped = [], {}
    for name in names:
        model = REGISTRY[name].build(model_inputs(m, params))
        d = model.domain
        x_lo, x_hi = max(d.x_min_m, 0.0), min(d.x_max_m, x_stop)
        if not math.isfinite(x_hi) or x_hi <= x_lo:
            skipped[name] = f"no finite contraction range (domain {d.x_min_m:g} .. {d.x_max_m:g} m)"
        else:
            curves += _model_curves(name, model, pressures, np.linspace(x_lo, x_hi, n_points), x_lo == 0.0)
    if not curves:
        raise InputError(f"muscle {m.name!r}: no curve to draw: the pressures "
                         f"{', '.join(f'{p / PA_PER_BAR:g}' for p in pressures)} bar lie outside the domain of "
                         f"{', '.join(names)}" + "".join(f"; {n}: {w}" for n, w in skipped.items()))
    return Atlas(m, pressures, tuple(curves), measured, skipped)


def _models_to_draw(muscle: str, m: Muscle, params: Mapping[str, float], models: Sequence[str] | None,
                    overrides: Mapping[str, float] | None) -> list[str]:
    """The models asked for, else every model whose parameters the muscle gives, each checked.

    Raises
    ------
    InputError
        No model applies to the muscle (none asked for), or a model asked for does not apply: the same
        checks and messages as a scenario or ``pamsim force``.
    """
    why = None if models else m.no_model_reason(model_inputs(m, params))
    if why:
        raise InputError(f"muscle {m.name!r}: {why}: nothing to draw")
    names = list(models) if models else [n for n, s in REGISTRY.items() if not s.missing(model_inputs(m, params))]
    for name in names:
        prepare(muscle, name, overrides)
    return names


def _pressures_Pa(pressures_bar: Sequence[float] | None, measured: np.ndarray, rating_Pa: float) -> tuple[float, ...]:
    """The pressures asked for [Pa], each within the rating, else :func:`default_pressures_Pa`.

    Raises
    ------
    InputError
        A pressure at or below zero, or above the muscle's rating.
    """
    if not pressures_bar:
        return default_pressures_Pa(measured, rating_Pa)
    for p in pressures_bar:
        if not 0.0 < p * PA_PER_BAR <= rating_Pa:
            raise InputError(f"pressure {p:g} bar: must lie in (0, {rating_Pa / PA_PER_BAR:g}] bar (the muscle's rating)")
    return tuple(float(p) * PA_PER_BAR for p in pressures_bar)


def _model_curves(name: str, model, pressures: Sequence[float], x: np.ndarray, from_zero: bool) -> list[Curve]:
    """One model's curves along the contractions ``x`` [m], at the pressures inside its domain; the blocked
    force (the first point's) when ``from_zero`` (``x`` starts at zero contraction), else NaN."""
    d = model.domain
    curves = []
    for p in pressures:
        if not d.p_min_Pa <= p <= d.p_max_Pa:
            continue
        F = np.asarray(model.force_N(x, p), dtype=float)
        free = model.free_contraction_m(p, 0.0)
        note = "" if math.isfinite(free) else (f"the force stays above zero up to the end of its domain "
                                                f"({d.x_max_m * 1e3:.3g} mm)")
        curves.append(Curve(name, p, x, F, float(F[0]) if from_zero else math.nan, float(free), note))
    return curves
