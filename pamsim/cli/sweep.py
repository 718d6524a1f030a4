"""``pamsim sweep SWEEP.toml -o DIR [--workers N | --dask ADDRESS | --dask-local N] [--chunk-size N]``:
run a sweep, write summary, report and figures."""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from pathlib import Path

from ..atomic import output_folder
from ..backends import BACKENDS
from . import figure_args, int_at_least
from .pool import process_pool


_workers = int_at_least(1)

MAX_FAILURE_LINES = 10
"""Failed runs named one per line on stderr; the tables hold them all."""


def register(sub) -> None:
    """Add ``pamsim sweep`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("sweep", help="run a sweep file (many cases, compared with measurements)",
                       description="Run every case of a sweep file under each friction model it names and write "
                                   "summary.csv, report.md and figures (PNG, or PDF or SVG with --format) into DIR.")
    p.add_argument("sweep_file", help="sweep TOML file (see scenarios/acra2012_grid.toml)")
    p.add_argument("-o", "--output", default="out", help="output directory (default: out)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_workers, default=None,
                       help="worker processes (default: number of CPUs; 1 runs in this process)")
    where.add_argument("--dask", metavar="ADDRESS",
                       help="run on a running Dask scheduler, e.g. tcp://host:8786 (needs pamsim[dask])")
    where.add_argument("--dask-local", metavar="N", type=_workers,
                       help="start a Dask LocalCluster of N worker processes (needs pamsim[dask])")
    p.add_argument("--chunk-size", metavar="N", type=_workers, default=None,
                   help="runs per executor task (default: about 32 chunks, at most 50 runs each with the python "
                        "backend, 1000 with native)")
    p.add_argument("--backend", choices=sorted(BACKENDS), default=None,
                   help="backend of every run (default: the sweep file's backend key, else python)")
    p.add_argument("--allow-incomplete", action="store_true",
                   help="keep going when runs are lost to the executor (a worker or cluster gone): write what "
                        "finished, the lost runs as failed rows and the uncertainty summary marked incomplete "
                        "(default: stop with exit code 3 and write nothing)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    figure_args.add_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim sweep``: run the sweep file's cases on worker processes or a Dask cluster and write the summary,
    report and figures into ``--output``; exit code 0 (a failed run is a warning on stderr), 3 when runs are
    lost to the executor (unless ``--allow-incomplete``) or the cluster goes away.
    """
    from ..sweep.dask_cluster import dask_executor, start_worker_server

    fmt, dpi = figure_args.options(args)
    if args.dask_local is not None:
        # The local workers' fork server imports Dask and pamsim while this process reads the sweep.
        start_worker_server()
    from ..sweep import load_sweep, run_sweep
    from ..sweep.run import check_backend

    spec = load_sweep(args.sweep_file)
    check_backend(spec, args.backend or spec.backend)  # before the output folder and the runs
    workers = args.workers or os.cpu_count() or 1
    with contextlib.ExitStack() as stack:
        # A missing Dask or an unreachable scheduler fails before the output folder is made.
        if args.dask is not None or args.dask_local is not None:
            executor, where = stack.enter_context(dask_executor(args.dask, args.dask_local))
        elif workers == 1:
            executor, where = None, "1 worker"
        else:
            executor = stack.enter_context(process_pool(workers))
            where = f"{workers} worker processes"
        with output_folder(args.output) as out:  # checked before the runs; removed again if nothing gets written
            result = run_sweep(spec, executor, progress=not args.no_progress, backend=args.backend,
                               chunk_size=args.chunk_size, allow_incomplete=args.allow_incomplete, output_dir=out)
            with result:  # the samples table's temporary file goes once the outputs are written, or not
                names = result.write(out, executor, fmt, dpi)
    _print_outcome(result, where, args.output, names)
    return 0


def _print_outcome(result, where: str, output: str, names: list[str]) -> None:
    """The failed runs (at most :data:`MAX_FAILURE_LINES` of them) on stderr, the summary line and the files
    written on stdout."""
    for failure in result.failures[:MAX_FAILURE_LINES]:
        print(f"pamsim: warning: failed run {failure}", file=sys.stderr)
    if result.failed_runs > MAX_FAILURE_LINES:
        print(f"pamsim: warning: {result.failed_runs - MAX_FAILURE_LINES} more failed runs (every one is a row "
              "with its message in the tables)", file=sys.stderr)
    spec = result.spec
    samples = f", {spec.uncertainty.samples} uncertainty samples" if spec.uncertainty is not None else ""
    lost = f" ({result.lost} lost: an incomplete sweep)" if result.lost else ""
    print(f"{spec.name}: {len(result.rows)} cases{samples}, {result.failed_runs} failed runs{lost}, "
          f"{result.wall_time_s:.2f} s on {where}")
    print(f"wrote {', '.join(str(Path(output) / n) for n in names)}")
