"""``pamsim fit static``, ``pamsim fit dynamic`` and ``pamsim fit hysteresis``: identify a muscle from measurements
(docs/identification.md, docs/hysteresis.md)."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from ..atomic import OutputError, ensure_output_dir
from ..identification import choices
from . import figure_args, finite_float, int_at_least
from .pool import process_pool

# The numerical modules (numpy, scipy, matplotlib) are imported by the run functions, not here:
# `pamsim --help` must not load them.


def _names(text: str) -> list[str]:
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise argparse.ArgumentTypeError(f"{text!r}: give comma-separated names")
    return names


def _columns(text: str, form: str = "QUANTITY=COLUMN, e.g. pressure=p_meas_kPa") -> dict[str, str]:
    out = {}
    for item in text.split(","):
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise argparse.ArgumentTypeError(f"{item!r}: write {form}")
        out[key.strip()] = value.strip()
    return out


_count = int_at_least(0)
_workers = int_at_least(1)


def _window(text: str) -> tuple[float, float]:
    a, sep, b = text.partition(":")
    try:
        t0, t1 = float(a), float(b)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: write T0:T1 in seconds, e.g. 1.4:6") from None
    if not sep or not t1 > t0:
        raise argparse.ArgumentTypeError(f"{text!r}: need T0:T1 with T1 > T0")
    return t0, t1


def _loads(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give one weight in N per trace, comma-separated") from None
    if not all(v > 0 for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: weights must be positive")
    return values


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
    """Add ``pamsim fit static``, ``pamsim fit dynamic`` and ``pamsim fit hysteresis`` and their options to ``sub``, the subparsers of
    :func:`pamsim.cli.build_parser`.
    """
    p = sub.add_parser("fit", help="identify a muscle from static tests, step responses or hysteresis loops",
                       description="Fit static force coefficients to static tests (fit static), friction and "
                                   "damping coefficients to step responses (fit dynamic), or a hysteresis model "
                                   "to a force-contraction loop (fit hysteresis).")
    fsub = p.add_subparsers(dest="fit_kind", required=True, metavar="KIND")
    s = fsub.add_parser("static", help="fit a static force model to static tests",
                        description="Fit a static force model to static tests (pressure, contraction, hung weight "
                                    "or measured force) and write fit.json, muscle.toml, report.md and figures.")
    s.add_argument("data", help="CSV with unit-suffixed columns (e.g. pamsim/data/acra2012_steady_state.csv)")
    s.add_argument("--muscle", default="shadow_6x300_acra2012",
                   help="starting muscle: a parameter set name or a muscle.toml path")
    s.add_argument("--model", help="static force model (default: the muscle's own)")
    s.add_argument("--free", type=_names, help="comma-separated coefficients to fit (default: the model's own)")
    s.add_argument("--objective", choices=choices.OBJECTIVES,
                   help="force or contraction (default: contraction for hung weights, force for measured forces)")
    s.add_argument("--compare", type=_names, help="comma-separated models to compare on the same data")
    s.add_argument("--columns", type=_columns, default={},
                   help="map quantities to other column names: pressure=NAME,contraction=NAME,force=NAME,weight=NAME")
    s.add_argument("--loss", default="linear", choices=choices.LOSSES, help="robust loss (default linear)")
    s.add_argument("--f-scale", type=finite_float, default=1.0,
                   help="scale of the robust loss, in the residual's unit (mm or N; default 1)")
    s.add_argument("--starts", type=_count, default=0, help="extra seeded random starts (default 0)")
    s.add_argument("--seed", type=_count, default=0, help="seed of the starts and of k-fold splits (default 0)")
    s.add_argument("--cv", default="auto", choices=choices.CV_CHOICES,
                   help="cross-validation: auto (leave-one-out up to 100 tests), loo, kfold or none")
    s.add_argument("--folds", type=_count, default=10, help="folds of --cv kfold (default 10)")
    s.add_argument("--censor-threshold-mm", type=finite_float, default=choices.CENSOR_THRESHOLD_M * 1e3,
                   help="measured contraction at or below which a hung load counts as not lifted (default 0.5)")
    s.add_argument("-o", "--output", required=True, help="output directory")
    s.add_argument("--json", action="store_true", help="print fit.json to stdout")
    figure_args.add_arguments(s)
    s.set_defaults(func=run_static)

    d = fsub.add_parser("dynamic", help="fit friction and damping to step responses (eq. 13)",
                        description="Fit coefficients to measured step responses with the hybrid simulator inside "
                                    "(the paper's eq. 13) and write fit.json, muscle.toml, scenario.toml, report.md "
                                    "and figures.")
    d.add_argument("traces", nargs="+", help="CSV traces with t_s, x_m (or x_mm) and optionally p_gauge_Pa, weight_N")
    d.add_argument("--scenario", required=True, help="scenario TOML: parameter set, elements, valve, solver")
    d.add_argument("--free", type=_names, default=list(choices.DYNAMIC_DEFAULT_FREE),
                   help="comma-separated coefficients to fit (default: D1, D2, N2, N1, N0 of the paper)")
    d.add_argument("--window", type=_window, help="time window T0:T1 [s] of the residuals (default: whole trace)")
    d.add_argument("--load-N", type=_loads, help="hung weight [N] per trace, comma-separated")
    d.add_argument("--columns", type=_columns, default={}, help="map quantities to other column names")
    d.add_argument("--per-trace", action="store_true", help="also fit every trace alone (Table 4 layout)")
    d.add_argument("--global", dest="global_search", action="store_true",
                   help="differential evolution (30 generations) over the start +- its size or typical scale, "
                        "before the local fits")
    d.add_argument("--starts", type=_count, default=None,
                   help="extra local fits: half from the best of 25 times as many seeded random points, half "
                        "from points near the best fit so far (default 16 with the native backend, 0 with python)")
    d.add_argument("--workers", type=_workers, default=None,
                   help="worker processes for the simulations (default: number of CPUs with the python backend; "
                        "1 with native, whose optimiser steps are too few cases to gain from workers)")
    d.add_argument("--max-iterations", type=_count, default=30, help="residual evaluations of the local fit")
    d.add_argument("--fd-step", type=finite_float, default=choices.FD_RELATIVE_STEP,
                   help="relative finite-difference step (default 1e-3)")
    d.add_argument("--knot-tolerance-Pa", type=finite_float, default=choices.KNOT_TOLERANCE_PA,
                   help="largest deviation of the thinned measured pressure [Pa] (default 10)")
    d.add_argument("--backend", choices=choices.DYNAMIC_BACKENDS, default="python",
                   help="simulator of the fit: python (default) or native (compiled C, one batch per step)")
    d.add_argument("--seed", type=_count, default=0, help="seed of --global and --starts (default 0)")
    d.add_argument("-o", "--output", required=True, help="output directory")
    d.add_argument("--json", action="store_true", help="print fit.json to stdout")
    figure_args.add_arguments(d)
    d.set_defaults(func=run_dynamic)
    register_hysteresis(fsub)


def _print_warnings(uncertainty) -> None:
    """What the data do not show, below a fit's summary."""
    for name in uncertainty.not_identified():
        print(f"  warning: {name} is not identified: the data carry no information on it")
    for a, b, r in uncertainty.inseparable_pairs():
        print(f"  warning: {a} and {b} are correlated (r = {r:+.3f}): the data do not separate them")


