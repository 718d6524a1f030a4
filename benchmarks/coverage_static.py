"""Are the static fit's intervals calibrated?  Coverage of its 95 % Wald and profile-likelihood intervals.

    python benchmarks/coverage_static.py [--datasets N] [--seed S]

For each setting, N synthetic data sets (seeded) are made from known coefficients, each is fitted,
and the fraction of intervals ``fitted +- 1.96 standard errors`` that hold the truth is counted
over every coefficient and data set; beside it the same with the Student-t quantile (the Wald interval
``fit.json`` reports) and for the profile-likelihood intervals (``fit.json``'s ``profile``).  Calibrated errors give 0.95 (with N = 200 and six
coefficients, a binomial standard error of about 0.006 if the coefficients were independent).

Settings (truth: the ACRA 2012 paper's printed coefficients; the 66 (pressure, load) pairs of its
Tables 1 and 2; the Shadow muscle's upper stop):

- ``contraction, censored``: hung weights, the contraction objective, 0.5 mm noise; the tests
  the truth cannot lift read 0 and are censored.
- ``contraction, lifted only``: the same with only the tests the truth lifts above 5 mm.
- ``force``: a force gauge at fixed lengths (0 to 50 mm, 0.5 to 4 bar, 80 tests), 0.05 N noise:
  the objective is linear in the coefficients, so the intervals are exact (a control).
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np
from scipy.stats import t as student_t

import pamsim
from pamsim.elements.static_force import Acra2012Polynomial
from pamsim.identification import fit_static, read_static_data
from pamsim.identification.columns import StaticData
from pamsim.identification.equilibrium import equilibrium_m
from pamsim.identification.muscle_file import upper_stop_table
from pamsim.identification.static_fit import make_problem
from pamsim.identification.synthetic import synthetic_static

ROOT = Path(__file__).resolve().parents[1]
COEFFS = ("K1_N_per_bar_m2", "K2_N_per_bar_m", "C1_N_per_bar", "S1_N_per_m2", "S2_N_per_m", "S3_N")
PRINTED = np.array([-476.95, -188.39, 23.90, 2562.4, -245.48, -11.56])
Z95 = 1.959963984540054
"""Normal quantile of the Wald interval; the Student-t quantile of the fit's degrees of freedom is
printed beside it (what calibrated errors from an estimated sigma reach exactly, for a linear model)."""


SETTINGS = ("contraction, censored", "contraction, lifted only", "force")
SHADOW_STOP = upper_stop_table(pamsim.load_muscle("shadow_6x300_acra2012"))
"""The paper's muscle's ``[upper_stop]`` (its braid lock), where its equilibria end."""


def settings(params):
    acra = read_static_data(ROOT / "pamsim" / "data" / "acra2012_steady_state.csv")
    problem = make_problem(acra, params, upper_stop=SHADOW_STOP)
    x_max = problem.stops(problem.start).x_high_m
    force = Acra2012Polynomial(*PRINTED).force_N
    lifted = equilibrium_m(force, acra.pressure_gauge_Pa, acra.load_N, x_max) >= 5e-3
    p_bar = np.repeat(np.linspace(0.5, 4.0, 8), 10)
    x = np.tile(np.linspace(0.0, 0.05, 10), 8)

    def gauge(seed):
        noise = np.random.default_rng(seed).normal(0.0, 0.05, x.size)
        return StaticData(p_bar * 1e5, x, force(x, p_bar * 1e5) + noise, "force")

    return {
        "contraction, censored": lambda seed: synthetic_static(force, acra.pressure_gauge_Pa, acra.load_N, x_max,
                                                               0.5e-3, seed),
        "contraction, lifted only": lambda seed: synthetic_static(force, acra.pressure_gauge_Pa[lifted],
                                                                  acra.load_N[lifted], x_max, 0.5e-3, seed),
        "force": gauge,
    }


def coverage(make, params, n: int, seed: int) -> tuple[float, float, float, np.ndarray, int]:
    """Coverage with the normal and with the Student-t quantile and of the profile intervals, the normal one
    per coefficient, and the data sets whose errors were not all finite."""
    hits = np.zeros((n, len(COEFFS)), dtype=bool)
    hits_t = np.zeros((n, len(COEFFS)), dtype=bool)
    hits_p = np.zeros((n, len(COEFFS)), dtype=bool)
    skipped = 0
    for i in range(n):
        fit = fit_static(make(seed + i), params, cv=None, upper_stop=SHADOW_STOP)
        hits_p[i] = (fit.profile_95[:, 0] <= PRINTED) & (PRINTED <= fit.profile_95[:, 1])
        u = fit.uncertainty
        if not np.all(np.isfinite(u.standard_errors)):
            skipped += 1
        err = np.abs(fit.theta - PRINTED)
        hits[i] = err <= Z95 * u.standard_errors
        hits_t[i] = err <= student_t.ppf(0.975, dof(fit)) * u.standard_errors
    return float(hits.mean()), float(hits_t.mean()), float(hits_p.mean()), hits.mean(axis=0), skipped


def dof(fit) -> int:
    """Degrees of freedom of the fit's residual variance (older versions did not record it)."""
    return getattr(fit.uncertainty, "dof", fit.n_points - len(fit.theta))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--settings", default=";".join(SETTINGS), help="settings to run, separated by semicolons")
    args = ap.parse_args()
    params = pamsim.get_parameter_set("shadow_6x300_acra2012").with_overrides(dict(zip(COEFFS, PRINTED)))
    print(f"95 % coverage over {args.datasets} synthetic data sets per setting (seeds from {args.seed}): Wald with "
          "the normal and the t quantile, profile likelihood")
    print(f"{'setting':<26} {'normal':>7} {'t':>6} {'profile':>7}  " + "  ".join(f"{c[:6]:>6}" for c in COEFFS)
          + "  not finite")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        chosen = [c.strip() for c in args.settings.split(";")]
        for label, make in settings(params).items():
            if label not in chosen:
                continue
            total, total_t, total_p, per, skipped = coverage(make, params, args.datasets, args.seed)
            print(f"{label:<26} {total:7.3f} {total_t:6.3f} {total_p:7.3f}  " + "  ".join(f"{c:6.3f}" for c in per)
                  + f"  {skipped}", flush=True)


if __name__ == "__main__":
    main()
