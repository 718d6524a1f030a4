"""The dynamic fit's default multistart on hidden coefficient sets, and the noise flag's false alarms.

    python benchmarks/bench_multistart.py [--seeds N] [--sets own|study|all] [--starts N] [--escapes N]

Native backend, scenarios/acra2012_fig4.toml, the five coefficients (D1, D2, N2, N1, N0); every case has
three synthetic traces (12.74, 22.74, 32.74 N, 2.5 s, 3.6 bar, pressure recorded, 0.05 mm of Gaussian
noise on the contraction).

1. False alarms: for ``--seeds`` noise seeds (default 20) of the recovery study's coefficients, a fit
   started at the truth (no extra starts), its pooled RMS over the traces' pooled noise estimate and the
   largest over the smallest per-trace ratio (:mod:`pamsim.identification.fit_quality`): mean, standard
   deviation, largest, and how many fits the flag marks; then the same for a single trace (22.74 N).
2. Hidden sets (``own``: five sets of this benchmark; ``study``: the four of
   ``python -m pamsim.identification.studies starts``), each fitted with the defaults from the
   scenario's values (the paper's Table 4) and from zero friction and damping (``--starts N``: with N
   extra starts instead of the default): the pooled RMS over the
   RMS at the truth, per-trace RMS, each coefficient's error, the flags, the extra starts and the wall
   time (on a shared machine: compare the times with each other; the load average is printed).
3. Escapes (``--escapes N``, default 12): from the two minima where eight screened random starts left the
   study's sets B (from zero) and D, N single local fits from hops (points near the minimum,
   :func:`pamsim.identification.dynamic_starts.hop_point`) and N from random points over the typical
   scales (:func:`pamsim.identification.dynamic_starts.random_points`, from zero): how many reach the RMS
   at the truth (within 1 %).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

import pamsim
from pamsim.identification.dynamic_fit import _local, fit_dynamic, make_problem, make_trials
from pamsim.identification.dynamic_starts import hop_point, random_points, typical_scales
from pamsim.identification.fit_quality import NOISE_FACTOR, SPREAD_FACTOR
from pamsim.identification.studies import STARTS_SETS, TRUTH
from pamsim.identification.synthetic import synthetic_trace, with_noise

ROOT = Path(__file__).resolve().parents[1]
FREE = tuple(TRUTH)
LOADS_N = (12.74, 22.74, 32.74)
NOISE_M = 0.05e-3
DURATION_S = 2.5
OWN_SETS = {"E heavy friction and damping": (-2.0, 5.0, 600.0, -200.0, 15.0),
            "F light friction and damping": (0.2, 0.05, 10.0, 5.0, 1.0),
            "G level falling along the travel (N2 < 0)": (1.0, 2.0, -100.0, 60.0, 4.0),
            "H small damping, steep level": (-0.2, 0.8, 300.0, -40.0, 8.0),
            "I strong damping, D1 > 0": (0.886, 2.537, 315.1, -132.4, 9.7)}
"""Hidden coefficients (D1, D2, N2, N1, N0) spanning the ranges: D1 from -2 to 1 N s/m, D2 from 0.05 to 5
N s^2/m^2, N0 from 1 to 15 N/bar, N1 and N2 of both signs; each keeps the Coulomb level positive over the
traces' travel (up to 75 mm).  I is the one of twelve random sets where the starts of the previous default
(eight screened random points) stopped 6-7 times above the noise."""


def _pooled_rms_mm(problem, theta) -> float:
    r = problem.residuals_from(make_trials(problem, "native")(np.asarray(theta, dtype=float)))
    return float(np.sqrt(np.mean(r ** 2)))


def _ratios(fit) -> tuple[float, float]:
    """Pooled RMS over pooled noise, and the largest over the smallest per-trace RMS over noise."""
    noise, rms = np.array(fit.noise_mm), np.array(fit.rms_contraction_mm)
    per = rms / noise
    return fit.rms_pooled_mm / float(np.sqrt(np.mean(noise ** 2))), float(per.max() / per.min())


def false_alarms(sc, n_seeds: int) -> None:
    """Fits started at the truth, over noise seeds: the flag's two ratios and how often they fire."""
    at_truth = sc.with_changes({"parameters": TRUTH})
    cleans = [synthetic_trace(sc, TRUTH, w, NOISE_M, duration_s=DURATION_S)[1] for w in LOADS_N]
    print(f"Fits started at the truth {tuple(TRUTH.values())}, {n_seeds} noise seeds, no extra starts; "
          f"flag thresholds: pooled {NOISE_FACTOR:g} x the noise, spread {SPREAD_FACTOR:g}\n")
    print("| traces | pooled RMS / noise: mean | SD | largest | traces' spread: mean | SD | largest | flagged |")
    print("|---|---|---|---|---|---|---|---|")
    for label, chosen in (("three loads", cleans), ("one load (22.74 N)", cleans[1:2])):
        pooled, spread, flagged = [], [], 0
        for seed in range(n_seeds):
            noisy = [with_noise(c, NOISE_M, 1000 + 10 * seed + i) for i, c in enumerate(chosen)]
            fit = fit_dynamic(at_truth, noisy, free=FREE, backend="native", n_starts=0)
            p, s = _ratios(fit)
            pooled.append(p)
            spread.append(s)
            flagged += bool(fit.warnings)
        print(f"| {label} | {np.mean(pooled):.4f} | {np.std(pooled, ddof=1):.4f} | {max(pooled):.4f} | "
              + (f"{np.mean(spread):.4f} | {np.std(spread, ddof=1):.4f} | {max(spread):.4f}" if len(chosen) > 1
                 else "- | - | -") + f" | {flagged} of {n_seeds} |")