def _print_stop(stop: dict) -> None:
    """The tests a static fit predicts on the upper stop, below its summary."""
    on = stop["tests_on_stop"]
    if on:
        print(f"  {len(on)} test(s) predicted on the upper stop ({stop['x_m'] * 1e3:.4g} mm, {stop['at']}): "
              f"{', '.join(str(i) for i in on)} (counted from 0 in the data's order)")


def _warn(lines) -> None:
    """One ``warning:`` line on stderr for each of ``lines``."""
    for line in lines:
        print(f"warning: {line}", file=sys.stderr)


def run_static(args: argparse.Namespace) -> int:
    """``pamsim fit static``: fit the static force model to the static tests of ``DATA.csv`` (and compare models
    with ``--compare``), write the fit, the muscle file, the report and the figures; exit code 0.
    """
    from ..identification import compare, muscle_file, report, static_fit
    from ..identification.columns import read_static_data

    figures = figure_args.options(args)
    params, muscle_model = muscle_file.load_muscle_parameters(args.muscle)
    upper_stop = muscle_file.load_upper_stop(args.muscle)
    model = args.model or muscle_model
    check_output_dir(args.output)
    data = read_static_data(args.data, args.columns)
    _warn(static_fit.check_data(data, params, model, upper_stop))
    options = dict(objective=args.objective, loss=args.loss, f_scale=args.f_scale, n_starts=args.starts,
                   seed=args.seed, censor_threshold_m=args.censor_threshold_mm * 1e-3, cv=args.cv,
                   k_folds=args.folds, upper_stop=upper_stop)
    fit = static_fit.fit_static(data, params, model=model, free=args.free, muscle_label=args.muscle, **options)
    compared = None
    if args.compare:
        # The main fit is one of the compared ones when it uses the model's own free coefficients.
        others = [m for m in args.compare if args.free or m != model]
        fits = dict(zip(others, compare.compare_models(data, params, others,
                                                       **{**options, "muscle_label": args.muscle})))
        compared = [fits.get(m, fit) for m in args.compare]
    names = report.write_static_fit(fit, args.output, compared, *figures)
    if args.json:
        body = fit.to_json()
        if compared:
            body["compare"] = compare.comparison_rows(compared)
        print(report.json_text(body), end="")
        return 0
    cv = "n/a" if fit.cv_kind.startswith("none") else f"{fit.cv_rms_contraction_mm:.3f} mm"
    print(f"{model} on {args.data}: RMS contraction {fit.rms_contraction_mm:.3f} mm "
          f"(cross-validated {cv}, {fit.cv_kind}), "
          f"{fit.n_points} tests, {fit.n_censored} censored")
    _print_stop(fit.upper_stop_json())
    _print_warnings(fit.uncertainty)
    print(f"wrote {', '.join(str(Path(args.output) / n) for n in names)}")
    return 0


