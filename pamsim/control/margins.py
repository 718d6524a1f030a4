"""Loop margins of the closed-loop design, the loop broken at the valve command.

    python -m pamsim.control.margins scenarios/closed_loop_position.toml

prints the gain crossover (``|L| = 1``) with its phase margin, the phase crossover
(phase -180 deg) with its gain margin, and the phase a pure delay costs at the
gain crossover.  The loop is the linear design loop: the held plant
linearisation at the design contraction (Coulomb friction dropped; the full one,
spool, line and thermal gas included, where the controller was designed on a
reduced model) and the LQR controller with its velocity filter, no saturation
and no deadband.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import asdict, dataclass

import control as ct
import numpy as np

from ..errors import InputError
from ..scenario import Scenario, load_scenario
from .closed_loop import ControllerConfig, controller_system, design_lqr
from .reduced import line_components


@dataclass(frozen=True)
class LoopMargins:
    """Stability margins of the loop ``L = -C P`` (negative feedback convention), frequencies in Hz."""

    gain_crossover_Hz: float
    phase_margin_deg: float
    phase_crossover_Hz: float
    gain_margin: float
    open_loop_unstable_poles: int
    """Poles of L in the right half plane (the integrators at 0 are not counted)."""

    @property
    def gain_margin_dB(self) -> float:
        """The gain margin in decibels."""
        return 20.0 * math.log10(self.gain_margin)

    def delay_phase_deg(self, delay_s: float) -> float:
        """Phase [deg] a pure delay of ``delay_s`` costs at the gain crossover."""
        return 360.0 * self.gain_crossover_Hz * delay_s


def loop_transfer(scenario: Scenario) -> ct.StateSpace:
    """The loop broken at the valve command: command in, minus the controller's command out; around the full
    linearisation where the controller was designed on a reduced model (a spool, a line, a thermal gas)."""
    config = ControllerConfig.from_scenario(scenario)
    design = design_lqr(scenario.build_model(), config, scenario.final_pressure_gauge_Pa, line_components(scenario))
    held = design.full_linear or design.linear
    plant = held.sys[["contraction_m", "p_gauge_Pa"], "valve_command"]
    ctrl = controller_system(design, config)[:, ["contraction_m", "p_gauge_Pa"]]
    return -ct.series(plant, ctrl)


def loop_margins(scenario: Scenario | str) -> LoopMargins:
    """Gain and phase margins of the design loop of a scenario with a ``[controller]`` table."""
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    L = loop_transfer(scenario)
    gm, pm, _, w_pc, w_gc, _ = ct.stability_margins(L)
    poles = L.poles()
    unstable = int(np.sum(np.real(poles) > 1e-9 * np.max(np.abs(poles))))
    return LoopMargins(float(w_gc) / (2 * math.pi), float(pm), float(w_pc) / (2 * math.pi), float(gm), unstable)


def main(argv: list[str] | None = None) -> int:
    """``python -m pamsim.control.margins SCENARIO``: print the margins (as JSON with ``--json``); exit code 0,
    or 2 for bad input.
    """
    ap = argparse.ArgumentParser(prog="python -m pamsim.control.margins", description=__doc__.split("\n")[0])
    ap.add_argument("scenario", help="scenario TOML with a [controller] table")
    ap.add_argument("--delay-ms", type=float, default=0.5, help="delay whose phase cost is reported [ms]")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    try:
        m = loop_margins(args.scenario)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = {**asdict(m), "gain_margin_dB": m.gain_margin_dB,
           "delay_ms": args.delay_ms, "delay_phase_deg": m.delay_phase_deg(args.delay_ms * 1e-3)}
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print(f"gain crossover |L| = 1 at {m.gain_crossover_Hz:.2f} Hz, phase margin {m.phase_margin_deg:.1f} deg")
        change = "fall" if m.gain_margin < 1 else "rise"
        factor = 1 / m.gain_margin if m.gain_margin < 1 else m.gain_margin
        print(f"phase crossover -180 deg at {m.phase_crossover_Hz:.2f} Hz: the loop gain may {change} by a factor "
              f"{factor:.1f} ({m.gain_margin_dB:.1f} dB) before the loop goes unstable")
        print(f"open-loop unstable poles: {m.open_loop_unstable_poles}")
        print(f"a {args.delay_ms:g} ms delay costs {out['delay_phase_deg']:.2f} deg at the gain crossover")
    return 0


if __name__ == "__main__":
    sys.exit(main())
