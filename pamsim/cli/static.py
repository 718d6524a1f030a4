"""``pamsim static``: static equilibrium and force capability at one pressure and load."""

from __future__ import annotations

import argparse
import json

from ..constants import PA_PER_BAR
from ..errors import InputError
from . import finite_float, muscle_args


def register(sub) -> None:
    """Add ``pamsim static`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("static", help="static equilibrium and force capability",
                       description="Equilibrium contraction of a hanging load and the largest load held above "
                                   "the lower stop, from a static force model alone.")
    p.add_argument("--pressure-bar", type=finite_float, required=True, help="gauge pressure [bar]")
    p.add_argument("--load-N", type=finite_float, required=True, help="hanging weight [N], holder included")
    muscle_args.add_arguments(p)
    muscle_args.add_upper_stop_argument(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim static``: print the static equilibrium contraction under the load, the stop it rests on if any,
    the largest load held above the lower stop at the pressure and the upper stop (as JSON with ``--json``);
    exit code 0.
    """
    from ..elements.stops import UPPER_BASES
    from ..static import static_report

    muscle, params, model = muscle_args.resolve(args)
    rating = params["rated_pressure_gauge_Pa"]
    if args.pressure_bar < 0 or args.pressure_bar * PA_PER_BAR > rating:
        raise InputError(f"--pressure-bar = {args.pressure_bar:g}: must lie in [0, {rating / PA_PER_BAR:g}] bar "
                         "(the muscle's rating)")
    if args.load_N <= 0:
        raise InputError(f"--load-N = {args.load_N:g}: must be positive")
    stops = muscle_args.end_stops(args, muscle, params, model)
    report = static_report(params, model, args.pressure_bar * PA_PER_BAR, args.load_N, stops)
    report["upper_stop"] = args.upper_stop or muscle.upper_stop
    report["muscle"] = muscle.name
    report["model"] = model.name
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    x = report["equilibrium_contraction_m"]
    print(f"muscle {muscle.name}, model {model.name}, {args.pressure_bar:g} bar, {args.load_N:g} N")
    why = report["equilibrium_note"] or ("cannot lift it off the lower stop" if report["on_stop"] == "lower" else "")
    print(f"  equilibrium contraction: {x * 1e3:.3f} mm" + (f" ({why})" if why else ""))
    print(f"  force capability (max load held above the lower stop): {report['max_load_N']:.2f} N")
    print(f"  upper stop: {report['upper_stop_m'] * 1e3:.3f} mm ({UPPER_BASES[report['upper_stop_basis']]}; "
          f"choice {report['upper_stop']})")
    if not report["within_fit_range"]:
        print("  warning: outside the model's valid domain")
    return 0
