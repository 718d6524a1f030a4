"""Model comparison: the same static data through several static force models."""

from __future__ import annotations

import csv
from typing import Sequence

from ..parameters import ParameterSet
from .columns import StaticData
from .models import check_model
from .static_fit import StaticFit, fit_static

COMPARE_COLUMNS = ("model", "n_free", "rms_contraction_mm", "cv_rms_contraction_mm", "rms_force_N", "aic", "bic",
                   "cv_kind", "objective")


def compare_models(data: StaticData, params: ParameterSet, models: Sequence[str], **fit_options) -> list[StaticFit]:
    """Fit every model in ``models`` (each with its default free coefficients) to the same data.

    ``fit_options`` go to :func:`~pamsim.identification.fit_static` (objective, loss, cv, ...).
    AIC and BIC compare models fitted with the same objective on the same tests.
    """
    for m in models:
        check_model(m, "--compare")
    return [fit_static(data, params, model=m, free=None, **fit_options) for m in models]


def comparison_rows(fits: Sequence[StaticFit]) -> list[dict]:
    """One row per model, with the columns of ``compare.csv``."""
    return [{"model": f.problem.model, "n_free": len(f.theta), "rms_contraction_mm": f.rms_contraction_mm,
             "cv_rms_contraction_mm": f.cv_rms_contraction_mm, "rms_force_N": f.rms_force_N, "aic": f.aic,
             "bic": f.bic, "cv_kind": f.cv_kind, "objective": f.problem.objective} for f in fits]


def write_comparison_csv(rows: Sequence[dict], path) -> None:
    """Write the model comparison ``rows`` to the CSV file ``path``, one column per :data:`COMPARE_COLUMNS`."""
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COMPARE_COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
