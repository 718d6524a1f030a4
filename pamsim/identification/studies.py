"""The numbers of docs/identification.md, printed as Markdown.

    python -m pamsim.identification.studies static    # ACRA 2012 refit, a few seconds
    python -m pamsim.identification.studies dynamic   # synthetic recovery and FD steps, minutes
    python -m pamsim.identification.studies inputs    # thinning of a recorded pressure, seconds
    python -m pamsim.identification.studies native    # the fits on the native backend, seconds
    python -m pamsim.identification.studies starts    # multistart and global search on native, a minute or two

Run from the repository root (the dynamic study reads scenarios/acra2012_fig4.toml; ``--scenario``
names another).
Everything is seeded; the tables in the docs are this output.
"""

from __future__ import annotations

import argparse
import os
from concurrent.futures import ProcessPoolExecutor
from importlib import resources

import numpy as np

from ..backends import simulate
from ..parameters import get_parameter_set
from ..scenario import Scenario
from .columns import TraceData, read_static_data
from .dynamic_fit import DEFAULT_STARTS, _Objective, fit_dynamic, make_problem, make_trials
from .models import build_static
from .static_fit import fit_static
from .static_fit import make_problem as make_static_problem
from .synthetic import synthetic_trace

TRUTH = {"D1_N_s_per_m": -0.5, "D2_N_s2_per_m2": 1.2, "N2_N_per_bar_m2": 200.0, "N1_N_per_bar_m": -80.0,
         "N0_N_per_bar": 6.0}
TRAINING = [(2.8, 12.74), (2.0, 22.74), (3.6, 22.74), (3.6, 32.74), (4.0, 42.74), (4.0, 52.74)]


def _rms(err_m: np.ndarray) -> float:
    return float(np.sqrt(np.mean((err_m * 1e3) ** 2)))


def static_study() -> None:
    """The paper's static polynomial refitted to its steady states, against the printed coefficients, and the
    applicable models compared; Markdown tables."""
    path = resources.files("pamsim.data").joinpath("acra2012_steady_state.csv")
    data = read_static_data(str(path))
    P = get_parameter_set("shadow_6x300_acra2012")
    coeffs = ("K1_N_per_bar_m2", "K2_N_per_bar_m", "C1_N_per_bar", "S1_N_per_m2", "S2_N_per_m", "S3_N")
    from ..muscles import load_muscle
    from .muscle_file import upper_stop_table

    stop = upper_stop_table(load_muscle("shadow_6x300_acra2012"))
    paper = make_static_problem(data, P, upper_stop=stop)
    paper_x = paper.predict_m(paper.start)
    within = paper_x >= 5e-3
    err0 = paper_x - data.contraction_m
    rows = [("printed coefficients (paper eq. 11)", {n: P[n] for n in coeffs}, _rms(err0), _rms(err0[within]), None)]
    p_step = np.round(data.pressure_gauge_Pa / 1e5 / 0.4) * 0.4
    train = np.array([int(np.flatnonzero(np.isclose(p_step, p) & np.isclose(data.load_N, w))[0]) for p, w in TRAINING])
    f6 = fit_static(data.subset(train), P, objective="force", cv=None, exact=True, upper_stop=stop)
    for label, fit in (("force objective, six training tests (exact)", f6),
                       ("contraction objective, all 66, linear loss", fit_static(data, P, cv="loo", upper_stop=stop)),
                       ("contraction objective, all 66, soft_l1 loss (1 mm)", fit_static(data, P, loss="soft_l1",
                                                                                        cv="loo", upper_stop=stop))):
        x = fit.problem.predict_m(fit.theta, data)
        e = x - data.contraction_m
        rows.append((label, fit.parameters, _rms(e), _rms(e[within]),
                     fit.cv_rms_contraction_mm if fit.cv_kind == "leave-one-out" else None))
    print("| coefficients | " + " | ".join(coeffs) + " | RMS all 66 [mm] | RMS 28 within capability [mm] | "
          "leave-one-out RMS [mm] |")
    print("|---|" + "---|" * (len(coeffs) + 3))
    for label, c, r66, r28, cv in rows:
        print(f"| {label} | " + " | ".join(f"{c[n]:.5g}" for n in coeffs) + f" | {r66:.3f} | {r28:.3f} | "
              + (f"{cv:.3f}" if cv is not None else "-") + " |")
    print("\nModel comparison (soft_l1 loss, 1 mm; leave-one-out; default free coefficients unless listed):\n")
    print("| model | free coefficients | RMS [mm] | leave-one-out RMS [mm] | AIC | BIC |\n|---|---|---|---|---|---|")
    for name in load_muscle("shadow_6x300_acra2012").applicable_models() + ["tondu_lopez+kappa"]:
        model, free = (("tondu_lopez", ["r0_m", "theta0_deg", "tondu_kappa1", "tondu_kappa2"])
                       if name.endswith("+kappa") else (name, None))
        f = fit_static(data, P, model=model, free=free, loss="soft_l1", cv="loo", upper_stop=stop)
        print(f"| {model} | {', '.join(f.problem.free)} | {f.rms_contraction_mm:.3f} | {f.cv_rms_contraction_mm:.3f} | "
              f"{f.aic:.1f} | {f.bic:.1f} |")
    w = data.subset(train)
    F = f6.problem.force(f6.theta).force_N(w.contraction_m, w.pressure_gauge_Pa)
    Fp = build_static("acra2012_polynomial", P).force_N(w.contraction_m, w.pressure_gauge_Pa)
    print(f"\nsix training tests: largest |F - W| {np.max(np.abs(F - w.load_N)):.1e} N (exact fit), "
          f"{np.max(np.abs(Fp - w.load_N)):.3f} N (printed coefficients); within-capability tests: {int(within.sum())}")


