"""``pamsim force``: the raw static force of one model at one point."""

from __future__ import annotations

import argparse
import json

from ..constants import PA_PER_BAR
from ..errors import InputError
from . import finite_float, muscle_args


def register(sub) -> None:
    """Add ``pamsim force`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("force", help="static force of a model at one contraction and pressure",
                       description="The raw static force (positive pulls; may be negative) of a library model "
                                   "for a muscle, after checking the point against the model's valid domain.")
    p.add_argument("--pressure-bar", type=finite_float, required=True, help="gauge pressure [bar]")
    p.add_argument("--contraction-mm", type=finite_float, required=True, help="contraction L0 - L [mm]")
    muscle_args.add_arguments(p)
    muscle_args.add_upper_stop_argument(p)
    p.add_argument("--json", action="store_true", help="print JSON (keys force_N, on_stop, upper_stop_m)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim force``: print the raw static force of one model at one contraction and pressure, and the stop the
    point lies on (at or past it; ``on_stop``: ``"upper"``, ``"lower"`` or null), as JSON with ``--json``; a point
    outside the model's domain is refused naming the flag; exit code 0.
    """
    muscle, params, model = muscle_args.resolve(args)
    x_m, p_Pa = args.contraction_mm * 1e-3, args.pressure_bar * PA_PER_BAR
    _check_domain(model, args, x_m, p_Pa)
    force = float(model.evaluate_N(x_m, p_Pa))
    stops = muscle_args.end_stops(args, muscle, params, model)
    on_stop = "upper" if x_m >= stops.x_high_m else "lower" if x_m <= stops.x_low_m else None
    if args.json:
        print(json.dumps({"muscle": muscle.name, "model": model.name, "contraction_m": x_m,
                          "pressure_gauge_Pa": p_Pa, "force_N": force, "on_stop": on_stop,
                          "upper_stop_m": stops.x_high_m, "upper_stop_basis": stops.upper_basis}, indent=2))
        return 0
    print(f"{model.name} on {muscle.name}: {force:.6g} N at {args.contraction_mm:g} mm, {args.pressure_bar:g} bar"
          + _stop_note(on_stop, stops))
    return 0


def _stop_note(on_stop: str | None, stops) -> str:
    """`` (at or past the upper stop, X mm)`` for a point on a stop, else nothing."""
    if on_stop is None:
        return ""
    x_mm = 1e3 * (stops.x_high_m if on_stop == "upper" else stops.x_low_m)
    return f" (at or past the {on_stop} stop, {x_mm:.4g} mm: a load there rests on it)"


def _check_domain(model, args: argparse.Namespace, x_m: float, p_Pa: float) -> None:
    """The model's domain check, reported with the flag and value the user wrote, in the flag's unit."""
    d = model.domain
    for flag, value, si, lo, hi, scale, unit in (
            ("--contraction-mm", args.contraction_mm, x_m, d.x_min_m, d.x_max_m, 1e3, "mm"),
            ("--pressure-bar", args.pressure_bar, p_Pa, d.p_min_Pa, d.p_max_Pa, 1.0 / PA_PER_BAR, "bar")):
        if not lo <= si <= hi:
            raise InputError(f"{flag} {value:g}: outside the valid domain of static model {model.name!r}, "
                             f"[{lo * scale:.4g}, {hi * scale:.4g}] {unit}")
