"""``pamsim run SCENARIO -o DIR``: simulate scenarios (files, or folders of them), write NAME.csv, NAME.json and a figure (NAME.png) for each.

A scenario with a ``[controller]`` table runs with its controller.  A folder
stands for the scenario files in it (sweep files, which name a
``base_scenario``, are left to ``pamsim sweep``).
"""

from __future__ import annotations

import argparse
import json
import sys
import tomllib
from pathlib import Path

from ..atomic import atomic_outputs, output_folder
from ..backends import BACKENDS, DESCRIPTIONS, check_backend
from ..errors import InputError
from . import figure_args, finite_float
from .length_run import check_length_drive, is_length_driven, run_length_drive
from .outputs import rhs_text, wall_time_text, write_run_files

MAX_CSV_MB = 200.0
"""Default limit of ``pamsim run --max-csv-MB``: a CSV beyond it is refused before the run."""


def register(sub) -> None:
    """Add ``pamsim run`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("run", help="simulate scenario files",
                       description="Simulate scenarios and write NAME.csv, NAME.json and the figure NAME.png "
                                   "(or .pdf, .svg with --format) for each into DIR.  A scenario with a [controller] "
                                   "table runs with its controller; exit code 1 if such a run misses its "
                                   "[controller.spec].")
    p.add_argument("scenario", nargs="+", help="scenario TOML files, or folders of them (e.g. scenarios/)")
    p.add_argument("-o", "--output", default="out", help="output directory (default: out)")
    p.add_argument("--backend", default="python", choices=sorted(BACKENDS),
                   help="; ".join(f"{name}: {DESCRIPTIONS[name]}" for name in BACKENDS))
    p.add_argument("--no-plot", action="store_true", help="skip the figure")
    p.add_argument("--no-measured", action="store_true",
                   help="leave the measured end of the test that a scenario's [measured] table names (the ACRA 2012 "
                        "paper's final contraction and pressure) out of the figure")
    figure_args.add_arguments(p)
    p.add_argument("--max-csv-MB", type=finite_float, default=MAX_CSV_MB, metavar="MB",
                   help=f"refuse a run whose CSV could exceed this size (default {MAX_CSV_MB:g} MB; "
                        "the estimate is an upper bound, about twice the usual size)")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar on stderr (shown after 1 s on a terminal)")
    p.set_defaults(func=run)


def _is_sweep_file(path: Path) -> bool:
    try:
        return "base_scenario" in tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, OSError):
        return False  # load_scenario reports it


def scenario_paths(arguments: list[str]) -> list[Path]:
    """The scenario files the arguments name: files as given, folders as their ``*.toml`` files (sorted)."""
    paths = []
    for arg in arguments:
        path = Path(arg)
        if path.is_dir():
            found = [p for p in sorted(path.glob("*.toml")) if not _is_sweep_file(p)]
            if not found:
                raise InputError(f"{path}: no scenario files (*.toml) in this folder")
            paths += found
        else:
            paths.append(path)
    return paths


def run(args: argparse.Namespace) -> int:
    """``pamsim run``: check every scenario, then simulate each and write its CSV, JSON and figure into
    ``--output``; exit code 1 if a closed-loop run misses its ``[controller.spec]``, else 0.
    """
    args.figures = figure_args.options(args)
    if not args.max_csv_MB > 0:
        raise InputError(f"--max-csv-MB = {args.max_csv_MB:g}: must be positive")
    scenarios = [load_any_scenario(p) for p in scenario_paths(args.scenario)]  # every file checked before any run
    seen = {}
    for sc in scenarios:
        if sc.name in seen:
            raise InputError(f"{sc.origin}: name = {sc.name!r}: {seen[sc.name]} has the same name; "
                             "their outputs would overwrite each other")
        seen[sc.name] = sc.origin
        if is_joint(sc):
            _check_joint(sc, args)
            continue
        if is_length_driven(sc):
            check_length_drive(sc, args)
            continue
        _check_csv_size(sc, args.max_csv_MB)
        check_backend(args.backend, sc)  # a setting the backend cannot honour, before any run
    missed = 0
    with output_folder(args.output) as out:  # checked before the runs; removed again if nothing gets written
        for scenario in scenarios:
            missed += bool(_run_joint(scenario, args, out) if is_joint(scenario) else _run_one(scenario, args, out))
    return 1 if missed else 0


def load_any_scenario(path: Path):
    """A one-muscle scenario, or muscles on a joint (a file with ``[joint]`` or ``[[muscle]]`` tables)."""
    from ..joints import is_joint_spec, load_joint_scenario
    from ..scenario import load_scenario

    try:
        spec = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, OSError):
        spec = {}  # load_scenario reports it
    return load_joint_scenario(path) if is_joint_spec(spec) else load_scenario(path)


def is_joint(scenario) -> bool:
    """Whether ``scenario`` is muscles on a joint (:class:`pamsim.joints.JointScenario`)."""
    return type(scenario).__name__ == "JointScenario"  # without importing pamsim.joints for --help


def _run_joint_controller(scenario, args: argparse.Namespace, out: Path) -> list[str]:
    """A joint under its ``[controller]``: write NAME.csv, NAME.json and the figure; return the spec's misses."""
    from ..figure_style import save
    from ..joints.control import controller_of, metrics, spec_failures
    from ..joints.plots import closed_loop_figure
    from ..result import write_columns

    controller = controller_of(scenario)
    run = controller.run(args.backend)
    measured = metrics(run, controller.reference, scenario.controller["settle_s"], scenario.duration_s)
    failures = spec_failures(measured, scenario.controller["spec"])
    names = tuple(t["name"] for t, _ in scenario.muscles)
    summary = {"name": scenario.name, "backend": args.backend,
               "gains": {k: float(v) for k, v in vars(controller.gains).items()}, "metrics": measured,
               "spec": scenario.controller["spec"], "meets_spec": not failures, "failures": failures,
               "final_theta_rad": float(run.theta_rad[-1])}
    fmt, dpi = args.figures
    files = [f"{scenario.name}.csv", f"{scenario.name}.json"] + ([] if args.no_plot else [f"{scenario.name}.{fmt}"])
    with atomic_outputs(out, files) as tmp:
        write_columns(tmp[files[0]], run.columns(names))
        tmp[files[1]].write_text(json.dumps(summary, indent=2) + "\n")
        if not args.no_plot:
            save(closed_loop_figure(run, names, f"{scenario.name}: angle at "
                                    f"{controller.k_Nm_per_rad:g} N m/rad ({args.backend})"), tmp[files[2]],
                 fmt=fmt, dpi=dpi)
    print(f"{scenario.name}: " + ", ".join(f"{k} {v:.4g}" for k, v in measured.items())
          + f"; gains Kp {controller.gains.Kp:.4g} N m/rad, Ki {controller.gains.Ki:.4g} N m/(rad s), "
          f"Kd {controller.gains.Kd:.4g} N m s/rad")
    print("  meets its specification" if not failures else "  misses its specification: " + "; ".join(failures))
    print(f"wrote {', '.join(str(out / n) for n in files)}")
    return failures