def _recovery(sc: Scenario, loads, duration_s, pool, backend: str = "python") -> None:
    pairs = [synthetic_trace(sc, TRUTH, w, seed=i, duration_s=duration_s) for i, w in enumerate(loads)]
    # One start on both backends: the tables compare the backends' fits of the same local search.
    fit = fit_dynamic(sc, [n for n, _ in pairs], free=tuple(TRUTH), executor=pool, backend=backend, n_starts=0)
    truth = np.array(list(TRUTH.values()))
    u = fit.uncertainty
    print(f"\n{len(loads)} trace(s) at {', '.join(f'{w:g}' for w in loads)} N, {duration_s:g} s, 3.6 bar: "
          f"{fit.n_simulations} simulations, {fit.wall_time_s:.1f} s ({backend} backend)")
    print("\n| coefficient | truth | start | fitted | error | standard error | identifiable |")
    print("|---|---|---|---|---|---|---|")
    ident = u.identifiable(fit.theta)
    for i, n in enumerate(fit.problem.free):
        print(f"| {n} | {truth[i]:g} | {fit.start[i]:g} | {fit.theta[i]:.4g} | "
              f"{(fit.theta[i] - truth[i]) / truth[i]:+.1%} | {u.standard_errors[i] / abs(fit.theta[i]):.1%} | "
              f"{'yes' if n in ident else 'no'} |")
    for a, b, r in u.inseparable_pairs():
        print(f"\n- {a} and {b}: r = {r:+.3f}", end="")
    print()
    for g in u.groups():
        wts, se = u.best_combination(g)
        idx = [fit.problem.free.index(n) for n in g]
        print(f"- best-determined combination of {', '.join(g)}: fitted {wts @ fit.theta[idx]:.4g}, "
              f"truth {wts @ truth[idx]:.4g}, standard error {se:.3g}")
    for (_, c), sim, start in zip(pairs, fit.simulated_m, fit.start_simulated_m):
        print(f"- {c.weight_N:g} N: fitted trajectory vs noise-free truth RMS {_rms(sim - c.x_m):.4f} mm "
              f"(start: {_rms(start - c.x_m):.3f} mm)")


