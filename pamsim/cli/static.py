"""``pamsim static``: static equilibrium and force capability at one pressure and load."""

from __future__ import annotations

import argparse
import json

from ..constants import PA_PER_BAR
from ..elements.static_force import STATIC_FORCE_MODELS
from ..errors import InputError
from ..parameters import PARAMETER_SETS
from . import finite_float


def register(sub) -> None:
    p = sub.add_parser("static", help="static equilibrium and force capability",
                       description="Equilibrium contraction of a hanging load and the largest load held above "
                                   "the lower stop, from the static force model alone.")
    p.add_argument("--pressure-bar", type=finite_float, required=True, help="gauge pressure [bar]")
    p.add_argument("--load-N", type=finite_float, required=True, help="hanging weight [N], holder included")
    p.add_argument("--set", default="shadow_6x300_acra2012", help="parameter set name")
    p.add_argument("--static-force", default="acra2012_polynomial", help="static force model")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..static import static_report

    if args.set not in PARAMETER_SETS:
        raise InputError(f"--set = {args.set!r}: unknown parameter set (choose from {', '.join(PARAMETER_SETS)})")
    if args.static_force not in STATIC_FORCE_MODELS:
        raise InputError(f"--static-force = {args.static_force!r}: unknown model "
                         f"(choose from {', '.join(STATIC_FORCE_MODELS)})")
    params = PARAMETER_SETS[args.set]
    rating = params["rated_pressure_gauge_Pa"]
    if args.pressure_bar < 0 or args.pressure_bar * PA_PER_BAR > rating:
        raise InputError(f"--pressure-bar = {args.pressure_bar:g}: must lie in [0, {rating / PA_PER_BAR:g}] bar "
                         "(the muscle's rating)")
    if args.load_N <= 0:
        raise InputError(f"--load-N = {args.load_N:g}: must be positive")
    report = static_report(params, STATIC_FORCE_MODELS[args.static_force](params),
                           args.pressure_bar * PA_PER_BAR, args.load_N)
    report["parameter_set"] = args.set
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    x = report["equilibrium_contraction_m"]
    print(f"parameter set {args.set}, {args.pressure_bar:g} bar, {args.load_N:g} N")
    print(f"  equilibrium contraction: {x * 1e3:.3f} mm" + ("" if x > 0 else " (cannot lift it off the lower stop)"))
    print(f"  force capability (max load held above the lower stop): {report['max_load_N']:.2f} N")
    if not report["within_fit_range"]:
        print("  warning: outside the range the polynomial was fitted on")
    return 0
