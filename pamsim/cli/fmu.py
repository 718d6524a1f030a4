"""``pamsim fmu build [-o PATH] [--fmi 2|3] [--scenario S.toml]``: compile the muscle model as an FMU."""

from __future__ import annotations

import argparse

from ..errors import InputError


def register(sub) -> None:
    p = sub.add_parser("fmu", help="export the model as an FMU",
                       description="Build a Functional Mock-up Unit (Model Exchange and Co-Simulation) of the "
                                   "muscle model with the system C compiler (docs/fmu.md).")
    fsub = p.add_subparsers(dest="fmu_command", required=True, metavar="ACTION")
    b = fsub.add_parser("build", help="compile and pack the FMU",
                        description="Generate the sources and model description, compile them and write the .fmu.")
    b.add_argument("-o", "--output", default=None,
                   help="FMU file to write (default: pamsim_muscle_fmi<version>.fmu in the current folder)")
    b.add_argument("--fmi", default="2", help="FMI version: 2 (FMI 2.0) or 3 (FMI 3.0); default 2")
    b.add_argument("--scenario", default=None,
                   help="bake the scenario's static force into the FMU as a force table (F(x, p) over its valid "
                        "domain, interpolated bicubically); the FMU then starts on the table")
    b.set_defaults(func=run_build)


def run_build(args: argparse.Namespace) -> int:
    from ..fmu import build

    if args.fmi not in ("2", "3"):
        raise InputError(f"--fmi = {args.fmi!r}: must be 2 or 3")
    table = None
    if args.scenario:
        from ..fmu.runner import tabulate_model
        from ..scenario import load_scenario

        table = tabulate_model(load_scenario(args.scenario))
    path = build(args.output, int(args.fmi), table)
    what = f", static force: a {table.shape[0]} x {table.shape[1]} table of {table.model_name}" if table else ""
    print(f"wrote {path} (FMI {args.fmi}.0, Model Exchange and Co-Simulation{what})")
    return 0