def _check_joint(scenario, args: argparse.Namespace) -> None:
    from ..joints import BACKENDS as JOINT_BACKENDS

    if scenario.controller is not None and args.backend not in ("python", "native", "fmu-cs"):
        raise InputError(f"{scenario.origin}: --backend {args.backend}: a joint under a [controller] runs on the "
                         "python, native and fmu-cs backends (the controller steps the plant sample by sample)")
    if args.backend not in JOINT_BACKENDS:
        raise InputError(f"{scenario.origin}: --backend {args.backend}: muscles on a joint run on the "
                         f"{' and '.join(JOINT_BACKENDS)} backends so far")
    n = int(round(scenario.duration_s * scenario.solver.sample_rate_Hz)) + 1
    size_MB = n * (4 + 4 * len(scenario.muscles) + 3) * 18 / 1e6  # at most 18 characters a value
    if size_MB > args.max_csv_MB:
        raise InputError(f"{scenario.origin}: simulation.sample_rate_Hz = {scenario.solver.sample_rate_Hz:g}: {n} "
                         f"samples make a CSV of up to {size_MB:.0f} MB, above the limit of {args.max_csv_MB:g} MB")


def _run_joint(scenario, args: argparse.Namespace, out: Path) -> list[str]:
    """Run muscles on a joint and write NAME.csv, NAME.json and the figure."""
    from ..joints import simulate_joint
    from ..joints.plots import joint_figure
    from ..joints.static import JointStatics

    if scenario.controller is not None:
        return _run_joint_controller(scenario, args, out)
    result = simulate_joint(scenario, args.backend)
    summary = result.summary()
    joint = scenario.body.name == "joint"
    if joint:  # a slider's statics are its muscles' force balance, which pamsim static gives per muscle
        eq = JointStatics(scenario).equilibrium([v["p_gauge_Pa"] for v in summary["muscles"].values()])
        summary["equilibrium_at_final_pressures"] = {"theta_rad": eq.theta_rad, "k_Nm_per_rad": eq.k_Nm_per_rad,
                                                     "on_limit": eq.on_limit}
    names = write_run_files(out, scenario.name, args, result.to_csv, summary, lambda: joint_figure(result))
    muscles = ", ".join(f"{m} {v['p_gauge_Pa'] / 1e5:.3f} bar, {v['F_tendon_N']:.2f} N" for m, v in summary["muscles"].items())
    pos = scenario.body.position
    final = f"final angle {summary[f'final_{pos}']:.4f} rad" if joint else f"final position {summary[f'final_{pos}'] * 1e3:.3f} mm"
    print(f"{scenario.name}: {final} ({summary['final_mode']}), {muscles}; "
          f"{len(summary['events'])} events, {rhs_text(result.stats['rhs_evaluations'], args.backend)}, "
          f"{wall_time_text(result.wall_time_s)}")
    if joint:
        print(f"  at rest at these pressures the joint balances at {eq.theta_rad:.4f} rad"
              + (f" (on its {eq.on_limit} limit)" if eq.on_limit else "") + f", stiffness {eq.k_Nm_per_rad:.4g} N m/rad")
    print(f"wrote {', '.join(str(out / n) for n in names)}")
    return []