def hidden_sets(sc, sets: dict[str, tuple[float, ...]], n_starts: int | None) -> None:
    """The fit of every set from two starts (``n_starts`` extra starts, None the default); one Markdown
    row each."""
    zero = sc.with_changes({"parameters": dict.fromkeys(FREE, 0.0)})
    print("\n| hidden set (D1, D2, N2, N1, N0) | start | RMS at truth [mm] | RMS / truth's | per-trace RMS [mm] | "
          "errors (D1, D2, N2, N1, N0) | flags | starts | s |\n|---|---|---|---|---|---|---|---|---|")
    for label, values in sets.items():
        truth = dict(zip(FREE, values))
        noisy = [synthetic_trace(sc, truth, w, NOISE_M, seed=i, duration_s=DURATION_S)[0]
                 for i, w in enumerate(LOADS_N)]
        for start_label, start in (("scenario", sc), ("zero", zero)):
            rms_truth = _pooled_rms_mm(make_problem(start, noisy, free=FREE), values)
            fit = fit_dynamic(start, noisy, free=FREE, backend="native", n_starts=n_starts)
            errors = ", ".join(f"{t - v:+.3g}" for t, v in zip(fit.theta, values))
            flags = ", ".join("pooled" if "pooled RMS" in w else "uneven" for w in fit.warnings) or "none"
            print(f"| {label} {values} | {start_label} | {rms_truth:.4f} | {fit.rms_pooled_mm / rms_truth:.3f} | "
                  f"{', '.join(f'{r:.4f}' for r in fit.rms_contraction_mm)} | {errors} | {flags} | {fit.n_starts} | "
                  f"{fit.wall_time_s:.1f} |", flush=True)


LOCAL_MINIMA = {"B": (0.523, 0.993, 25.93, -15.58, 2.827), "D": (1.91, 0.807, 171.07, 9.629, 2.022)}
"""Where eight screened random starts left the study's sets B (from zero, 1.22 times the RMS at the
truth) and D (1.04 times), as the fits printed them (``python -m pamsim.identification.studies starts``
before hops)."""


def escapes(sc, n: int) -> None:
    """Local fits from hops around each minimum and from random points: how many reach the truth."""
    zero = sc.with_changes({"parameters": dict.fromkeys(FREE, 0.0)})
    print(f"\n| local minimum of set | its RMS / truth's | of {n} hops: reach the truth | of {n} random points: "
          "reach the truth |\n|---|---|---|---|")
    for label, minimum in LOCAL_MINIMA.items():
        truth = STARTS_SETS[label]
        noisy = [synthetic_trace(sc, dict(zip(FREE, truth)), w, NOISE_M, seed=i, duration_s=DURATION_S)[0]
                 for i, w in enumerate(LOADS_N)]
        problem = make_problem(zero, noisy, free=FREE)
        trials = make_trials(problem, "native")
        scales = typical_scales(problem, np.zeros(len(FREE)))
        rms_truth = _pooled_rms_mm(problem, truth)
        rng = np.random.default_rng(7)
        hops = [hop_point(np.array(minimum), scales, problem.bounds, rng) for _ in range(n)]
        far = random_points(np.zeros(len(FREE)), scales, problem.bounds, n, 7)

        n_residuals = sum(int(m.sum()) for m in problem.windows)

        def reached(points) -> int:
            costs = [_local(problem, p, None, 1e-3, 30, trials, scales)[1].cost for p in points]
            return sum(np.sqrt(2.0 * c / n_residuals) <= 1.01 * rms_truth for c in costs)

        print(f"| {label} {truth} | {_pooled_rms_mm(problem, minimum) / rms_truth:.3f} | {reached(hops)} | "
              f"{reached(far)} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--sets", choices=("own", "study", "all"), default="all")
    parser.add_argument("--escapes", type=int, default=12)
    parser.add_argument("--starts", type=int, default=None)
    args = parser.parse_args()
    sc = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    fit_dynamic(sc, [synthetic_trace(sc, {}, 22.74, duration_s=1.5)[0]], free=("N0_N_per_bar",), max_iterations=1,
                backend="native", n_starts=0)  # the library built and loaded before the clocks
    if args.seeds > 0:
        false_alarms(sc, args.seeds)
    chosen = {**(OWN_SETS if args.sets in ("own", "all") else {}),
              **(STARTS_SETS if args.sets in ("study", "all") else {})}
    hidden_sets(sc, chosen, args.starts)
    if args.escapes > 0:
        escapes(sc, args.escapes)
    print(f"\nload average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
