"""Memory an uncertainty study holds per sample while it runs, and the disk its samples table takes.

    python benchmarks/bench_uncertainty_memory.py [--samples 10000 100000] [--workers 2] [--backend native]

Runs ``scenarios/acra2012_fig4_uncertainty.toml`` (4 parameters, 1 friction model) with each sample count,
each in a fresh Python process, on a process pool, and prints per sample:

- the peak of the memory Python and numpy allocated in the sweep's process (``tracemalloc``), from before
  the samples are drawn to the end of ``pamsim.sweep`` (the pool's workers are other processes: what they
  hold does not grow with the sample count);
- the part of it still held by the result (the samples and the columns of the summarised quantities);
- the growth of the process's peak resident memory (``ru_maxrss``) over the sweep;
- the bytes per row of the written ``uncertainty_samples.csv`` and the most the disk check assumes;

and the memory a chunk out on the executor takes per run in the sweep's process (its tasks, their pickle,
the runs' outputs), the constant that the chunks out add whatever the sample count; and the peak of
drawing 1,000,000 samples of 1 and of 4 parameters alone.

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


def chunk_bytes_per_run(backend: str, runs: int = 1000) -> tuple[float, float, float]:
    """(task, pickled task, output) bytes per run of a chunk of ``runs`` runs (``tracemalloc``)."""
    import pickle

    from pamsim.sweep import load_sweep, run

    spec = load_sweep(STUDY)
    spec = dataclasses.replace(spec, uncertainty=dataclasses.replace(spec.uncertainty, samples=runs))
    tasks = run._Tasks([], spec, spec.uncertainty.draw(), backend)
    run.run_chunk(tasks[0:16])  # the library loaded
    tracemalloc.start()
    sizes = [tracemalloc.get_traced_memory()[0]]
    chunk = tasks[0:runs]
    sizes.append(tracemalloc.get_traced_memory()[0])
    sent = pickle.dumps((run.run_chunk, chunk))
    sizes.append(tracemalloc.get_traced_memory()[0])
    outputs = run.run_chunk(chunk)
    sizes.append(tracemalloc.get_traced_memory()[0])
    tracemalloc.stop()
    del sent, outputs
    return tuple((b - a) / runs for a, b in zip(sizes, sizes[1:]))


def draw_peak_bytes_per_sample(samples: int, parameters: int) -> float:
    """Peak allocated while drawing ``samples`` samples of the study's first ``parameters`` parameters."""
    from pamsim.sweep import load_sweep

    study = load_sweep(STUDY).uncertainty
    study = dataclasses.replace(study, samples=samples, parameters=study.parameters[:parameters])
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    study.draw()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return (peak - base) / samples


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
    task, pickled, output = chunk_bytes_per_run(args.backend)
    print(f"a chunk out, per run: task {task:.0f} B, its pickle {pickled:.0f} B, outputs {output:.0f} B "
          f"(1,000 runs; {args.backend} backend)")
    one, four = (draw_peak_bytes_per_sample(1_000_000, d) for d in (1, 4))
    print(f"drawing 1,000,000 samples peaks at {one:.0f} B per sample for 1 parameter, {four:.0f} B for 4 "
          f"({(four - one) / 3:.0f} B per parameter more)")


if __name__ == "__main__":
    main()