def run_dynamic(args: argparse.Namespace) -> int:
    """``pamsim fit dynamic``: fit friction and damping to the step responses with the scenario's model (on
    ``--workers`` processes or the native backend), write the fit, the report and the figures; exit code 0.
    """
    from ..identification import dynamic_fit, report
    from ..identification.columns import read_trace
    from ..scenario import load_scenario

    figures = figure_args.options(args)
    scenario = load_scenario(args.scenario)
    traces = [read_trace(t, args.columns) for t in args.traces]
    check_output_dir(args.output)
    _warn(dynamic_fit.check_data(scenario, traces, args.load_N))
    options = dict(free=args.free, window_s=args.window, loads_N=args.load_N, global_search=args.global_search,
                   per_trace=args.per_trace, seed=args.seed, fd_step=args.fd_step,
                   max_iterations=args.max_iterations, knot_tolerance_Pa=args.knot_tolerance_Pa,
                   backend=args.backend, n_starts=args.starts)
    if args.workers is None:
        args.workers = 1 if args.backend == "native" else os.cpu_count() or 1
    if args.workers == 1:
        fit = dynamic_fit.fit_dynamic(scenario, traces, executor=None, **options)
    else:
        with process_pool(args.workers) as pool:
            fit = dynamic_fit.fit_dynamic(scenario, traces, executor=pool, **options)
    names = report.write_dynamic_fit(fit, args.output, *figures)
    _warn(fit.warnings)
    if args.json:
        print(report.json_text(fit.to_json()), end="")
        return 0
    print(f"{len(traces)} trace(s): pooled RMS {fit.rms_pooled_mm:.4f} mm, {fit.n_simulations} simulations in "
          f"{fit.wall_time_s:.2f} s on {args.workers} worker(s), {args.backend} backend")
    for name, value in fit.parameters.items():
        print(f"  {name} = {value:.6g}")
    _print_warnings(fit.uncertainty)
    print(f"wrote {', '.join(str(Path(args.output) / n) for n in names)}")
    return 0