def _check_csv_size(scenario, limit_MB: float) -> None:
    from ..result import Result
    from ..simulator import n_samples

    n = n_samples(scenario.duration_s, scenario.solver.sample_rate_Hz)
    size_MB = Result.csv_bytes_estimate(scenario.build_model(), n) / 1e6
    if size_MB > limit_MB:
        raise InputError(f"{scenario.origin}: simulation.sample_rate_Hz = {scenario.solver.sample_rate_Hz:g}: "
                         f"{n} samples over {scenario.duration_s:g} s make a CSV of up to {size_MB:.0f} MB, above "
                         f"the limit of {limit_MB:g} MB (lower the rate, or raise the limit with --max-csv-MB)")


def _measured_warnings(scenario, outcome) -> list[str]:
    """A ``[measured]`` table that names no test at the scenario's conditions: said, since nothing is drawn."""
    name = scenario.spec.get("measured", {}).get("steady_state")
    if name is None or outcome.measured is not None or outcome.closed_loop is not None:
        return []
    pr = scenario.spec["pressure"]
    at = (f"a {scenario.final_pressure_gauge_Pa / 1e5:g} bar supply step" if pr["source"] == "valve"
          else "a prescribed pressure (its tests are valve steps)")
    return [f"measured.steady_state = {name!r}: no measured test at {at} with "
            f"{scenario.mass_kg * scenario.parameters['g_m_s2']:g} N; the figure shows no measured values"]


