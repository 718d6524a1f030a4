"""The 66 ACRA 2012 cases rerun with a tube between the valve and the muscle and with the thermal chamber.

    python benchmarks/fidelity_pneumatics.py [--backend native] [--friction load_dependent]
        [--lengths-m 0.25,0.5,1.0] [--diameter-mm 2.5] [--h-W-per-m2-K 15.7] [--T-wall-K 293.15]

Every configuration is ``scenarios/acra2012_grid.toml`` (its 66 cases, one friction model) run by
:func:`pamsim.sweep.run_sweep`, the path of ``pamsim sweep``, with its base scenario (Figure 4's rig: the
valve opens at 1 s onto the case's stable pressure) changed in two ways only:

- a tube between the valve and the muscle (``[pressure] outlet_port = "tube.inlet"``, the tube's bore at the
  valve's side and its laminar resistance before the muscle, as in ``scenarios/supply_chain.toml``), of each
  length of ``--lengths-m`` and the bore ``--diameter-mm``; its gas is isothermal (the tube's default);
- the chamber's law: today's polytropic one (the muscle's index, 1), or the thermal one (``[chamber] law =
  "thermal"`` with ``--h-W-per-m2-K`` and ``--T-wall-K``).

Nothing else changes: the valve (C = 1e-9 m^3/(s Pa)), the friction and damping, the cases.  For each
configuration it prints, over the cases within force capability (static equilibrium >= 5 mm, 28 of them):
the RMS, largest and mean error of the final contraction against the paper's Table 2 (the figure
``docs/validation.md`` gives as 2.61 mm for today's rig), the median settling times after the valve opens
(the pressure's and the contraction's: the time after which each stays within 5 % of its step of its final
value, ``pamsim.sweep.settled_time_s``), the cases at rest at 8 s (of 66), how far the final contractions
moved from today's rig, and the wall time of the 66 runs (the backend's code built beforehand).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

import pamsim
from pamsim.elements.friction import FRICTION_MODELS
from pamsim.errors import InputError
from pamsim.scenario import Scenario
from pamsim.sweep import load_sweep, run_sweep
from pamsim.sweep.report import error_stats_mm

ROOT = Path(__file__).resolve().parents[1]
GRID = ROOT / "scenarios" / "acra2012_grid.toml"
BACKENDS = ("native", "python")
LAWS = ("polytropic", "thermal")


@dataclasses.dataclass(frozen=True)
class Config:
    """One configuration of the rig: a tube (None: the valve straight onto the muscle, today's rig) and a
    chamber law with its wall's heat transfer and temperature (the thermal law's only)."""

    tube_length_m: float | None = None
    tube_diameter_m: float = 2.5e-3
    law: str = "polytropic"
    h_W_per_m2_K: float = 15.7
    T_wall_K: float = 293.15

    @property
    def label(self) -> str:
        """A short name for the table."""
        tube = "no tube" if self.tube_length_m is None else \
            f"tube {self.tube_length_m:g} m x {self.tube_diameter_m * 1e3:g} mm"
        law = self.law if self.law != "thermal" else f"thermal h={self.h_W_per_m2_K:g}"
        return f"{tube}, {law}"


def configurations(lengths_m, diameter_m: float, h_W_per_m2_K: float, T_wall_K: float) -> list[Config]:
    """Today's rig first, then each tube, then the same without and with each tube under the thermal law."""
    out = []
    for law in LAWS:
        for length in (None, *lengths_m):
            out.append(Config(length, diameter_m, law, h_W_per_m2_K, T_wall_K))
    return out


def variant(base: Scenario, config: Config) -> Scenario:
    """``base`` with ``config``'s tube between its valve and its muscle and its chamber law."""
    spec = {k: dict(v) if isinstance(v, dict) else v for k, v in base.spec.items()}
    if config.tube_length_m is not None:
        spec["pressure"]["outlet_port"] = "tube.inlet"
        spec["component"] = [{"name": "tube", "type": "tube", "inlet": "volume", "length_m": config.tube_length_m,
                              "diameter_m": config.tube_diameter_m, "connect": {"outlet": "chamber.port"}}]
    if config.law == "thermal":
        spec["chamber"] = {"law": "thermal", "h_W_per_m2_K": config.h_W_per_m2_K, "T_wall_K": config.T_wall_K}
    elif config.law != "polytropic":
        spec["chamber"] = {"law": config.law, "T_wall_K": config.T_wall_K}
    return Scenario.from_dict(spec, f"{base.name}_{config.label}", base.base_dir, f"{base.origin} [{config.label}]")