def _fd_steps(sc: Scenario, backend: str = "python") -> None:
    res = simulate(sc.with_changes({"parameters": TRUTH, "simulation": {"duration_s": 2.5}}))
    tr = TraceData(res.t_s, res.x_m, res.p_gauge_Pa, 22.74)
    prob = make_problem(sc, [tr], free=tuple(TRUTH))
    trials = make_trials(prob, backend)
    theta = np.array([sc.parameters[n] for n in prob.free])
    ref = _Objective(prob, None, 1e-3, trials).jacobian(theta)
    print(f"\n| relative FD step | Jacobian change against step 1e-3 (relative Frobenius norm), {backend} backend |"
          "\n|---|---|")
    steps = (1e-12, 1e-11, 1e-10, 1e-9) if backend == "native" else (1e-9,)
    for h in (*steps, 1e-7, 1e-5, 1e-4, 3e-3, 1e-2, 3e-2):
        J = _Objective(prob, None, h, trials).jacobian(theta)
        print(f"| {h:g} | {np.linalg.norm(J - ref) / np.linalg.norm(ref):.3g} |")


def inputs_study(scenario_path: str) -> None:
    """Thinned pressure against the full 1 kHz trace, and the forces a 3.6 bar trace excites."""
    import time
    from dataclasses import replace

    from ..elements.pressure_source import PrescribedPressure
    from ..scenario import load_scenario
    from ..signals import Trace
    from ..simulator import simulate_model
    from .pressure_input import thinned_input

    sc = load_scenario(scenario_path).with_changes({"parameters": TRUTH})
    res = simulate(sc)
    model = sc.build_model()
    opts = replace(sc.solver, rtol=1e-8)

    def run(signal):
        best = np.inf
        for _ in range(3):
            start = time.perf_counter()
            out = simulate_model(replace(model, source=PrescribedPressure(signal)), sc.duration_s, opts)
            best = min(best, time.perf_counter() - start)
        return out, best

    full, t_full = run(Trace(res.t_s, res.p_gauge_Pa))
    print(f"8 s trace, rtol 1e-8: full 1 kHz pressure trace {t_full:.3f} s per simulation\n")
    print("| knot tolerance [Pa] | knots | breakpoints | s per simulation | largest contraction difference [mm] |")
    print("|---|---|---|---|---|")
    for tol in (1.0, 10.0, 100.0, 1000.0):
        sig = thinned_input(res.t_s, res.p_gauge_Pa, tol)
        out, t = run(sig)
        print(f"| {tol:g} | {len(sig.t_s)} | {len(sig.breakpoints)} | {t:.3f} | "
              f"{np.max(np.abs(out.x_m - full.x_m)) * 1e3:.4f} |")
    moving = np.abs(res.mode) == 1
    print(f"\nalong the truth trace (22.74 N): largest |damping force| {np.max(np.abs(res.signals['F_damping_N'])):.3f} N, "
          f"largest Coulomb level while sliding {np.max(res.signals['F_coulomb_level_N'][moving]):.2f} N, "
          f"largest speed {np.max(np.abs(res.v_m_s)):.3f} m/s")


def dynamic_study(scenario_path: str) -> None:
    """Finite-difference steps and the recovery of synthetic truth from one and from three loads."""
    from ..scenario import load_scenario

    sc = load_scenario(scenario_path)
    _fd_steps(sc)
    with ProcessPoolExecutor(2) as pool:
        _recovery(sc, [22.74], 8.0, pool)
        _recovery(sc, [12.74, 22.74, 32.74], 8.0, pool)