# ------------------------------------------------------------------ pamsim fit hysteresis
def _numbers(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give numbers, comma-separated, e.g. 0,1,2.5") from None


def _check_hysteresis_options(args: argparse.Namespace) -> None:
    """Refuse a count, threshold list or exponent out of range with one line naming the option (exit 2)."""
    from ..errors import InputError
    from ..hysteresis import checks

    for key in ("elements", "max_elements", "plays"):
        if getattr(args, key) is not None:
            checks.count("--" + key.replace("_", "-"), getattr(args, key))
    r = args.thresholds_mm
    if r is not None:
        text = ",".join(f"{v:g}" for v in r)
        bad = [i for i in range(1, len(r)) if not r[i] > r[i - 1]]
        if bad:
            raise InputError(f"--thresholds-mm = {text!r}: thresholds must increase strictly (threshold {bad[0]}, "
                             f"{r[bad[0]]:g} mm, follows {r[bad[0] - 1]:g} mm)")
        if not r[0] >= 0:
            raise InputError(f"--thresholds-mm = {text!r}: the first threshold must be at least 0")
    if args.exponent is not None:
        checks.number("--exponent", args.exponent, 0.0, strict=True)
    if not args.noise_N >= 0:
        raise InputError(f"--noise-N = {args.noise_N!r}: must be at least 0")


def _parameters(text: str) -> dict[str, float]:
    out = {}
    for key, value in _columns(text, "NAME=VALUE,..., e.g. F0_N=150,k0_N_per_m=-3000").items():
        try:
            out[key] = float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{key}={value!r}: the value is not a number") from None
    return out


def register_hysteresis(fsub) -> None:
    """Add ``pamsim fit hysteresis`` to ``fsub``, the subparsers of ``pamsim fit``."""
    from ..hysteresis import MODELS

    h = fsub.add_parser("hysteresis", help="fit a hysteresis model to a force-contraction loop",
                        description="Fit Maxwell-slip, Prandtl-Ishlinskii and Bouc-Wen models to a loop (contraction "
                                    "in, force out; with --scenario, a pressure-contraction loop at a hanging "
                                    "load, whose force is the weight minus the muscle's static force), report the chosen one's parameters with confidence intervals "
                                    "and AIC/BIC across the models and across N, and write fit.json, report.md, "
                                    "compare.csv and figures (docs/hysteresis.md).  With --write-synthetic, write "
                                    "a synthetic loop to DATA instead.")
    h.add_argument("data", help="loop CSV: t_s, a pressure (p_*_Pa, _kPa, _bar), a contraction (x_m or x_mm) and "
                                "force_N (no force with --scenario)")
    h.add_argument("--scenario", help="the loop was measured at this scenario's hanging load: its force is the "
                                      "weight minus the muscle's static force at the file's contraction and pressure")
    h.add_argument("--model", choices=MODELS, default="maxwell_slip", help="the model reported (default maxwell_slip)")
    h.add_argument("--elements", type=int, help="Maxwell-slip elements N, 1 to 100 (default: chosen by BIC)")
    h.add_argument("--max-elements", type=int, default=6, help="largest N tried for the BIC (default 6)")
    h.add_argument("--plays", type=int, default=8,
                   help="Prandtl-Ishlinskii play operators on the default threshold grid (default 8)")
    h.add_argument("--thresholds-mm", type=_numbers,
                   help="Prandtl-Ishlinskii thresholds [mm], at least 0 and strictly increasing (default: a grid of --plays)")
    h.add_argument("--exponent", type=finite_float, help="Bouc-Wen exponent n, fixed (default: fitted)")
    h.add_argument("--columns", type=_columns, default={},
                   help="map quantities to other column names: time=NAME,pressure=NAME,contraction=NAME,force=NAME")
    h.add_argument("--residual", choices=("correlated", "white"), default="correlated",
                   help="the residual in the intervals and AIC/BIC: correlated (default) counts its effective "
                        "samples when its lag-1 autocorrelation is significant; white takes it as independent noise")
    h.add_argument("--window", type=_window,
                   help="fit the samples of the time window T0:T1 [s] only (default: the whole file)")
    h.add_argument("-o", "--output", help="output directory (required to fit)")
    h.add_argument("--json", action="store_true", help="print fit.json to stdout")
    h.add_argument("--write-synthetic", action="store_true",
                   help="write a synthetic loop of --model with --parameters to DATA (no fit)")
    h.add_argument("--parameters", type=_parameters, default={},
                   help="with --write-synthetic: NAME=VALUE,... named as the fit reports them")
    h.add_argument("--noise-N", type=finite_float, default=0.0, help="with --write-synthetic: force noise [N]")
    h.add_argument("--seed", type=_count, default=0, help="with --write-synthetic: seed of the noise (default 0)")
    figure_args.add_arguments(h)
    h.set_defaults(func=run_hysteresis)


def run_hysteresis(args: argparse.Namespace) -> int:
    """``pamsim fit hysteresis``: fit the loop of ``DATA`` (or write a synthetic one); exit code 0."""
    from ..errors import InputError

    _check_hysteresis_options(args)
    thresholds_m = None if args.thresholds_mm is None else [v * 1e-3 for v in args.thresholds_mm]
    if args.write_synthetic:
        for key in ("scenario", "window"):
            if getattr(args, key) is not None:
                raise InputError(f"--{key} = {getattr(args, key)!r}: only to fit a loop, not with --write-synthetic")
        if not args.parameters:
            raise InputError(f"--parameters: required with --write-synthetic: the {args.model} model's values, named "
                             "as the fit reports them (NAME=VALUE,...: docs/hysteresis.md, 'An example')")
        return _write_synthetic(args, thresholds_m)
    if args.output is None:
        raise InputError("-o/--output: required to fit (the folder for fit.json, report.md and the figures)")
    from ..hysteresis import fit_hysteresis, read_loop
    from ..hysteresis.report import summary_lines, write_hysteresis_fit

    figures = figure_args.options(args)
    check_output_dir(args.output)
    hanging_load = None
    if args.scenario is not None:
        from ..hysteresis.hanging_load import HangingWeight

        hanging_load = HangingWeight.from_scenario(args.scenario)
    data = read_loop(args.data, args.columns, hanging_load)
    if args.window is not None:
        data = data.window(*args.window)
    fit = fit_hysteresis(data, args.model, elements=args.elements, max_elements=args.max_elements,
                         plays=args.plays, thresholds_m=thresholds_m, exponent=args.exponent, residual=args.residual)
    names = write_hysteresis_fit(fit, args.output, *figures)
    if args.json:
        from ..identification.report import json_text

        print(json_text(fit.to_json()), end="")
        return 0
    print("\n".join(summary_lines(fit)))
    print(f"wrote {', '.join(str(Path(args.output) / n) for n in names)}")
    return 0


def _write_synthetic(args: argparse.Namespace, thresholds_m) -> int:
    """``--write-synthetic``: the loop of ``--model`` with ``--parameters`` over the default cycle, to DATA."""
    from ..atomic import atomic_path
    from ..hysteresis.loop_data import write_loop_csv
    from ..hysteresis.synthetic import pull_from_parameters, synthetic_loop

    pull = pull_from_parameters(args.model, args.parameters, thresholds_m)
    loop = synthetic_loop(pull, args.noise_N, args.seed, label=f"synthetic {args.model}")
    with atomic_path(args.data) as tmp:
        write_loop_csv(loop, tmp)
    print(f"wrote {args.data}: {len(loop)} samples of {args.model} with noise {args.noise_N:g} N (seed {args.seed})")
    return 0
