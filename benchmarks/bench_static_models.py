"""Benchmark of the static-model library: evaluations per second on 1e6-point arrays.

Prints, for every closed-form (and table) model of the library on a muscle it
applies to, the best of N timings of ``force_N`` on 1e6 (x, p) points, as
evaluations per second beside the target (>= 1e7/s for the polynomial and
Gaylord, >= 1e6/s for the energy models, no target for the others) and as the
ratio measured/target; plus the cost of one scalar (Python float) call, which is
what the ODE's inner loop pays.

Run on one core:  taskset -c 0 python benchmarks/bench_static_models.py [--repeats N] [--points N]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402

from pamsim.muscles import load_muscle  # noqa: E402
from pamsim.static_models import REGISTRY, get  # noqa: E402

TARGETS = {"acra2012_polynomial": 1e7, "gaylord": 1e7, "kothera_mooney_rivlin": 1e6, "kothera_corrected_mooney_rivlin": 1e6,
           "kothera_energy": 1e6, "kothera_energy_tips": 1e6, "ogden": 1e6, "neo_hookean": 1e6}
"""Evaluations per second required by the specification (energy models: 1e6/s)."""

MUSCLE_FOR = {"acra2012_polynomial": "shadow_6x300_acra2012"}
ASSUMED = {  # constants for models no shipped muscle has (timing only; values as in the sanity tests)
    "ogden": {"ogden_mu1_Pa": 2e6, "ogden_alpha1": 2.0, "ogden_mu2_Pa": 1.1e6, "ogden_alpha2": -2.0},
    "itto": {"itto_kappa1": 0.5, "itto_kappa2_per_Pa": -1e-6, "itto_kappa3": 0.5},
    "meller": {"meller_kappa1_m2": 1.6e-4, "meller_kappa2_N": -1.0, "meller_kappa3": 0.02},
    "andrikopoulos": {"andrikopoulos_F_max_N": 60.0, "andrikopoulos_x_max_m": 0.02, "andrikopoulos_P_test_Pa": 4e5},
    "takosoglu": {"takosoglu_kappa1": 0.2, "takosoglu_kappa2_Pa": 5e5, "takosoglu_kappa3": 2.0, "takosoglu_kappa4": 0.0,
                  "takosoglu_kappa5_Pa": 5e5, "takosoglu_kappa6": 2.6},
    "mpam_bundle_empirical": {"bundle_kappa1_m2": 3e-4, "bundle_kappa2_N": 0.0, "bundle_kappa3_m2": -1.5e-4},
    "empirical_poly46": {"emp46_k1_m2": 1.5e-4, "emp46_k2_m2": -6e-4, "emp46_k3_m2": 3e-4,
                         **{f"emp46_k{i}_N": 0.1 for i in range(4, 9)}},
    "empirical_poly47": {"emp47_k1_N": 0.0, "emp47_k2_N": 0.0, "emp47_k3_N": 0.0, "emp47_k4_m2": 1.5e-4, "emp47_k5_m2": -6e-4},
    "empirical_poly48": {"emp48_k1_m2_per_Pa": 0.0, "emp48_k2_m2": -6e-4, "emp48_k3_N": 0.0, "emp48_k4_m2": 1.5e-4, "emp48_k5_N": 0.0},
    "empirical_linear": {"emp49_k1": 1.0, "emp49_Fmax_N": 60.0, "emp49_eps_max": 0.2},
    "pillsbury": {"pillsbury_E1I_Pa": 2.28e6, "pillsbury_E1S": 0.1},
}


def force_map_file(directory: Path) -> Path:
    """A 40 x 12 table of the Kothera 5a force-balance model, written for the force_map timing."""
    m = load_muscle("kothera2009_5a").static_force("kothera_force_balance_thickness")
    xs = np.linspace(0.0, 0.9 * m.domain.x_max_m, 40)
    ps = np.linspace(0.0, 4.1e5, 12)
    path = directory / "kothera5a_map.csv"
    path.write_text("contraction_m,pressure_gauge_Pa,force_N\n"
                    + "".join(f"{float(x)!r},{float(p)!r},{float(m.force_N(x, p))!r}\n" for x in xs for p in ps))
    return path


def build(name: str, tmp: Path):
    if name == "force_map":
        return get(name).build({"force_map_file": force_map_file(tmp)})
    muscle = load_muscle(MUSCLE_FOR.get(name, "kothera2009_5a"))
    return get(name).build({**muscle.model_inputs(), **ASSUMED.get(name, {})})


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--points", type=int, default=1_000_000)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    print(f"== force_N on {args.points:.0e} points, best of {args.repeats}; scalar call = one float pair ==")
    print(f"{'model':40s} {'kind':12s} {'evals/s':>10s} {'target':>8s} {'ratio':>7s} {'scalar us':>10s}")
    with tempfile.TemporaryDirectory() as tmp:
        for name, spec in REGISTRY.items():
            if spec.kind == "implicit":  # a root solve per point: tabulated for the dynamics, not an array law
                print(f"{name:40s} {spec.kind:12s} {'not timed: one nonlinear solve per point':>40s}")
                continue
            m = build(name, Path(tmp))
            d = m.domain
            x = rng.uniform(max(d.x_min_m, 0.0), 0.9 * d.x_max_m, args.points)
            p = rng.uniform(max(d.p_min_Pa, 0.0), min(d.p_max_Pa, 6e5), args.points)
            best = min(_timed(m.force_N, x, p) for _ in range(args.repeats))
            rate = args.points / best
            xs, ps = float(x[0]), float(p[0])
            n_scalar = 20000
            t0 = time.perf_counter()
            for _ in range(n_scalar):
                m.force_N(xs, ps)
            scalar_us = (time.perf_counter() - t0) / n_scalar * 1e6
            target = TARGETS.get(name)
            ratio = f"{rate / target:7.1f}" if target else f"{'-':>7s}"
            target_text = f"{target:8.0e}" if target else f"{'-':>8s}"
            print(f"{name:40s} {spec.kind:12s} {rate:10.3g} {target_text} {ratio} {scalar_us:10.2f}")


def _timed(f, x, p) -> float:
    t0 = time.perf_counter()
    f(x, p)
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
