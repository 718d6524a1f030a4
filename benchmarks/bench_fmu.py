"""Benchmark of the FMU (issue 4): the compiled model's own cost against the Python simulator.

Prints, side by side:
  * one 8 s paper scenario (fig. 4): ``pamsim.simulate`` against the C core
    stepped by a small C driver (no FMI layer) and against the FMU stepped by
    fmpy with a coarse communication step (0.1 s), with the contraction
    difference to the Python result so the costs are at comparable accuracy;
  * the 66-case grid of the paper's steady-state tests (valve source, supply
    = stable pressure, valve opens at 1 s, 8 s) in the C core (target < 0.1 s)
    and with ``pamsim.simulate``;
  * fmpy's own overhead per co-simulation step (1 ms against 0.1 s steps) and
    the Model Exchange run through fmpy's CVode.

Run on one core:  taskset -c 0 python benchmarks/bench_fmu.py [--repeats N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402

import pamsim  # noqa: E402
from pamsim.fmu.generate import c_source_dir, write_sources  # noqa: E402
from pamsim.fmu.runner import cached_fmu, run_cs, run_me  # noqa: E402
from pamsim.paperdata import acra2012_steady_state  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TARGET_GRID_S = 0.1


def median_time(fn, repeats: int):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def compile_driver(folder: Path) -> Path:
    src = folder / "sources"
    write_sources(src, 2)
    exe = folder / "grid_driver"
    subprocess.run(["cc", "-O2", "-std=c99", "-I", str(src), str(src / "pam_core.c"),
                    str(c_source_dir() / "bench" / "grid_driver.c"), "-o", str(exe), "-lm"], check=True)
    return exe


def run_driver(exe: Path, cases: list[tuple[float, float]], dt_s: float, t_open_s: float, duration_s: float):
    text = "".join(f"{m!r} {p!r} {t_open_s!r} {duration_s!r}\n" for m, p in cases)
    out = subprocess.run([str(exe), repr(dt_s)], input=text, capture_output=True, text=True, check=True).stdout.split()
    return np.array([float(v) for v in out[:-2]]), float(out[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    sc = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    t_open = float(sc.spec["pressure"]["valve_open_time_s"])
    fmu2 = cached_fmu(2)

    with tempfile.TemporaryDirectory() as tmp:
        exe = compile_driver(Path(tmp))
        t_py, ref = median_time(lambda: pamsim.simulate(sc), args.repeats)
        core = [run_driver(exe, [(sc.mass_kg, sc.final_pressure_gauge_Pa)], 0.1, t_open, sc.duration_s)
                for _ in range(args.repeats)]
        t_core = statistics.median(c[1] for c in core)
        x_core = core[0][0][0]
        coarse = np.arange(0.0, sc.duration_s + 1e-9, 0.1)
        t_cs_coarse, tr_coarse = median_time(lambda: run_cs(sc, 2, communication_times=coarse, fmu_path=fmu2),
                                             args.repeats)
        t_cs_fine, tr_fine = median_time(lambda: run_cs(sc, 2, fmu_path=fmu2), args.repeats)
        t_me, tr_me = median_time(lambda: run_me(sc, 2, fmu_path=fmu2), args.repeats)

        rows = acra2012_steady_state()
        grid = [(float(r["weight_N"]) / sc.parameters["g_m_s2"], float(r["pressure_stable_bar"]) * 1e5) for r in rows]
        runs = [run_driver(exe, grid, 0.1, t_open, sc.duration_s) for _ in range(args.repeats)]
        t_grid_core = statistics.median(r[1] for r in runs)
        x_grid_core = runs[0][0]
        scenarios = [sc.with_changes({"load": {"weight_N": float(r["weight_N"])},
                                      "pressure": {"supply_gauge_bar": float(r["pressure_stable_bar"])}})
                     for r in rows]
        t0 = time.perf_counter()
        x_grid_py = np.array([pamsim.simulate(s).x_m[-1] for s in scenarios])
        t_grid_py = time.perf_counter() - t0

    n_fine, n_coarse = len(tr_fine["t_s"]) - 1, len(coarse) - 1
    per_step = (t_cs_fine - t_cs_coarse) / (n_fine - n_coarse)
    print(f"8 s scenario {sc.name}  (median of {args.repeats})")
    print(f"  {'run':44s} {'time':>10s} {'vs python':>10s} {'|x - x_py| final':>18s}")
    print(f"  {'pamsim.simulate (LSODA, rtol 1e-6)':44s} {t_py * 1e3:8.2f} ms {1.0:9.3f}x {0.0:15.4f} mm")
    for label, t, x in [("C core, C driver, 0.1 s steps", t_core, x_core),
                        ("FMU CS via fmpy, 0.1 s communication steps", t_cs_coarse, tr_coarse["contraction_m"][-1]),
                        ("FMU CS via fmpy, 1 ms communication steps", t_cs_fine, tr_fine["contraction_m"][-1]),
                        ("FMU ME via fmpy CVode, 1 ms output", t_me, tr_me["contraction_m"][-1])]:
        print(f"  {label:44s} {t * 1e3:8.2f} ms {t / t_py:9.3f}x {abs(x - ref.x_m[-1]) * 1e3:15.4f} mm")
    print(f"  fmpy overhead per co-simulation step: {per_step * 1e6:.1f} us "
          f"(({t_cs_fine * 1e3:.1f} - {t_cs_coarse * 1e3:.1f}) ms / ({n_fine} - {n_coarse}) steps)")
    print(f"66-case grid (valve, supply = stable pressure, valve opens at {t_open:g} s, {sc.duration_s:g} s)")
    print(f"  C core, C driver, 0.1 s steps: {t_grid_core * 1e3:8.2f} ms  (target < {TARGET_GRID_S * 1e3:.0f} ms: "
          f"{'met' if t_grid_core < TARGET_GRID_S else 'MISSED'})")
    print(f"  pamsim.simulate:               {t_grid_py * 1e3:8.2f} ms  (C core {t_grid_py / t_grid_core:.0f}x faster)")
    print(f"  largest final-contraction difference C core vs Python: "
          f"{np.max(np.abs(x_grid_core - x_grid_py)) * 1e3:.4f} mm")


if __name__ == "__main__":
    main()
