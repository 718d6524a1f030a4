"""``pamsim sweep SWEEP.toml -o DIR [--workers N]``: run a sweep, write summary, report and figures."""

from __future__ import annotations

import argparse
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from ..atomic import ensure_output_dir
from ..sweep import load_sweep, run_sweep


def _workers(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: need at least one worker")
    return n


def register(sub) -> None:
    p = sub.add_parser("sweep", help="run a sweep file (many cases, compared with measurements)",
                       description="Run every case of a sweep file under each friction model it names and write "
                                   "summary.csv, report.md and PNG figures into DIR.")
    p.add_argument("sweep_file", help="sweep TOML file (see scenarios/acra2012_grid.toml)")
    p.add_argument("-o", "--output", default="out", help="output directory (default: out)")
    p.add_argument("--workers", type=_workers, default=os.cpu_count() or 1,
                   help="worker processes (default: number of CPUs; 1 runs in this process)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    spec = load_sweep(args.sweep_file)
    ensure_output_dir(args.output)  # before the runs, not after them
    if args.workers == 1:
        result = run_sweep(spec, None, progress=not args.no_progress)
    else:
        with ProcessPoolExecutor(max_workers=args.workers) as pool:
            result = run_sweep(spec, pool, progress=not args.no_progress)
    names = result.write(args.output)
    for failure in result.failures:
        print(f"pamsim: warning: failed run {failure}", file=sys.stderr)
    print(f"{spec.name}: {len(result.rows)} cases, {len(result.failures)} failed runs, "
          f"{result.wall_time_s:.2f} s on {args.workers} worker(s)")
    print(f"wrote {', '.join(str(Path(args.output) / n) for n in names)}")
    return 0
