"""Wall time of the 66-case ACRA 2012 sweep with 1 and 2 worker processes, and the speed-up.

    python benchmarks/bench_sweep.py [--repeat N]

Two sweeps are timed: the 66 cases alone (default valve, load-dependent friction; the issue's
target is <= 3 s on 2 workers) and the whole ``scenarios/acra2012_grid.toml`` (66 cases x 2
friction models + the 3.6 bar frequency study + the 5 paper scenarios = 156 runs).  Times include
starting the worker processes; writing the figures is timed once, apart.  The best of N repeats
is printed.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pamsim
from pamsim.sweep import load_sweep

GRID = Path(__file__).resolve().parents[1] / "scenarios" / "acra2012_grid.toml"


def wall_time_s(spec, workers: int) -> float:
    """Seconds for one sweep, pool start-up included (1 worker runs in this process)."""
    start = time.perf_counter()
    if workers == 1:
        pamsim.sweep(spec)
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            pamsim.sweep(spec, pool)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="repeats per configuration (best is kept)")
    args = parser.parse_args()
    full = load_sweep(GRID)
    cases_only = dataclasses.replace(full, friction_models=full.friction_models[:1], frequency=None,
                                     time_responses=())
    print(f"{os.cpu_count()} CPUs; best of {args.repeat}")
    print(f"{'sweep':<44} {'runs':>5} {'1 worker [s]':>13} {'2 workers [s]':>14} {'speed-up':>9}")
    for label, spec, runs in (("66 cases, load-dependent, valve", cases_only, 66),
                              ("acra2012_grid.toml (both models + studies)", full, 156)):
        t1 = min(wall_time_s(spec, 1) for _ in range(args.repeat))
        t2 = min(wall_time_s(spec, 2) for _ in range(args.repeat))
        print(f"{label:<44} {runs:>5} {t1:>13.2f} {t2:>14.2f} {t1 / t2:>9.2f}")
    result = pamsim.sweep(full)
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        result.write(out)
        print(f"writing summary.csv, report.md and 4 figures: {time.perf_counter() - start:.2f} s")


if __name__ == "__main__":
    main()