def _input_hold(sc: Scenario) -> None:
    """Native against Python contraction at the truth, recorded pressure (the thinned polyline, exact on both
    backends) and valve (a step), at several output sample rates."""
    noisy, _ = synthetic_trace(sc, TRUTH, 22.74, seed=0)
    by_valve = TraceData(noisy.t_s, noisy.x_m, None, 22.74)
    theta = np.array(list(TRUTH.values()))
    print("\n| output sample rate [Hz] | largest contraction difference, recorded pressure [mm] | "
          "same, valve [mm] |\n|---|---|---|")
    for rate in (10.0, 100.0, 1000.0, 4000.0):
        rated = sc.with_changes({"simulation": {"sample_rate_Hz": rate}})
        diff = []
        for tr in (noisy, by_valve):
            prob = make_problem(rated, [tr], free=tuple(TRUTH), loads_N=[22.74])
            x_py, = make_trials(prob, "python")(theta)
            x_nat, = make_trials(prob, "native")(theta)
            diff.append(np.max(np.abs(x_nat - x_py)) * 1e3)
        print(f"| {rate:g} | {diff[0]:.2e} | {diff[1]:.2e} |")


def native_study(scenario_path: str) -> None:
    """The dynamic study on the native backend: input hold, FD steps, recovery (in this process)."""
    from ..scenario import load_scenario

    sc = load_scenario(scenario_path)
    _input_hold(sc)
    _fd_steps(sc, "native")
    _recovery(sc, [22.74], 8.0, None, "native")
    _recovery(sc, [12.74, 22.74, 32.74], 8.0, None, "native")


STARTS_SETS = {"recovery study": tuple(TRUTH.values()), "B": (0.8, 0.3, 50.0, -20.0, 3.0),
               "C": (-1.5, 3.0, 400.0, -150.0, 10.0), "D": (2.0, 0.5, 0.0, 20.0, 2.0)}
"""Hidden coefficients (D1, D2, N2, N1, N0) of the multistart study: positive and negative D1, a small and a large
Coulomb level, a level that rises along the travel (N1 > 0)."""


def starts_study(scenario_path: str) -> None:
    """Native fits of the five coefficients to three synthetic loads (2.5 s, 0.05 mm noise, seeds 0-2) from the
    scenario's values and from zero friction and damping: one start, the default starts, the global search."""
    from ..scenario import load_scenario

    sc = load_scenario(scenario_path)
    free = tuple(TRUTH)
    runs = {"one start": {"n_starts": 0}, f"{DEFAULT_STARTS['native']} starts (default)": {},
            "--global, one start": {"n_starts": 0, "global_search": True}}
    print("\n| hidden set | start | RMS at the truth [mm] | " + " | ".join(f"{r}: RMS [mm], s" for r in runs)
          + " |\n|---|---|---|" + "---|" * len(runs))
    for label, values in STARTS_SETS.items():
        truth = dict(zip(free, values))
        noisy = [synthetic_trace(sc, truth, w, seed=i, duration_s=2.5)[0] for i, w in enumerate((12.74, 22.74, 32.74))]
        for start_label, start in (("scenario", sc), ("zero", sc.with_changes({"parameters": dict.fromkeys(free, 0.0)}))):
            prob = make_problem(start, noisy, free=free)
            at_truth = float(np.sqrt(np.mean(prob.residuals_from(make_trials(prob, "native")(np.array(values))) ** 2)))
            cells = []
            for options in runs.values():
                fit = fit_dynamic(start, noisy, free=free, backend="native", **options)
                cells.append(f"{fit.rms_pooled_mm:.4f}{'' if fit.success else ' (flagged)'}, {fit.wall_time_s:.1f}")
            print(f"| {label} {values} | {start_label} | {at_truth:.4f} | " + " | ".join(cells) + " |")
    print(f"\nload average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")


STUDIES = {"static": lambda scenario: static_study(), "dynamic": dynamic_study, "inputs": inputs_study,
           "native": native_study, "starts": starts_study}


def main() -> None:
    """``python -m pamsim.identification.studies static|dynamic|inputs|native|starts [--scenario S]``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("which", choices=tuple(STUDIES))
    parser.add_argument("--scenario", default="scenarios/acra2012_fig4.toml")
    args = parser.parse_args()
    STUDIES[args.which](args.scenario)


if __name__ == "__main__":
    main()