def _run_compensation(scenario, args: argparse.Namespace, out: Path) -> list[str]:
    """A ``[compensation]`` study: write NAME.json (figures), NAME.csv (the tracking runs), NAME_identification.csv
    (the noisy loop, in the format ``pamsim fit hysteresis`` reads) and the figure; return what misses the spec."""
    from ..figure_style import save
    from ..hysteresis.compensation import run_compensation, write_tracking_csv
    from ..hysteresis.loop_data import write_loop_csv
    from ..hysteresis.plots import plot_compensation

    study = run_compensation(scenario, args.backend)
    fmt, dpi = args.figures
    names = [f"{scenario.name}.csv", f"{scenario.name}.json", f"{scenario.name}_identification.csv"]
    names += [] if args.no_plot else [f"{scenario.name}.{fmt}"]
    summary = study.summary()
    with atomic_outputs(out, names) as tmp:
        write_tracking_csv(study, tmp[names[0]])
        tmp[names[1]].write_text(json.dumps(summary, indent=2) + "\n")
        write_loop_csv(study.identification.loop, tmp[names[2]])
        if not args.no_plot:
            save(plot_compensation(study), tmp[names[3]], dpi=dpi)
    comp = study.identification.compensator
    print(f"{scenario.name} ({args.backend}): compensator {comp.label} fitted to {len(study.identification.loop)} "
          f"noisy samples, RMS {comp.rms_N:.3g} N")
    for r in summary["tracking"]:
        print(f"  {r['frequency_Hz']:g} Hz: RMS tracking error {r['rms_feedforward_m'] * 1e3:.3f} mm with the "
              f"feedforward alone, {r['rms_compensated_m'] * 1e3:.3f} mm compensated: "
              f"{r['reduction_percent']:.1f} % lower")
    print("  meets its specification" if not summary["failures"]
          else "  misses its specification: " + "; ".join(summary["failures"]))
    print(f"wrote {', '.join(str(out / n) for n in names)}")
    return summary["failures"]


def _run_one(scenario, args: argparse.Namespace, out: Path) -> list[str]:
    """Run one scenario and write its files; returns the controller specification items it misses."""
    from tqdm import tqdm

    if is_length_driven(scenario):
        return run_length_drive(scenario, args, out)
    if "compensation" in scenario.spec:
        return _run_compensation(scenario, args, out)

    from ..api import run as run_scenario

    # Shown only for runs that last over a second, on a terminal (a log keeps every redraw); cleared when done.
    with tqdm(total=scenario.duration_s, desc=scenario.name, unit="s simulated", delay=1.0, leave=False,
              file=sys.stderr, disable=args.no_progress or not sys.stderr.isatty(),
              bar_format="{l_bar}{bar}| {n:.3g}/{total:g} s [{elapsed}<{remaining}]") as bar:
        outcome = run_scenario(scenario, args.backend, progress=lambda t: bar.update(t - bar.n))
    result = outcome.result
    summary = outcome.summary()
    names = write_run_files(out, scenario.name, args, result.to_csv, summary,
                            lambda: outcome.figure(measured=not args.no_measured))
    for warning in result.warnings + _measured_warnings(scenario, outcome):
        print(f"pamsim: warning: {scenario.name}: {warning}", file=sys.stderr)
    s = summary
    print(f"{scenario.name}: final contraction {s['final_contraction_m'] * 1e3:.2f} mm "
          f"(peak {s['peak_contraction_m'] * 1e3:.2f} mm), final pressure {s['final_pressure_gauge_Pa'] / 1e5:.3f} bar, "
          f"{'at rest' if s['at_rest_at_end'] else 'still moving'} ({s['final_mode']}), {s['events']} events, "
          f"{rhs_text(s['rhs_evaluations'], args.backend)}, {wall_time_text(s['wall_time_s'])}")
    if outcome.closed_loop is not None:
        c = s["controller"]
        m = c["metrics"]
        print(f"  controller: rise time {m['rise_time_s'] * 1e3:.1f} ms, overshoot {m['overshoot_percent']:.2f} %, "
              f"settling time {m['settling_time_s'] * 1e3:.1f} ms, steady-state error "
              f"{m['steady_state_error_mm']:.3f} mm; gains K (x [1/m], v [s/m], p [1/Pa], z [1/(m s)]): "
              + ", ".join(f"{k:.4g}" for k in c["gains_K"]))
        print("  meets its specification" if not outcome.failures
              else "  misses its specification: " + "; ".join(outcome.failures))
    print(f"wrote {', '.join(str(out / n) for n in names)}")
    return outcome.failures
