"""The native backend's speed against its targets and against the Python backend, measured in the same run.

    python benchmarks/bench_native.py [--repeat N]

Rows:

- fig4 in process: ``pamsim.simulate(scenario, backend="native")``, the whole call (inputs, the
  library, the Result; its force breakdown waits until read); median of N x 200 calls after 20 warm-up calls
  (a steady state: the first calls also pay for first-touch memory and caches).  The
  library call alone is shown for reference.
- the 66-case grid, serial: the 66 steady-state cases (valve, load-dependent friction) in one
  ``pamsim.native.simulate_batch`` call, Results included; best of N.
- ``pamsim sweep scenarios/acra2012_grid.toml --backend native --workers 2 -o DIR``: a fresh
  process, end to end (start, imports, 156 runs, report and figures); best of N.
- the 10,000-sample fig4 uncertainty sweep on 2 workers, if ``scenarios/acra2012_fig4_uncertainty.toml``
  exists (it belongs to the uncertainty studies).

The Python backend runs the same work once per row for the ratio (the CLI row: once, without repeats).
Each row also gives the CPU time the native run used (this process, or the CLI process and its
workers): on a machine shared with other jobs the wall time grows with the load average, the CPU
time much less.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pamsim
from pamsim.native import simulate_batch
from pamsim.native.backend import _run, case_inputs
from pamsim.sweep import load_sweep

ROOT = Path(__file__).resolve().parents[1]
GRID = ROOT / "scenarios" / "acra2012_grid.toml"
FIG4 = ROOT / "scenarios" / "acra2012_fig4.toml"
UNCERTAINTY = ROOT / "scenarios" / "acra2012_fig4_uncertainty.toml"


def _cpu_s() -> float:
    """CPU seconds of this process and of its finished children (the CLI and its workers)."""
    own = time.process_time()
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own + kids.ru_utime + kids.ru_stime


def per_call_s(fn, calls: int = 20, repeat: int = 3) -> tuple[float, float]:
    """Median wall and CPU seconds per call over ``repeat`` x ``calls`` calls, after one warm-up call."""
    fn()
    walls, cpus = [], []
    for _ in range(repeat):
        start, cpu = time.perf_counter(), _cpu_s()
        for _ in range(calls):
            fn()
        walls.append((time.perf_counter() - start) / calls)
        cpus.append((_cpu_s() - cpu) / calls)
    return statistics.median(walls), statistics.median(cpus)


def best_s(fn, repeat: int) -> tuple[float, float]:
    """Best wall seconds of ``repeat`` calls, and the CPU seconds of that call."""
    best = (float("inf"), float("inf"))
    for _ in range(repeat):
        start, cpu = time.perf_counter(), _cpu_s()
        fn()
        best = min(best, (time.perf_counter() - start, _cpu_s() - cpu))
    return best


def cli_sweep_s(sweep: Path, backend: str, repeat: int, extra: tuple[str, ...] = ()) -> tuple[float, float]:
    def run():
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([sys.executable, "-m", "pamsim", "sweep", str(sweep), "--backend", backend, "--workers",
                            "2", "--no-progress", "-o", str(Path(out) / "sweep"), *extra], check=True,
                           capture_output=True)
    return best_s(run, repeat)


def row(label: str, native: tuple[float, float], target: str, limit_s: float | None, python_s: float | None,
        min_speedup: float = 1.0) -> None:
    wall, cpu = native
    fast_enough = python_s is None or python_s / wall >= min_speedup
    met = "" if limit_s is None else "yes" if wall <= limit_s and fast_enough else "NO"
    ratio = f"{python_s / wall:8.1f}x" if python_s else "       -"
    py = f"{python_s * 1e3:11.1f}" if python_s else "          -"
    print(f"{label:<58} {wall * 1e3:10.2f} {cpu * 1e3:10.2f} {target:>9} {met:>4} {py} {ratio}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="repeats per row (best or median kept)")
    args = parser.parse_args()
    print(f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}; repeat {args.repeat}")
    print(f"{'measure':<58} {'wall [ms]':>10} {'CPU [ms]':>10} {'target':>9} {'met':>4} {'python [ms]':>11} "
          f"{'faster':>9}")

    fig4 = pamsim.load_scenario(FIG4)
    for _ in range(20):
        pamsim.simulate(fig4, backend="native")
    native = per_call_s(lambda: pamsim.simulate(fig4, backend="native"), calls=200, repeat=args.repeat)
    python = per_call_s(lambda: pamsim.simulate(fig4), calls=3, repeat=args.repeat)[0]
    row("fig4 in process, pamsim.simulate(backend='native')", native, "<= 1 ms", 1e-3, python, min_speedup=15.0)
    case = case_inputs(fig4)
    row("  of which the library call (trace only)", per_call_s(lambda: _run([case], [1024]), repeat=args.repeat),
        "", None, None)

    full = load_sweep(GRID)
    cases = [full.case_scenario(c, full.friction_models[0]) for c in full.cases]
    native = best_s(lambda: simulate_batch(cases), args.repeat)
    python = best_s(lambda: [pamsim.simulate(s) for s in cases], 1)[0]
    row(f"{len(cases)}-case grid, native serial (one simulate_batch call)", native, "<= 60 ms", 0.06, python)

    native = cli_sweep_s(GRID, "native", args.repeat)
    python = cli_sweep_s(GRID, "python", 1)[0]
    row("pamsim sweep acra2012_grid.toml --workers 2, end to end", native, "<= 2.5 s", 2.5, python)

    if UNCERTAINTY.is_file():
        row("10,000-sample fig4 uncertainty sweep, 2 workers, end to end", cli_sweep_s(UNCERTAINTY, "native", 1),
            "<= 15 s", 15.0, None)
    else:
        print(f"({UNCERTAINTY.name} not in this checkout: the uncertainty row is not measured)")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
