"""``pamsim fit static`` and ``pamsim fit dynamic``: identify a muscle from measurements
(docs/identification.md)."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from ..atomic import OutputError, ensure_output_dir
from ..identification import compare, muscle_file, report, static_fit
from ..identification.columns import read_static_data
from ..identification.crossval import CV_CHOICES
from . import finite_float


def _names(text: str) -> list[str]:
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise argparse.ArgumentTypeError(f"{text!r}: give comma-separated names")
    return names


def _columns(text: str) -> dict[str, str]:
    out = {}
    for item in text.split(","):
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise argparse.ArgumentTypeError(f"{item!r}: write QUANTITY=COLUMN, e.g. pressure=p_meas_kPa")
        out[key.strip()] = value.strip()
    return out


def _count(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if n < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must not be negative")
    return n


def check_output_dir(directory: str) -> None:
    """Refuse an output folder that cannot be written, before any work, without creating it."""
    path = Path(directory)
    if path.exists():
        ensure_output_dir(path)
        return
    parent = path.parent
    while not parent.exists():
        parent = parent.parent
    if not (parent.is_dir() and os.access(parent, os.W_OK | os.X_OK)):
        raise OutputError(f"{directory}: cannot create the output folder ({parent} is not writable)")


def register(sub) -> None:
    p = sub.add_parser("fit", help="identify a muscle from static tests or step responses",
                       description="Fit static force coefficients to static tests (fit static) or friction and "
                                   "damping coefficients to step responses (fit dynamic).")
    fsub = p.add_subparsers(dest="fit_kind", required=True, metavar="KIND")
    s = fsub.add_parser("static", help="fit a static force model to static tests",
                        description="Fit a static force model to static tests (pressure, contraction, hung weight "
                                    "or measured force) and write fit.json, muscle.toml, report.md and figures.")
    s.add_argument("data", help="CSV with unit-suffixed columns (e.g. pamsim/data/acra2012_steady_state.csv)")
    s.add_argument("--muscle", default="shadow_6x300_acra2012",
                   help="starting muscle: a parameter set name or a muscle.toml path")
    s.add_argument("--model", help="static force model (default: the muscle's own)")
    s.add_argument("--free", type=_names, help="comma-separated coefficients to fit (default: the model's own)")
    s.add_argument("--objective", choices=static_fit.OBJECTIVES,
                   help="force or contraction (default: contraction for hung weights, force for measured forces)")
    s.add_argument("--compare", type=_names, help="comma-separated models to compare on the same data")
    s.add_argument("--columns", type=_columns, default={},
                   help="map quantities to other column names: pressure=NAME,contraction=NAME,force=NAME,weight=NAME")
    s.add_argument("--loss", default="linear", choices=static_fit.LOSSES, help="robust loss (default linear)")
    s.add_argument("--f-scale", type=finite_float, default=1.0,
                   help="scale of the robust loss, in the residual's unit (mm or N; default 1)")
    s.add_argument("--starts", type=_count, default=0, help="extra seeded random starts (default 0)")
    s.add_argument("--seed", type=_count, default=0, help="seed of the starts and of k-fold splits (default 0)")
    s.add_argument("--cv", default="auto", choices=CV_CHOICES,
                   help="cross-validation: auto (leave-one-out up to 100 tests), loo, kfold or none")
    s.add_argument("--folds", type=_count, default=10, help="folds of --cv kfold (default 10)")
    s.add_argument("--censor-threshold-mm", type=finite_float, default=static_fit.CENSOR_THRESHOLD_M * 1e3,
                   help="measured contraction at or below which a hung load counts as not lifted (default 0.5)")
    s.add_argument("-o", "--output", required=True, help="output directory")
    s.add_argument("--json", action="store_true", help="print fit.json to stdout")
    s.set_defaults(func=run_static)


def run_static(args: argparse.Namespace) -> int:
    params, muscle_model = muscle_file.load_muscle_parameters(args.muscle)
    model = args.model or muscle_model
    check_output_dir(args.output)
    data = read_static_data(args.data, args.columns)
    options = dict(objective=args.objective, loss=args.loss, f_scale=args.f_scale, n_starts=args.starts,
                   seed=args.seed, censor_threshold_m=args.censor_threshold_mm * 1e-3, cv=args.cv,
                   k_folds=args.folds)
    fit = static_fit.fit_static(data, params, model=model, free=args.free, muscle_label=args.muscle, **options)
    compared = None
    if args.compare:
        compared = compare.compare_models(data, params, args.compare,
                                          **{**options, "muscle_label": args.muscle})
    names = report.write_static_fit(fit, args.output, compared)
    if args.json:
        body = fit.to_json()
        if compared:
            body["compare"] = compare.comparison_rows(compared)
        print(report.json_text(body), end="")
        return 0
    print(f"{model} on {args.data}: RMS contraction {fit.rms_contraction_mm:.3f} mm "
          f"(cross-validated {fit.cv_rms_contraction_mm:.3f} mm, {fit.cv_kind}), "
          f"{fit.n_points} tests, {fit.n_censored} censored")
    for a, b, r in fit.uncertainty.inseparable_pairs():
        print(f"  warning: {a} and {b} are correlated (r = {r:+.3f}): the data do not separate them")
    print(f"wrote {', '.join(str(Path(args.output) / n) for n in names)}")
    return 0
