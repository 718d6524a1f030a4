"""Wall time of the identification commands against the issue's targets.

    python benchmarks/bench_fit.py [--repeat N] [--workers N]

1. Static fit of the 66 ACRA 2012 steady states (contraction objective, no cross-validation):
   target <= 2 s.  The leave-one-out cross-validation (66 more fits) is timed apart.
2. A 5-coefficient dynamic fit (D1, D2, N2, N1, N0, started from the paper's values) on one 8 s
   synthetic trace (3.6 bar valve step, 22.74 N, pressure recorded, 0.05 mm noise, seed 0) with the
   Python backend on 2 worker processes: target <= 20 s.  Prints simulations per second.
3. The same fit on the native backend (``backend="native"``), in this process and on the same 2
   worker processes (one library call per worker per optimiser step), its time and its ratio to the
   Python fit's, and both fits' coefficients side by side with their difference in standard errors.

The best of N repeats is printed beside the target and as a ratio (below 1 meets it), with the
machine's load average: on a shared machine the workers wait for a core.  The time of one
simulation in this process (best of 3) times the simulations per worker is printed as the bound
an unloaded machine would reach.
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import pamsim
from pamsim.identification import fit_static, read_static_data
from pamsim.identification.dynamic_fit import fit_dynamic, make_problem, run_simulation
from pamsim.identification.muscle_file import upper_stop_table
from pamsim.identification.synthetic import synthetic_trace

ROOT = Path(__file__).resolve().parents[1]
TRUTH = {"D1_N_s_per_m": -0.5, "D2_N_s2_per_m2": 1.2, "N2_N_per_bar_m2": 200.0, "N1_N_per_bar_m": -80.0,
         "N0_N_per_bar": 6.0}


def _best(fn, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return min(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()

    data = read_static_data(ROOT / "pamsim" / "data" / "acra2012_steady_state.csv")
    params = pamsim.get_parameter_set("shadow_6x300_acra2012")
    stop = upper_stop_table(pamsim.load_muscle("shadow_6x300_acra2012"))  # its braid lock
    t, fit = _best(lambda: fit_static(data, params, cv=None, intervals=False, upper_stop=stop), args.repeat)
    print(f"static fit, 66 tests, contraction objective: {t:.3f} s (target 2 s, ratio {t / 2.0:.2f}); "
          f"{fit.nfev} evaluations, RMS {fit.rms_contraction_mm:.3f} mm")
    t_prof, _ = _best(lambda: fit_static(data, params, cv=None, upper_stop=stop), args.repeat)
    print(f"static fit + profile-likelihood intervals of the six coefficients: {t_prof:.3f} s")
    t, fit = _best(lambda: fit_static(data, params, cv="loo", intervals=False, upper_stop=stop), 1)
    print(f"static fit + leave-one-out cross-validation (67 fits): {t:.2f} s; CV RMS {fit.cv_rms_contraction_mm:.3f} mm")

    sc = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    noisy, clean = synthetic_trace(sc, TRUTH, 22.74, seed=0)
    with ProcessPoolExecutor(args.workers) as pool:
        pool.submit(int).result()  # workers started before the clock
        t, dyn = _best(lambda: fit_dynamic(sc, [noisy], free=tuple(TRUTH), executor=pool), args.repeat)
    rate = dyn.n_simulations / t
    print(f"dynamic fit, 5 coefficients, one 8 s trace, {args.workers} workers: {t:.2f} s (target 20 s, ratio "
          f"{t / 20.0:.2f}); {dyn.n_simulations} simulations, {rate:.1f} simulations/s")
    task = make_problem(sc, [noisy], free=tuple(TRUTH)).tasks(dyn.start)[0]
    t_sim, _ = _best(lambda: run_simulation(task), 3)
    print(f"  one 8 s simulation: {t_sim:.3f} s; {dyn.n_simulations} simulations on {args.workers} workers: "
          f">= {t_sim * dyn.n_simulations / args.workers:.2f} s; load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} CPUs")
    err = np.sqrt(np.mean((dyn.simulated_m[0] - clean.x_m) ** 2)) * 1e3
    print(f"  fitted trajectory vs noise-free truth: RMS {err:.4f} mm; residual RMS {dyn.rms_pooled_mm:.4f} mm")

    fit_dynamic(sc, [noisy], free=("N0_N_per_bar",), max_iterations=1, backend="native")  # library built and loaded
    # One start, as the Python fit above: the same local search on both backends.
    t_here, nat = _best(lambda: fit_dynamic(sc, [noisy], free=tuple(TRUTH), backend="native", n_starts=0), args.repeat)
    with ProcessPoolExecutor(args.workers) as pool:
        pool.submit(int).result()
        t_pool, _ = _best(lambda: fit_dynamic(sc, [noisy], free=tuple(TRUTH), executor=pool, backend="native",
                                              n_starts=0), args.repeat)
    print(f"dynamic fit, native backend: {t_here:.3f} s in this process ({t / t_here:.0f}x faster than the Python "
          f"fit), {t_pool:.3f} s on {args.workers} workers ({t / t_pool:.0f}x); {nat.n_simulations} simulations, "
          f"{nat.n_simulations / t_here:.0f} simulations/s in this process")
    err = np.sqrt(np.mean((nat.simulated_m[0] - clean.x_m) ** 2)) * 1e3
    print(f"  fitted trajectory vs noise-free truth: RMS {err:.4f} mm; residual RMS {nat.rms_pooled_mm:.4f} mm")
    se = dyn.uncertainty.standard_errors
    print(f"  {'coefficient':<18} {'truth':>10} {'python':>12} {'native':>12} {'(nat-py)/se':>12}")
    for k, name in enumerate(TRUTH):
        print(f"  {name:<18} {TRUTH[name]:>10.4g} {dyn.theta[k]:>12.6g} {nat.theta[k]:>12.6g} "
              f"{(nat.theta[k] - dyn.theta[k]) / se[k]:>+12.3f}")


if __name__ == "__main__":
    main()
