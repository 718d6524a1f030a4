"""Start-up time of the quick commands: ``pamsim --help`` and ``pamsim static``.

Prints the median wall time of each command in a fresh interpreter beside the
target (0.4 s) and as a ratio, with a bare ``python -c pass`` for reference
(on a loaded machine every figure grows; compare the ratios to it).  The test
suite checks the cause instead (which heavy modules get imported), never the time.

Run:  python benchmarks/bench_startup.py [--repeats N]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

TARGET_S = 0.4
COMMANDS = {
    "python -c pass": [sys.executable, "-c", "pass"],
    "pamsim --help": [sys.executable, "-m", "pamsim", "--help"],
    "pamsim static": [sys.executable, "-m", "pamsim", "static", "--pressure-bar", "3.6", "--load-N", "22.74"],
}


def median_wall_s(argv: list[str], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(f"{'command':<16} {'median [s]':>10} {'target [s]':>10} {'ratio':>6}")
    for name, argv in COMMANDS.items():
        t = median_wall_s(argv, args.repeats)
        target = TARGET_S if name.startswith("pamsim") else float("nan")
        print(f"{name:<16} {t:>10.3f} {target:>10.2f} {t / target:>6.2f}")


if __name__ == "__main__":
    main()
