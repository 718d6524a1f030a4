"""``pamsim run`` of a scenario with a ``[motion]`` table: the muscle alone driven by its length."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import InputError
from .outputs import rhs_text, wall_time_text, write_run_files


def is_length_driven(scenario) -> bool:
    """Whether ``scenario`` drives a muscle alone by its length (a ``[motion]`` table)."""
    return "motion" in getattr(scenario, "spec", {})


CSV_BYTES_PER_VALUE = 18
"""The most characters a value takes in the CSV (10 significant digits, sign, exponent, comma)."""


def check_length_drive(scenario, args: argparse.Namespace) -> None:
    """Refuse, before any run, a bad ``[motion]`` table, a backend that does not run it, or a CSV above
    ``--max-csv-MB``."""
    from ..muscle_alone import BACKENDS, LengthDrive
    from ..simulator import n_samples

    if args.backend not in BACKENDS:
        raise InputError(f"{scenario.origin}: --backend {args.backend}: a muscle driven by its length runs on "
                         f"{', '.join(BACKENDS)}")
    flat = LengthDrive(scenario).assembly.flatten()
    rate = scenario.solver.sample_rate_Hz
    n = n_samples(scenario.duration_s, rate)
    size_MB = n * (len(flat.states) + len(flat.outputs) + 2) * CSV_BYTES_PER_VALUE / 1e6
    if size_MB > args.max_csv_MB:
        raise InputError(f"{scenario.origin}: simulation.sample_rate_Hz = {rate:g}: {n} samples make a CSV of up to "
                         f"{size_MB:.3g} MB, above the limit of {args.max_csv_MB:g} MB (lower the rate, or raise the "
                         "limit with --max-csv-MB)")


def run_length_drive(scenario, args: argparse.Namespace, out: Path) -> list[str]:
    """Run the muscle along its motion and write NAME.csv (its first columns the loop ``pamsim fit hysteresis``
    reads), NAME.json and the figure."""
    from ..muscle_alone import simulate_length_drive
    from ..muscle_alone.plots import length_drive_figure

    result = simulate_length_drive(scenario, args.backend)
    summary = result.summary()
    names = write_run_files(out, scenario.name, args, result.to_csv, summary, lambda: length_drive_figure(result))
    lo, hi = summary["force_range_N"]
    x0, x1 = summary["contraction_range_m"]
    print(f"{scenario.name} ({args.backend}): {summary['motion']} motion over {x0 * 1e3:.2f} to {x1 * 1e3:.2f} mm, "
          f"force {lo:.3f} to {hi:.3f} N, final {summary['final_force_N']:.3f} N; work done on the muscle "
          f"{summary['work_on_muscle_J'] * 1e3:.4f} mJ; {len(summary['events'])} events, "
          f"{rhs_text(summary['stats']['rhs_evaluations'], args.backend)}, "
          f"{wall_time_text(summary['stats']['wall_time_s'])}")
    print(f"wrote {', '.join(str(out / n) for n in names)}")
    return []
