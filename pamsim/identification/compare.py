"""Model comparison: the same static data through several static force models."""

from __future__ import annotations

import csv
import math
from typing import Sequence

from ..parameters import ParameterSet
from .columns import StaticData
from .models import check_model
from .static_fit import StaticFit, fit_static

COMPARE_COLUMNS = ("rank", "model", "n_free", "rms_contraction_mm", "cv_rms_contraction_mm", "rms_force_N", "aic",
                   "delta_aic", "akaike_weight", "bic", "cv_kind", "objective")


def compare_models(data: StaticData, params: ParameterSet, models: Sequence[str], **fit_options) -> list[StaticFit]:
    """Fit every model in ``models`` (each with its default free coefficients) to the same data.

    ``fit_options`` go to :func:`~pamsim.identification.fit_static` (objective, loss, cv, ...).
    AIC and BIC compare models fitted with the same objective on the same tests.
    """
    for m in models:
        check_model(m, "--compare")
    return [fit_static(data, params, model=m, free=None, **fit_options) for m in models]


def akaike_weights(aics: Sequence[float]) -> tuple[list[float], list[float]]:
    """ΔAIC (each AIC minus the smallest) and Akaike weights ``exp(-Δ/2) / sum exp(-Δ/2)``, the relative
    likelihood of each model being the best of those compared; NaN for a model without a finite AIC (a
    fit that passes through every test, or no fit), and for all when none has one."""
    finite = [a for a in aics if math.isfinite(a)]
    if not finite:
        return [math.nan] * len(aics), [math.nan] * len(aics)
    best = min(finite)
    delta = [a - best if math.isfinite(a) else math.nan for a in aics]
    rel = [math.exp(-d / 2.0) if math.isfinite(d) else 0.0 for d in delta]
    total = sum(rel)
    return delta, [r / total if math.isfinite(d) else math.nan for r, d in zip(rel, delta)]


def comparison_rows(fits: Sequence[StaticFit]) -> list[dict]:
    """One row per model, with the columns of ``compare.csv``, best AIC first (``rank`` 1); models without a
    finite AIC last, in the order given."""
    delta, weight = akaike_weights([f.aic for f in fits])
    rows = [{"model": f.problem.model, "n_free": len(f.theta), "rms_contraction_mm": f.rms_contraction_mm,
             "cv_rms_contraction_mm": f.cv_rms_contraction_mm, "rms_force_N": f.rms_force_N, "aic": f.aic,
             "delta_aic": d, "akaike_weight": w, "bic": f.bic, "cv_kind": f.cv_kind,
             "objective": f.problem.objective} for f, d, w in zip(fits, delta, weight)]
    rows.sort(key=lambda r: r["delta_aic"] if math.isfinite(r["delta_aic"]) else math.inf)
    return [{"rank": i + 1, **r} for i, r in enumerate(rows)]


def write_comparison_csv(rows: Sequence[dict], path) -> None:
    """Write the model comparison ``rows`` to the CSV file ``path``, one column per :data:`COMPARE_COLUMNS`."""
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COMPARE_COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
