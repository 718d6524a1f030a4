"""Wall time of the Figure 4 uncertainty study on 2 workers: process pool against a Dask LocalCluster.

    python benchmarks/bench_dask.py [--backend native|python] [--samples N] [--workers 2] [--chunk-size N] [--repeat 1]

Runs ``scenarios/acra2012_fig4_uncertainty.toml`` (10,000 Latin hypercube samples unless
``--samples`` says fewer) with the chosen backend (default native) on a ``ProcessPoolExecutor`` and
on a ``distributed.LocalCluster`` of single-threaded worker processes, both with the same chunking,
measured two ways:

- **the command**: ``pamsim sweep STUDY --backend B --workers 2 -o DIR`` against the same with
  ``--dask-local 2``, end to end (the process's start, reading the file, the runs, the tables and
  the two figures), as ``benchmarks/bench_native.py`` measures the pool's 10,000-sample study;
- **the sweep call**: ``pamsim.sweep(spec, executor)`` in a fresh Python process, timed from before
  the pool or the cluster is made until it is closed (importing Dask and starting the cluster
  included; reading the file, the figures and the tables not).

Each measurement runs in a fresh process, with nothing left warm by an earlier one.  The pool and
the cluster alternate, and the best of ``--repeat`` of each is kept.  Targets: Dask within 1.3x of
the process pool; with the native backend, the 10,000 samples in <= 15 s on the pool.  The results
are also checked to be identical (the command's tables byte for byte).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import pickle
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pamsim
from pamsim.sweep import load_sweep
from pamsim.sweep.dask_cluster import dask_executor
from pamsim.sweep.run import UNCERTAINTY_TABLES

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


def _study_file(directory: Path, samples: int | None) -> Path:
    """The study's sweep file, with ``samples`` samples if given (a copy in ``directory``)."""
    if not samples:
        return STUDY
    text = STUDY.read_text()
    text = re.sub(r"(?m)^samples = \d+", f"samples = {samples}", text)
    text = re.sub(r'(?m)^base_scenario = "(.*)"', lambda m: f'base_scenario = "{(STUDY.parent / m[1]).as_posix()}"', text)
    path = directory / STUDY.name
    path.write_text(text)
    return path


def _command(kind: str, study: Path, out: Path, args) -> float:
    """Wall seconds of ``pamsim sweep`` on the pool or the cluster, from its start to its exit."""
    where = ["--workers", str(args.workers)] if kind == "pool" else ["--dask-local", str(args.workers)]
    chunk = ["--chunk-size", str(args.chunk_size)] if args.chunk_size else []
    shutil.rmtree(out, ignore_errors=True)
    start = time.perf_counter()
    subprocess.run([str(Path(sys.executable).with_name("pamsim")), "sweep", str(study), "--backend", args.backend,
                    *where, *chunk, "-o", str(out), "--no-progress"], check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def _table(label: str, n: int, backend: str, pools: list[float], dasks: list[float]) -> None:
    """Print one comparison: the best times, their ratio and every run."""
    pool_s, dask_s = min(pools), min(dasks)
    pool_target = f"<= {NATIVE_TARGET_S:g} s" if backend == "native" and n == 10000 else ""
    print(f"\n{label} ({backend} backend)")
    print(f"{'executor':<20} {'wall [s]':>9} {'per run [ms]':>13} {'ratio to pool':>14} {'target':>10}   every run [s]")
    for name, best, runs, ratio, target in (
            ("process pool", pool_s, pools, 1.0, pool_target),
            ("Dask LocalCluster", dask_s, dasks, dask_s / pool_s, f"<= {DASK_RATIO_TARGET:g}x")):
        print(f"{name:<20} {best:>9.2f} {1e3 * best / n:>13.2f} {ratio:>14.2f} {target:>10}   "
              + " ".join(f"{t:.2f}" for t in runs))


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
    pools, dasks, command = [], [], {"pool": [], "dask": []}
    with tempfile.TemporaryDirectory() as tmp:
        study = _study_file(Path(tmp), args.samples)
        for _ in range(args.repeat):
            for kind in ("pool", "dask"):
                command[kind].append(_command(kind, study, Path(tmp) / kind, args))
            pools.append(_in_fresh_process("pool", args))
            dasks.append(_in_fresh_process("dask", args))
        same_tables = all((Path(tmp) / "pool" / t).read_bytes() == (Path(tmp) / "dask" / t).read_bytes()
                          for t in UNCERTAINTY_TABLES)
    (_, pool_result), (_, dask_result) = (min(runs, key=lambda r: r[0]) for runs in (pools, dasks))
    identical = all(_same(a, b) for a, b in zip(dask_result.uncertainty.sample_rows(),
                                                pool_result.uncertainty.sample_rows()))
    _table(f"the command, pamsim sweep {STUDY.name} -o DIR, end to end", n, args.backend,
           command["pool"], command["dask"])
    _table("the sweep call, pamsim.sweep(spec, executor), executor start included", n, args.backend,
           [t for t, _ in pools], [t for t, _ in dasks])
    print(f"\ncommand's tables ({', '.join(UNCERTAINTY_TABLES)}) byte-identical: {same_tables}; sweep call's "
          f"results identical: {identical}; failed runs: pool {len(pool_result.failures)}, "
          f"Dask {len(dask_result.failures)}")


if __name__ == "__main__":
    main()
