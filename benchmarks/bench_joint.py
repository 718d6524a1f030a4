"""Muscles on a joint against one muscle on its hanging load, on both backends, in the same run.

The antagonistic pair (``scenarios/antagonistic_pair.toml``, run for 5 s) and the ACRA 2012 Figure 4
scenario (one muscle, 8 s), then the Festo pair, Figure 4 as a slider and the pair on elastic tendons
against Figure 4: the median wall time of N runs after warm-up, with the engine's own time for the
native runs, and the ratio pair / one muscle per backend.  Targets for the pair: native <= 2 ms,
python <= 80 ms.  A joint run's outputs (torques, flows) are computed when first read, as a one-muscle
run's force columns are; the timed runs read the angle only.

Run:  python benchmarks/bench_joint.py [--repeats N]
"""

from __future__ import annotations

import argparse
import statistics
import time
import tomllib
from pathlib import Path

import pamsim
from pamsim.joints import JointScenario, load_joint_scenario, simulate_joint

ROOT = Path(__file__).resolve().parents[1]
TARGETS_MS = {"native": 2.0, "python": 80.0}


def median_ms(run, repeats: int) -> tuple[float, float]:
    """Median wall time of ``run()`` [ms] over ``repeats`` calls after 3 warm-up calls, and the median of
    the results' own ``wall_time_s`` (the engine's time, on native)."""
    for _ in range(3):
        run()
    walls, own = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = run()
        walls.append(time.perf_counter() - t0)
        own.append(res.wall_time_s)
        res.position if hasattr(res, "position") else res.x_m  # noqa: B018 (what a caller reads)
    return statistics.median(walls) * 1e3, statistics.median(own) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    spec = tomllib.loads((ROOT / "scenarios" / "antagonistic_pair.toml").read_text())
    spec["simulation"] = {**spec.get("simulation", {}), "duration_s": 5.0}
    pair = JointScenario.from_dict(spec)
    fig4 = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    print(f"{'backend':8} {'pair 5 s [ms]':>14} {'(engine)':>9} {'target':>7} {'fig4 8 s [ms]':>14} {'pair / fig4':>12}")
    for backend in ("native", "python"):
        p_ms, p_own = median_ms(lambda: simulate_joint(pair, backend), args.repeats)
        f_ms, _ = median_ms(lambda: pamsim.simulate(fig4, backend=backend), args.repeats)
        engine = f"{p_own:9.3f}" if backend == "native" else " " * 9
        print(f"{backend:8} {p_ms:14.3f} {engine} {TARGETS_MS[backend]:7.1f} {f_ms:14.3f} {p_ms / f_ms:12.2f}")
    res = simulate_joint(pair, "native")
    print(f"pair on native: {res.stats['rhs_evaluations']} RHS evaluations, {len(res.transitions)} events, "
          f"final angle {res.theta_rad[-1]:.4f} rad")
    # The other shipped bodies, against Figure 4 on the same backend in the same run.
    others = {"Festo pair (Ogden), 3 s": load_joint_scenario(ROOT / "scenarios" / "antagonistic_festo.toml"),
              "Figure 4 as a slider, 8 s": load_joint_scenario(ROOT / "scenarios" / "acra2012_fig4_slider.toml"),
              "pair on 2 kN/m tendons, 3 s": load_joint_scenario(ROOT / "scenarios" / "antagonistic_elastic.toml")}
    print(f"{'scenario':28} {'backend':8} {'[ms]':>9} {'/ fig4':>7}")
    for backend in ("native", "python"):
        f_ms, _ = median_ms(lambda: pamsim.simulate(fig4, backend=backend), args.repeats)
        for label, scenario in others.items():
            ms, _ = median_ms(lambda: simulate_joint(scenario, backend), args.repeats)
            print(f"{label:28} {backend:8} {ms:9.3f} {ms / f_ms:7.2f}")


if __name__ == "__main__":
    main()
