"""Wall time of the Figure 4 uncertainty study on 2 workers: process pool against a Dask LocalCluster.

    python benchmarks/bench_dask.py [--backend native|python] [--samples N] [--workers 2] [--chunk-size N] [--repeat 1]

Runs ``scenarios/acra2012_fig4_uncertainty.toml`` (10,000 Latin hypercube samples unless
``--samples`` says fewer) with the chosen backend (default native) on a ``ProcessPoolExecutor`` and
on a ``distributed.LocalCluster`` of single-threaded worker processes, both with the same chunking.
Each measurement runs in a fresh Python process, as ``pamsim sweep`` does: its time includes
importing Dask (or not) and starting the pool or the cluster, with nothing left warm by an earlier
one.  The two alternate, and the best of ``--repeat`` of each is kept.  Targets: Dask
within 1.3x of the process pool; with the native backend, the 10,000 samples in <= 15 s on the
pool.  The two results are also checked to be identical.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import pickle
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pamsim
from pamsim.sweep import load_sweep
from pamsim.sweep.dask_cluster import dask_executor

STUDY = Path(__file__).resolve().parents[1] / "scenarios" / "acra2012_fig4_uncertainty.toml"
DASK_RATIO_TARGET = 1.3
NATIVE_TARGET_S = 15.0


def timed_pool(spec, workers: int, chunk_size: int | None):
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=workers) as pool:
        result = pamsim.sweep(spec, pool, chunk_size=chunk_size)
    return time.perf_counter() - start, result


def timed_dask(spec, workers: int, chunk_size: int | None):
    start = time.perf_counter()
    with dask_executor(local_workers=workers) as (executor, _):
        result = pamsim.sweep(spec, executor, chunk_size=chunk_size)
    return time.perf_counter() - start, result


def _same(a: dict, b: dict) -> bool:
    return all(a[k] == b[k] or (isinstance(a[k], float) and math.isnan(a[k]) and math.isnan(b[k]))
               for k in b if k != "wall_time_s")


def _arguments(args) -> list[str]:
    out = ["--backend", args.backend, "--workers", str(args.workers)]
    if args.samples:
        out += ["--samples", str(args.samples)]
    if args.chunk_size:
        out += ["--chunk-size", str(args.chunk_size)]
    return out


def _in_fresh_process(kind: str, args) -> tuple[float, object]:
    """(seconds, result) of one measurement, in a new Python process."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "result.pickle"
        subprocess.run([sys.executable, __file__, "--one", kind, "--out", str(out), *_arguments(args)], check=True)
        return pickle.loads(out.read_bytes())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--backend", choices=("native", "python"), default="native",
                        help="backend of every run (default native; python takes about 20 ms a run)")
    parser.add_argument("--samples", type=int, default=None, help="samples (default: the file's 10,000)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--chunk-size", type=int, default=None, help="runs per task (default: automatic)")
    parser.add_argument("--repeat", type=int, default=1, help="repeats per configuration (best is kept)")
    parser.add_argument("--one", choices=("pool", "dask"), help=argparse.SUPPRESS)  # one measurement, here
    parser.add_argument("--out", help=argparse.SUPPRESS)
    args = parser.parse_args()
    spec = load_sweep(STUDY)
    if args.samples:
        spec = dataclasses.replace(spec, uncertainty=dataclasses.replace(spec.uncertainty, samples=args.samples))
    n = spec.uncertainty.samples
    spec = dataclasses.replace(spec, backend=args.backend)
    if args.one:
        timed = timed_pool if args.one == "pool" else timed_dask
        seconds, result = timed(spec, args.workers, args.chunk_size)
        Path(args.out).write_bytes(pickle.dumps((seconds, result)))
        return
    print(f"{os.cpu_count()} CPUs; {n} samples of {STUDY.name}; {args.workers} workers; "
          f"chunk size {args.chunk_size or 'automatic'}; best of {args.repeat}, each in a fresh process")
    # Alternated, so that a drift of the machine's speed during the benchmark does not favour either.
    pools, dasks = [], []
    for _ in range(args.repeat):
        pools.append(_in_fresh_process("pool", args))
        dasks.append(_in_fresh_process("dask", args))
    (pool_s, pool_result), (dask_s, dask_result) = (min(runs, key=lambda r: r[0]) for runs in (pools, dasks))
    identical = all(_same(a, b) for f in pool_result.uncertainty.outputs
                    for a, b in zip(dask_result.uncertainty.outputs[f], pool_result.uncertainty.outputs[f]))
    pool_target = f"<= {NATIVE_TARGET_S * n / 10000:g} s" if args.backend == "native" else ""
    label = f"({args.backend} backend)"
    print(f"{'executor':<34} {'wall [s]':>9} {'per run [ms]':>13} {'ratio to pool':>14} {'target':>10}")
    print(f"{'process pool ' + label:<34} {pool_s:>9.1f} {1e3 * pool_s / n:>13.2f} {1.0:>14.2f} {pool_target:>10}")
    print(f"{'Dask LocalCluster ' + label:<34} {dask_s:>9.1f} {1e3 * dask_s / n:>13.2f} "
          f"{dask_s / pool_s:>14.2f} {'<= ' + format(DASK_RATIO_TARGET, 'g') + 'x':>10}")
    pool_runs, dask_runs = (" ".join(f"{t:.2f}" for t, _ in runs) for runs in (pools, dasks))
    print(f"every run [s]: pool {pool_runs}; Dask {dask_runs}")
    print(f"Dask results identical to the process pool's: {identical}; failed runs: pool "
          f"{len(pool_result.failures)}, Dask {len(dask_result.failures)}")

if __name__ == "__main__":
    main()