def grid(friction: str, config: Config, cases=None):
    """The grid's sweep with ``config``'s base, one friction model, no frequency or response studies;
    ``cases`` (indices) keeps some of its cases."""
    spec = load_sweep(GRID)
    kept = spec.cases if cases is None else tuple(spec.cases[i] for i in cases)
    return dataclasses.replace(spec, base=variant(spec.base, config), cases=kept, friction_models=(friction,),
                               frequency=None, time_responses=())


def rerun(friction: str, config: Config, backend: str, cases=None) -> tuple[list[dict], float]:
    """The summary rows of the grid's cases under ``config`` and the wall time of their runs [s] (the
    backend's code for this structure built by a first run beforehand)."""
    spec = grid(friction, config, cases)
    pamsim.simulate(spec.case_scenario(spec.cases[0], friction), backend=backend)
    result = run_sweep(spec, backend=backend)
    failed = [r["failure"] for r in result.rows if r["failure"]]
    if failed:
        raise RuntimeError(f"{config.label}: {len(failed)} runs failed, the first: {failed[0]}")
    return result.rows, result.wall_time_s


def summarise(rows: list[dict], valve_open_s: float, today: list[dict] | None = None) -> dict[str, float]:
    """The figures of one configuration: final-contraction error within capability [mm], median settling
    times after the valve opens [s], cases at rest, and the largest change of a final contraction from
    ``today``'s rows [mm]."""
    within = [r for r in rows if r["within_capability"] and math.isfinite(r["measured_contraction_m"])]
    errors = np.array([r["error_m"] for r in within])
    rms, largest, n = error_stats_mm(errors)
    out = {"n_within": n, "rms_mm": rms, "max_mm": largest, "mean_mm": float(np.mean(errors)) * 1e3,
           "pressure_settling_s": float(np.median([r["settled_time_s"] for r in within])) - valve_open_s,
           "stuck_settling_s": _median_settling(within, True) - valve_open_s,
           "ringing_settling_s": _median_settling(within, False) - valve_open_s,
           "at_rest": sum(bool(r["at_rest"]) for r in rows), "n_cases": len(rows),
           "figure4_settling_s": _figure4(rows)["contraction_settled_time_s"] - valve_open_s}
    ringing = [r["last_second_peak_to_peak_m"] for r in rows if not r["at_rest"]]
    out["ringing_mm"] = float(np.median(ringing)) * 1e3 if ringing else 0.0
    if today is not None:
        moved = [abs(r["final_contraction_m"] - t["final_contraction_m"]) for r, t in zip(rows, today)]
        out["largest_change_mm"] = max(moved) * 1e3
    return out


def _median_settling(rows: list[dict], at_rest: bool) -> float:
    """The median settling time of the contraction [s] over the rows at rest at the end (``at_rest``) or
    not: the cases that stick and the cases that still ring at 8 s settle seconds apart, and a median
    over both would fall between the groups and jump from one to the other."""
    times = [r["contraction_settled_time_s"] for r in rows if bool(r["at_rest"]) == at_rest]
    return float(np.median(times)) if times else math.nan


def _figure4(rows: list[dict]) -> dict:
    """The row of the paper's Figure 4 test: the 3.6 bar step with the 22.74 N weight."""
    return next(r for r in rows if r["pressure_step_bar"] == 3.6 and r["weight_N"] == 22.74)


