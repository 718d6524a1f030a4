"""``pamsim run`` of a scenario with a ``[motion]`` table: the muscle alone driven by its length."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import InputError
from .outputs import write_run_files


def is_length_driven(scenario) -> bool:
    """Whether ``scenario`` drives a muscle alone by its length (a ``[motion]`` table)."""
    return "motion" in getattr(scenario, "spec", {})


def check_length_drive(scenario, args: argparse.Namespace) -> None:
    """Refuse, before any run, a bad ``[motion]`` table or a backend that does not run it."""
    from ..muscle_alone import BACKENDS, motion_of

    if args.backend not in BACKENDS:
        raise InputError(f"{scenario.origin}: --backend {args.backend}: a muscle driven by its length runs on "
                         f"{', '.join(BACKENDS)}")
    motion_of(scenario)


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
          f"{summary['stats']['rhs_evaluations']} RHS evaluations, {summary['stats']['wall_time_s'] * 1e3:.0f} ms")
    print(f"wrote {', '.join(str(out / n) for n in names)}")
    return []
