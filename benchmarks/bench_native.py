"""The native backend's speed against its targets and against the Python backend, measured in the same run.

    python benchmarks/bench_native.py [--repeat N]

Rows:

- fig4 in process: ``pamsim.simulate(scenario, backend="native")``, the whole call (inputs, the
  library, the Result with its force breakdown); median of N x 20 calls after a warm-up.  The
  library call alone is shown for reference.
- the 66-case grid, serial: the 66 steady-state cases (valve, load-dependent friction) in one
  ``pamsim.native.simulate_batch`` call, Results included; best of N.
- ``pamsim sweep scenarios/acra2012_grid.toml --backend native --workers 2 -o DIR``: a fresh
  process, end to end (start, imports, 156 runs, report and figures); best of N.
- the 10,000-sample fig4 uncertainty sweep on 2 workers, if ``scenarios/acra2012_fig4_uncertainty.toml``
  exists (it belongs to the uncertainty studies).

The Python backend runs the same work once per row for the ratio (the CLI row: once, without repeats).
"""

from __future__ import annotations

import argparse
import os
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


def per_call_s(fn, calls: int = 20, repeat: int = 3) -> float:
    """Median seconds per call over ``repeat`` x ``calls`` calls, after one warm-up call."""
    fn()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        times.append((time.perf_counter() - start) / calls)
    return statistics.median(times)


def best_s(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def cli_sweep_s(sweep: Path, backend: str, repeat: int, extra: tuple[str, ...] = ()) -> float:
    def run():
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([sys.executable, "-m", "pamsim", "sweep", str(sweep), "--backend", backend, "--workers",
                            "2", "--no-progress", "-o", str(Path(out) / "sweep"), *extra], check=True,
                           capture_output=True)
    return best_s(run, repeat)


def row(label: str, native_s: float, target: str, ok: bool, python_s: float | None) -> None:
    ratio = f"{python_s / native_s:8.1f}x" if python_s else "       -"
    py = f"{python_s * 1e3:11.1f}" if python_s else "          -"
    print(f"{label:<58} {native_s * 1e3:11.2f} {target:>9} {'yes' if ok else 'NO':>4} {py} {ratio}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="repeats per row (best or median kept)")
    args = parser.parse_args()
    print(f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}; repeat {args.repeat}")
    print(f"{'measure':<58} {'native [ms]':>11} {'target':>9} {'met':>4} {'python [ms]':>11} {'faster':>9}")

    fig4 = pamsim.load_scenario(FIG4)
    native = per_call_s(lambda: pamsim.simulate(fig4, backend="native"), repeat=args.repeat)
    python = per_call_s(lambda: pamsim.simulate(fig4), calls=3, repeat=args.repeat)
    row("fig4 in process, pamsim.simulate(backend='native')", native, "<= 1 ms", native <= 1e-3 and
        python / native >= 15, python)
    case = case_inputs(fig4)
    library = per_call_s(lambda: _run([case], [1024]), repeat=args.repeat)
    row("  of which the library call (trace only)", library, "", True, None)

    full = load_sweep(GRID)
    cases = [full.case_scenario(c, full.friction_models[0]) for c in full.cases]
    native = best_s(lambda: simulate_batch(cases), args.repeat)
    python = best_s(lambda: [pamsim.simulate(s) for s in cases], 1)
    row(f"{len(cases)}-case grid, native serial (one simulate_batch call)", native, "<= 60 ms", native <= 0.06,
        python)

    native = cli_sweep_s(GRID, "native", args.repeat)
    python = cli_sweep_s(GRID, "python", 1)
    row("pamsim sweep acra2012_grid.toml --workers 2, end to end", native, "<= 2.5 s", native <= 2.5, python)

    if UNCERTAINTY.is_file():
        native = cli_sweep_s(UNCERTAINTY, "native", 1)
        row("10,000-sample fig4 uncertainty sweep, 2 workers, end to end", native, "<= 15 s", native <= 15.0, None)
    else:
        print(f"({UNCERTAINTY.name} not in this checkout: the uncertainty row is not measured)")


if __name__ == "__main__":
    main()
