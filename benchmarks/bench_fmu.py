"""Benchmark of the FMU (issue 4): the compiled model's own cost against the Python simulator.

Prints, side by side:
  * one 8 s paper scenario (fig. 4): ``pamsim.simulate`` against the FMU's engine and
    generated model without the FMI layer (the native backend runs the same ones) and against
    the FMU stepped by fmpy with a coarse communication step (0.1 s), with the contraction
    difference to the Python result so the costs are at comparable accuracy;
  * the 66-case grid of the paper's steady-state tests (valve source, supply
    = stable pressure, valve opens at 1 s, 8 s) on that engine in one batch (target < 0.1 s)
    and with ``pamsim.simulate``;
  * fmpy's own overhead per co-simulation step (1 ms against 0.1 s steps) and
    the Model Exchange run through fmpy's CVode;
  * building the one-muscle FMU and the FMU of ``scenarios/parallel_spring.toml``'s assembly (generated
    C and compiled, in a fresh temporary folder; best of N), with the generated model's lines of C.

Run on one core:  taskset -c 0 python benchmarks/bench_fmu.py [--repeats N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402

import pamsim  # noqa: E402
import pamsim.native  # noqa: E402  (simulate_batch)
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    sc = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    t_open = float(sc.spec["pressure"]["valve_open_time_s"])
    fmu2 = cached_fmu(2)

    # The FMU's engine and generated model without the FMI layer: the native backend at the FMU's tolerance.
    t_py, ref = median_time(lambda: pamsim.simulate(sc), args.repeats)
    engine = sc.with_changes({"solver": {"rtol": 1e-8, "native_rtol_factor": 1.0}})
    pamsim.simulate(engine, backend="native")  # its library built or found
    t_core, core = median_time(lambda: pamsim.simulate(engine, backend="native"), args.repeats)
    x_core = core.x_m[-1]
    coarse = np.arange(0.0, sc.duration_s + 1e-9, 0.1)
    t_cs_coarse, tr_coarse = median_time(lambda: run_cs(sc, 2, communication_times=coarse, fmu_path=fmu2),
                                         args.repeats)
    t_cs_fine, tr_fine = median_time(lambda: run_cs(sc, 2, fmu_path=fmu2), args.repeats)
    t_me, tr_me = median_time(lambda: run_me(sc, 2, fmu_path=fmu2), args.repeats)

    rows = acra2012_steady_state()
    scenarios = [sc.with_changes({"load": {"weight_N": float(r["weight_N"])},
                                  "pressure": {"supply_gauge_bar": float(r["pressure_stable_bar"])}})
                 for r in rows]
    on_engine = [s.with_changes({"solver": {"rtol": 1e-8, "native_rtol_factor": 1.0}}) for s in scenarios]
    pamsim.native.simulate_batch(on_engine)  # warm-up: the first batch of a process fills per-case caches
    t_grid_core, batch = median_time(lambda: pamsim.native.simulate_batch(on_engine), max(args.repeats, 5))
    x_grid_core = np.array([r.x_m[-1] for r in batch])
    t0 = time.perf_counter()
    x_grid_py = np.array([pamsim.simulate(s).x_m[-1] for s in scenarios])
    t_grid_py = time.perf_counter() - t0

    n_fine, n_coarse = len(tr_fine["t_s"]) - 1, len(coarse) - 1
    per_step = (t_cs_fine - t_cs_coarse) / (n_fine - n_coarse)
    print(f"8 s scenario {sc.name}  (median of {args.repeats})")
    print(f"  {'run':44s} {'time':>10s} {'vs python':>10s} {'|x - x_py| final':>18s}")
    print(f"  {'pamsim.simulate (LSODA, rtol 1e-6)':44s} {t_py * 1e3:8.2f} ms {1.0:9.3f}x {0.0:15.4f} mm")
    for label, t, x in [("engine and generated model, no FMI (rtol 1e-8)", t_core, x_core),
                        ("FMU CS via fmpy, 0.1 s communication steps", t_cs_coarse, tr_coarse["contraction_m"][-1]),
                        ("FMU CS via fmpy, 1 ms communication steps", t_cs_fine, tr_fine["contraction_m"][-1]),
                        ("FMU ME via fmpy CVode, 1 ms output", t_me, tr_me["contraction_m"][-1])]:
        print(f"  {label:44s} {t * 1e3:8.2f} ms {t / t_py:9.3f}x {abs(x - ref.x_m[-1]) * 1e3:15.4f} mm")
    print(f"  fmpy overhead per co-simulation step: {per_step * 1e6:.1f} us "
          f"(({t_cs_fine * 1e3:.1f} - {t_cs_coarse * 1e3:.1f}) ms / ({n_fine} - {n_coarse}) steps)")
    print(f"66-case grid (valve, supply = stable pressure, valve opens at {t_open:g} s, {sc.duration_s:g} s)")
    print(f"  engine, one batch, rtol 1e-8:  {t_grid_core * 1e3:8.2f} ms  (target < {TARGET_GRID_S * 1e3:.0f} ms: "
          f"{'met' if t_grid_core < TARGET_GRID_S else 'MISSED'})")
    print(f"  pamsim.simulate:               {t_grid_py * 1e3:8.2f} ms  (engine {t_grid_py / t_grid_core:.0f}x faster)")
    print(f"  largest final-contraction difference engine vs Python: "
          f"{np.max(np.abs(x_grid_core - x_grid_py)) * 1e3:.4f} mm")
    build_times(args.repeats)


def build_times(repeats: int) -> None:
    """Generating and compiling the one-muscle FMU and an assembly's, with the lines of generated C."""
    import tempfile
    import zipfile

    from pamsim.fmu import build, build_assembly

    spring = pamsim.load_scenario(ROOT / "scenarios" / "parallel_spring.toml")
    print("building an FMU (generate + compile + zip, FMI 2.0; best of N)")
    for label, make in (("one-muscle FMU", lambda p: build(p, 2)),
                        ("parallel_spring assembly FMU", lambda p: build_assembly(spring, p, 2))):
        times = []
        for _ in range(repeats):
            with tempfile.TemporaryDirectory() as tmp:
                t0 = time.perf_counter()
                path = make(Path(tmp) / "m.fmu")
                times.append(time.perf_counter() - t0)
                lines = zipfile.ZipFile(path).read("sources/pam_model.c").decode().count("\n")
        print(f"  {label:30s} {min(times):6.2f} s  ({lines} lines of generated C)")


if __name__ == "__main__":
    main()
