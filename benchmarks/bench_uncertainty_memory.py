"""Memory an uncertainty study holds per sample while it runs, and the disk its samples table takes.

    python benchmarks/bench_uncertainty_memory.py [--samples 10000 100000] [--workers 2] [--backend native]

Runs ``scenarios/acra2012_fig4_uncertainty.toml`` (4 parameters, 1 friction model) with each sample count,
each in a fresh Python process, on a process pool, and prints per sample:

- the peak of the memory Python and numpy allocated in the sweep's process (``tracemalloc``), from before
  the samples are drawn to the end of ``pamsim.sweep`` (the pool's workers are other processes: what they
  hold does not grow with the sample count);
- the part of it still held by the result (the samples and the columns of the summarised quantities);
- the growth of the process's peak resident memory (``ru_maxrss``) over the sweep;
- the bytes per row of the written ``uncertainty_samples.csv`` and the most the disk check assumes.

The figures divided by the sample count level off as it grows when memory per sample is what grows.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import resource
import subprocess
import sys
import tempfile
import tracemalloc
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

STUDY = Path(__file__).resolve().parents[1] / "scenarios" / "acra2012_fig4_uncertainty.toml"


def measure(samples: int, workers: int, backend: str) -> dict:
    """One study of ``samples`` samples in this process: the figures printed by :func:`main`."""
    import pamsim
    from pamsim.sweep import load_sweep, run

    spec = load_sweep(STUDY)
    spec = dataclasses.replace(spec, uncertainty=dataclasses.replace(spec.uncertainty, samples=samples))
    with ProcessPoolExecutor(max_workers=workers) as pool, tempfile.TemporaryDirectory() as out:
        pamsim.sweep(dataclasses.replace(spec, uncertainty=dataclasses.replace(spec.uncertainty, samples=8)),
                     pool, backend=backend, output_dir=out).close()  # imports, workers and library warm
        rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
        result = pamsim.sweep(spec, pool, backend=backend, output_dir=out)
        held, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        rss_after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        with result:
            result.write(out)
        table = Path(out) / "uncertainty_samples.csv"
        rows = samples * len(spec.friction_models)
        return {"samples": samples, "peak": (peak - base) / samples, "held": (held - base) / samples,
                "rss": (rss_after - rss_before) / samples, "row": table.stat().st_size / rows,
                "row_bound": run.sample_table_bytes(spec) / rows, "planned": run.sample_memory_bytes(spec) / samples,
                "failed": result.failed_runs}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--backend", default="native")
    parser.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(measure(args.samples[0], args.workers, args.backend)))
        return
    print(f"{STUDY.name}, {args.backend} backend, {args.workers} worker processes; bytes per sample")
    print(f"{'samples':>8} {'peak (tracemalloc)':>19} {'held by the result':>19} {'peak RSS growth':>16} "
          f"{'memory check plans':>19} {'CSV row':>8} {'row bound':>10}")
    for n in args.samples:
        proc = subprocess.run([sys.executable, __file__, "--one", "--samples", str(n), "--workers", str(args.workers),
                               "--backend", args.backend], capture_output=True, text=True, check=True)
        m = json.loads(proc.stdout.strip().splitlines()[-1])
        print(f"{n:>8} {m['peak']:>19.1f} {m['held']:>19.1f} {m['rss']:>16.1f} {m['planned']:>19.1f} "
              f"{m['row']:>8.1f} {m['row_bound']:>10.1f}" + (f"  ({m['failed']} failed runs)" if m["failed"] else ""))


if __name__ == "__main__":
    main()
