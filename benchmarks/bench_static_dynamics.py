"""Benchmark: the fig4 scenario with every static force model, time relative to the polynomial.

The fig4 scenario (ACRA 2012 Figure 4: valve step to 3.6 bar at 1 s, 8 s, LSODA at rtol 1e-6) is
run with each library model on the Shadow muscle where the model applies to it; a model that needs
values the Shadow muscle does not give (wall thickness, bladder constants, fibres) runs the same
scenario on Kothera's actuator 5a (friction and damping: the assumed defaults), with the load at
30 % of that model's blocked force at 3.6 bar.  The runs differ in their dynamics too (a model that
lifts the load higher or a muscle without friction oscillates longer and takes more steps), so the
ratio is the cost of a model's whole run, not of its force evaluation alone.  Two more rows force the
polynomial and Kothera's energy model through the table the dynamics use for implicit models: the
polynomial's table follows the polynomial's own trajectory, so its ratio is the table's cost.

Target (issue): a paper scenario with an implicit (tabulated) model costs at most 3x the
polynomial's run.  Each figure is the median of --repeats runs (default 3), wall time of
``pamsim.simulate`` only (the table is built when the scenario is validated and cached).

Run on one core:  taskset -c 0 python benchmarks/bench_static_dynamics.py [--repeats N] [--tables]
(``--tables``: only the two table rows, each against its closed form, and the table errors).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time
from pathlib import Path

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402

import pamsim  # noqa: E402
import pamsim.elements.muscle_force as muscle_force  # noqa: E402
from pamsim.muscles import load_muscle  # noqa: E402
from pamsim.parameters import dynamics_parameters  # noqa: E402
from pamsim.static_models import REGISTRY  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TARGET_RATIO_IMPLICIT = 3.0


def _time(scenario: pamsim.Scenario, repeats: int) -> tuple[float, pamsim.Result]:
    times, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = pamsim.simulate(scenario)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), res


def _scenario(base: pamsim.Scenario, model: str) -> pamsim.Scenario:
    shadow = dynamics_parameters(load_muscle("shadow_6x300_acra2012").parameters)
    if not REGISTRY[model].missing(shadow):
        return base.with_changes({"model": {"static_force": model}}, name=f"fig4_{model}")
    kothera = dynamics_parameters(load_muscle("kothera2009_5a").parameters)
    blocked = float(REGISTRY[model].build(kothera).force_N(0.0, 3.6e5))
    return base.with_changes({"model": {"muscle": "kothera2009_5a", "static_force": model},
                              "load": {"weight_N": 0.3 * blocked}}, name=f"fig4_{model}_kothera5a")


def table_errors() -> None:
    """Largest table error (cell centres) of every model the three muscles give, relative to its
    blocked force at the muscle's rating: what the dynamics would use if the model were implicit; with
    the largest grid refinement made and the slowest build.  Then the one implicit model, two-phase, on
    the 45 mm muscle with an assumed nylon modulus of 3 GPa."""
    from pamsim.elements.force_table import table_error, tabulate
    from pamsim.elements.stops import EndStops

    print("table error, spline on the refined grid, max |table - model| / blocked force at the rating:")
    for muscle in ("shadow_6x300_acra2012", "kothera2009_5a", "mpam_survey_45mm"):
        m = load_muscle(muscle)
        p = dynamics_parameters(m.parameters)
        worst, largest, slowest = (0.0, ""), (0, 0, ""), (0.0, "")
        for name in m.applicable_models():
            model = REGISTRY[name].build(p)
            t0 = time.perf_counter()
            t = tabulate(model, (0.0, EndStops.from_parameters(p).x_high_m), (0.0, p["rated_pressure_gauge_Pa"]))
            slowest = max(slowest, (time.perf_counter() - t0, name))
            largest = max(largest, (len(t.x_grid_m) * len(t.p_grid_Pa), f"{len(t.x_grid_m)} x {len(t.p_grid_Pa)}",
                                    name))
            rel = table_error(model, t) / abs(float(model.force_N(0.0, p["rated_pressure_gauge_Pa"])))
            worst = max(worst, (rel, name))
        print(f"  {muscle:24s} worst {worst[0] * 100:.4f} % ({worst[1]}) over {len(m.applicable_models())} models "
              f"(target <= 0.1 %); largest grid {largest[1]} ({largest[2]}); slowest build "
              f"{slowest[0] * 1e3:.0f} ms ({slowest[1]})")
    m = load_muscle("mpam_survey_45mm").static_force("mpam_two_phase", overrides={"E_nylon_Pa": 3e9})
    t0 = time.perf_counter()
    t = tabulate(m, (0.0, m.domain.x_max_m), (0.0, 827e3))
    build = time.perf_counter() - t0
    print(f"  mpam_two_phase, 45 mm, E_nylon 3 GPa: {table_error(m, t) / m.force_N(0.0, 827e3) * 100:.4f} % on a "
          f"{len(t.x_grid_m)} x {len(t.p_grid_Pa)} grid, built in {build:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--tables", action="store_true", help="only the table rows and the table errors")
    args = ap.parse_args()
    base = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    t_poly, _ = _time(base, args.repeats)
    print(f"fig4 with acra2012_polynomial: {t_poly * 1e3:.1f} ms (median of {args.repeats})")
    print(f"{'model':38s} {'muscle':24s} {'kind':12s} {'time [ms]':>10s} {'ratio':>7s} {'final x [mm]':>12s}")
    models = [] if args.tables else [m for m, s in REGISTRY.items() if s.kind != "table"]
    kothera = dynamics_parameters(load_muscle("kothera2009_5a").parameters)
    shadow = dynamics_parameters(load_muscle("shadow_6x300_acra2012").parameters)
    for model in models:
        if REGISTRY[model].missing(shadow) and REGISTRY[model].missing(kothera):
            print(f"{model:38s} (needs parameters neither muscle gives: {', '.join(REGISTRY[model].missing(kothera))})")
            continue
        sc = _scenario(base, model)
        t, res = _time(sc, args.repeats)
        print(f"{model:38s} {sc.muscle.name:24s} {REGISTRY[model].kind:12s} {t * 1e3:10.1f} {t / t_poly:7.2f} "
              f"{res.x_m[-1] * 1e3:12.3f}")
    # The table path: a model marked implicit, so the dynamics tabulate it.  The polynomial through its
    # table follows the same trajectory as the polynomial itself, so the ratio is the table's own cost.
    for model in ("acra2012_polynomial", "kothera_energy"):
        implicit = dataclasses.replace(REGISTRY[model], kind="implicit")
        original = muscle_force.get
        muscle_force.get = lambda name, m=model, s=implicit: s if name == m else original(name)
        try:
            t_build = time.perf_counter()
            sc = _scenario(base, model)
            t_build = time.perf_counter() - t_build
            t, res = _time(sc, args.repeats)
        finally:
            muscle_force.get = original
        t_closed, closed = _time(_scenario(base, model), args.repeats)
        print(f"{model + ' as a table':38s} {sc.muscle.name:24s} {'(tabulated)':12s} {t * 1e3:10.1f} {t / t_poly:7.2f} "
              f"{res.x_m[-1] * 1e3:12.3f}   vs its closed form: {t / t_closed:.2f}x, final x "
              f"{abs(res.x_m[-1] - closed.x_m[-1]) * 1e6:.3g} um apart; "
              f"scenario validation with the table build: {t_build * 1e3:.0f} ms")
        if model == "acra2012_polynomial":
            ratio = t / t_poly
            print(f"  the fig4 run through a table costs {ratio:.2f}x the polynomial's run (target <= "
                  f"{TARGET_RATIO_IMPLICIT:g}x: {'met' if ratio <= TARGET_RATIO_IMPLICIT else 'NOT met'})")
    two_phase_table_against_itself()
    table_errors()


def two_phase_table_against_itself() -> None:
    """The implicit two-phase model (45 mm muscle, E_nylon 3 GPa, a 0.2-1.2 s ramp to 7 bar) through its
    table, as the dynamics run it, and solved at every evaluation (marked closed-form here): the final
    contraction of each and how far apart they are."""
    spec = {"model": {"muscle": "mpam_survey_45mm", "static_force": "mpam_two_phase"},
            "parameters": {"E_nylon_Pa": 3e9}, "load": {"weight_N": 0.05},
            "simulation": {"duration_s": 2.0, "sample_rate_Hz": 100.0},
            "pressure": {"source": "prescribed",
                         "prescribed": {"kind": "ramp", "start_s": 0.2, "end_s": 1.2, "final_gauge_bar": 7.0}}}
    table = pamsim.simulate(pamsim.Scenario.from_dict(spec))
    exact_spec = dataclasses.replace(REGISTRY["mpam_two_phase"], kind="closed-form")
    original = muscle_force.get
    muscle_force.get = lambda name: exact_spec if name == "mpam_two_phase" else original(name)
    try:
        t0 = time.perf_counter()
        exact = pamsim.simulate(pamsim.Scenario.from_dict(spec))
        t_exact = time.perf_counter() - t0
    finally:
        muscle_force.get = original
    print(f"mpam_two_phase ramp (45 mm, 3 GPa): final x {table.x_m[-1] * 1e3:.6f} mm through its table, "
          f"{exact.x_m[-1] * 1e3:.6f} mm solved at every evaluation ({t_exact:.1f} s): "
          f"{abs(table.x_m[-1] - exact.x_m[-1]) * 1e6:.3g} um apart, largest {np.max(np.abs(table.x_m - exact.x_m)) * 1e6:.3g} um")


if __name__ == "__main__":
    main()