class _Parser(argparse.ArgumentParser):
    """Bad arguments: one line naming the option and the value, exit code 2."""

    def error(self, message: str):
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def _positive_list(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: comma-separated numbers expected") from None
    if not values or not all(math.isfinite(v) and v > 0 for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: every length must be a finite number > 0")
    return values


def _number(low: float, inclusive: bool):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: not a number") from None
        if not math.isfinite(value) or value < low or (value == low and not inclusive):
            raise argparse.ArgumentTypeError(f"{text!r}: must be {'>=' if inclusive else '>'} {low:g}")
        return value
    return parse


def parse_args(argv=None) -> argparse.Namespace:
    """The command line, checked (exit code 2 and one line on a bad value)."""
    parser = _Parser(prog="fidelity_pneumatics.py", description=__doc__.splitlines()[0])
    parser.add_argument("--backend", choices=BACKENDS, default="native")
    parser.add_argument("--friction", choices=sorted(FRICTION_MODELS), default="load_dependent")
    parser.add_argument("--lengths-m", type=_positive_list, default=(0.25, 0.5, 1.0),
                        help="tube lengths [m] (default 0.25,0.5,1.0; assumed, docs/validation.md)")
    parser.add_argument("--diameter-mm", type=_number(0.0, False), default=2.5,
                        help="the tube's inner diameter [mm] (default 2.5: a 4 mm OD polyurethane tube, assumed)")
    parser.add_argument("--h-W-per-m2-K", dest="h", type=_number(0.0, True), default=15.7,
                        help="the thermal chamber's wall heat transfer (default: the law's, 15.7)")
    parser.add_argument("--T-wall-K", dest="T_wall", type=_number(0.0, False), default=293.15,
                        help="the wall's temperature [K] (default: the law's, room temperature)")
    return parser.parse_args(argv)


HEADER = (f"{'configuration':38} {'n':>3} {'RMS mm':>7} {'max mm':>7} {'mean mm':>8} {'p settle s':>10} "
          f"{'x stuck s':>9} {'x ring s':>8} {'fig4 x s':>8} {'at rest':>8} {'ring mm':>7} {'moved mm':>9} "
          f"{'wall s':>7}")
LEGEND = ("n: cases within capability; RMS, max, mean: final contraction minus Table 2 over them [mm]; "
          "p settle: median settling time after the valve opens of the pressure (within 5 % of its step) over "
          "them; x stuck, x ring: the same of the contraction over those at rest at 8 s and over those not; "
          "fig4 x s: the contraction's of the 3.6 bar / 22.74 N test (Figure 4); at rest: cases at rest at 8 s; "
          "ring mm: median peak-to-peak contraction over the last second of the cases not at rest; moved mm: "
          "largest change of a final contraction from the first line; wall s: the 66 runs")


def _line(config: Config, s: dict, wall_s: float) -> str:
    return (f"{config.label:38} {s['n_within']:3d} {s['rms_mm']:7.2f} {s['max_mm']:7.2f} {s['mean_mm']:8.2f} "
            f"{s['pressure_settling_s']:10.3f} {s['stuck_settling_s']:9.3f} {s['ringing_settling_s']:8.3f} "
            f"{s['figure4_settling_s']:8.3f} "
            f"{s['at_rest']:4d}/{s['n_cases']:<3d} {s['ringing_mm']:7.3f} {s.get('largest_change_mm', 0.0):9.2f} "
            f"{wall_s:7.2f}")


def main(argv=None) -> int:
    """Run every configuration and print its line of the table."""
    args = parse_args(argv)
    configs = configurations(args.lengths_m, args.diameter_mm * 1e-3, args.h, args.T_wall)
    valve_open_s = float(load_sweep(GRID).base.spec["pressure"]["valve_open_time_s"])
    print(f"the 66 cases of {GRID.name}, {args.friction} friction, {args.backend} backend; "
          "errors over the cases within capability")
    print(LEGEND)
    print(HEADER)
    today = None
    for config in configs:
        try:
            rows, wall_s = rerun(args.friction, config, args.backend)
        except InputError as exc:
            sys.stderr.write(f"fidelity_pneumatics.py: error: {exc}\n")
            return 2
        today = today or rows
        print(_line(config, summarise(rows, valve_open_s, today), wall_s), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
