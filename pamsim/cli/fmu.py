"""``pamsim fmu build [-o PATH] [--fmi 2|3] [--scenario S.toml | --muscle M [--static-force NAME]]``:
compile the muscle model as an FMU, for a scenario or a muscle if one is given."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import InputError


def register(sub) -> None:
    """Add ``pamsim fmu build`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("fmu", help="export the model as an FMU",
                       description="Build a Functional Mock-up Unit (Model Exchange and Co-Simulation) of the "
                                   "muscle model with the system C compiler (docs/fmu.md).")
    fsub = p.add_subparsers(dest="fmu_command", required=True, metavar="ACTION")
    b = fsub.add_parser("build", help="compile and pack the FMU",
                        description="Generate the sources and model description, compile them and write the .fmu.")
    b.add_argument("-o", "--output", default=None,
                   help="FMU file to write (default: pamsim_muscle_fmi<version>.fmu in the current folder, or "
                        "pamsim_assembly_fmi<version>.fmu for a scenario that adds components, has a controller or "
                        "a chamber law other than the polytropic)")
    b.add_argument("--fmi", default="2", help="FMI version: 2 (FMI 2.0) or 3 (FMI 3.0); default 2")
    b.add_argument("--scenario", default=None,
                   help="build the FMU for this scenario: its muscle's and its own values (parameters, choices, "
                        "initial state, input signals, run) are the FMU's start values, and a static force other "
                        "than the ACRA 2012 polynomial is baked in as a force table; a scenario that adds components "
                        "([[component]]), has a [controller] or a [chamber] law other than the polytropic gives "
                        "the FMU generated from its assembly, with "
                        "structured names (the controller, designed as pamsim run designs it, inside)")
    b.add_argument("--muscle", default=None,
                   help="build the FMU for this muscle (shipped name or TOML path): its parameters are the FMU's "
                        "start values, and its static force is baked in as a force table")
    b.add_argument("--static-force", default=None,
                   help="with --muscle: the library static force model (default: the muscle's default_static_force)")
    b.add_argument("--static-force-variant", default=None, help="variant of that model (default: its default)")
    b.add_argument("--generated", action="store_true",
                   help="with --scenario: the FMU generated from the scenario's assembly of components (structured "
                        "names such as load.x_m, exact directional derivatives), as a scenario that adds components "
                        "always gets, rather than the one-muscle FMU with its own variable names")
    b.add_argument("--muscle-only", action="store_true",
                   help="with --scenario: the muscle alone, its length and lengthening velocity inputs (length_m, "
                        "lengthening_velocity_m_s) and its force an output (motion.F_N), for an importer that owns "
                        "the mechanics; the scenario gives the muscle, its model and its pressure source")
    b.set_defaults(func=run_build)


def _muscle_scenario(args: argparse.Namespace):
    """The smallest scenario naming the muscle and model, so they are checked as a scenario file's would be."""
    from ..scenario import Scenario

    model = {"muscle": args.muscle}
    if args.static_force:  # else the scenario's default: the muscle's default_static_force
        model["static_force"] = args.static_force
    if args.static_force_variant:
        model["static_force_variant"] = args.static_force_variant
    spec = {"model": model, "load": {"weight_N": 1.0},
            "pressure": {"source": "valve", "supply_gauge_bar": 0.0, "valve_open_time_s": 0.0},
            "simulation": {"duration_s": 1.0}}
    return Scenario.from_dict(spec, name="fmu_force_table", origin="pamsim fmu build --muscle")


def _build_assembly(scenario, args: argparse.Namespace) -> int:
    """The FMU generated from the scenario's assembly: its added components, or its controller (designed
    here, as ``pamsim run`` designs it), in the FMU; exit code 0."""
    from ..fmu import build_assembly

    model, what = None, ""
    if "controller" in scenario.spec:
        from ..control.closed_loop import design_closed_loop

        model, what = design_closed_loop(scenario).model, " with its controller"
    path = build_assembly(scenario, args.output, int(args.fmi), model)
    print(f"wrote {path} (FMI {args.fmi}.0, Model Exchange and Co-Simulation, generated from the assembly "
          f"of scenario {scenario.name}{what}: structured variable names such as load.x_m)")
    return 0


def run_build(args: argparse.Namespace) -> int:
    """``pamsim fmu build``: compile the FMU (FMI 2.0 or 3.0), with the static force of ``--scenario`` or of
    ``--muscle`` and ``--static-force`` baked in as a table when given; exit code 0.
    """
    from ..fmu import build

    by_muscle = _check_options(args)
    scenario = None
    if args.scenario:
        from .run import is_joint, load_any_scenario

        scenario = load_any_scenario(Path(args.scenario))
        if is_joint(scenario):
            if args.muscle_only:
                raise InputError(f"--muscle-only: {args.scenario} is a joint scenario; give a one-muscle scenario "
                                 "(its muscle, model and pressure source) for the muscle-only FMU")
            return _build_joint(scenario, args)
        if args.muscle_only:
            return _build_muscle_only(scenario, args)
        if "motion" in scenario.spec:
            raise InputError(f"{args.scenario}: [motion]: a muscle driven by its length has no load; build its "
                             "FMU with --muscle-only")
        if scenario.beyond_one_muscle_fmu or args.generated or "controller" in scenario.spec:
            return _build_assembly(scenario, args)
    preset = _preset(args, scenario, by_muscle)
    path = build(args.output, int(args.fmi), preset=preset)
    print(f"wrote {path} (FMI {args.fmi}.0, Model Exchange and Co-Simulation{_built_for(preset)})")
    return 0


def _build_joint(scenario, args: argparse.Namespace) -> int:
    """The FMU of muscles on a joint (:func:`pamsim.joints.fmu.build_joint_fmu`)."""
    from ..joints.fmu import build_joint_fmu

    path = build_joint_fmu(scenario, args.output, int(args.fmi))
    body, n = scenario.body, len(scenario.muscles)
    print(f"wrote {path} (FMI {args.fmi}.0, Model Exchange and Co-Simulation, the {body.name} and its "
          f"{n} muscle{'s' if n > 1 else ''} of scenario {scenario.name}: structured variable names such as "
          f"{body.name}.{body.position})")
    if scenario.controller is not None:
        print("  the scenario's [controller] is not in the FMU: it is the plant, its pressure inputs "
              "(input_source = importer) the importer's controller's to set")
    return 0


def _build_muscle_only(scenario, args: argparse.Namespace) -> int:
    """The muscle-only FMU of a one-muscle scenario (:mod:`pamsim.fmu.muscle_only`)."""
    from ..fmu.muscle_only import build_muscle_only
    from ..muscle_alone import motion_of

    motion = motion_of(scenario) if "motion" in scenario.spec else None
    path = build_muscle_only(scenario, args.output, int(args.fmi), motion)
    print(f"wrote {path} (FMI {args.fmi}.0, Model Exchange and Co-Simulation, the muscle of scenario {scenario.name} "
          "alone: inputs length_m and lengthening_velocity_m_s, its force the output motion.F_N"
          + (", following the scenario's [motion] until the importer drives it)" if motion else ")"))
    return 0


def _check_options(args: argparse.Namespace) -> bool:
    """Refuse an FMI version other than 2 or 3 and options that do not go together, in this order; return
    whether the FMU is built for a muscle (``--muscle``, ``--static-force`` or ``--static-force-variant``)."""
    if args.fmi not in ("2", "3"):
        raise InputError(f"--fmi = {args.fmi!r}: must be 2 or 3")
    by_muscle = any(a is not None for a in (args.muscle, args.static_force, args.static_force_variant))
    if args.scenario and by_muscle:
        raise InputError(f"--scenario = {args.scenario!r}: give either --scenario or --muscle")
    if by_muscle and args.muscle is None:
        given = "--static-force" if args.static_force is not None else "--static-force-variant"
        raise InputError(f"--muscle: needed with {given}")
    if args.muscle_only and not args.scenario:
        raise InputError("--muscle-only: needs --scenario (its muscle, model and pressure source)")
    if args.generated and not args.scenario:
        raise InputError("--generated: needs --scenario (the FMU is generated from the scenario's assembly)")
    return by_muscle


def _preset(args: argparse.Namespace, scenario, by_muscle: bool):
    """The :class:`pamsim.fmu.preset.Preset` the one-muscle FMU is built for: the scenario's, the muscle's,
    or None (the FMU of the paper's muscle)."""
    if scenario is None and not by_muscle:
        return None
    from ..fmu import preset as presets

    return presets.for_scenario(scenario) if scenario is not None else presets.for_muscle(_muscle_scenario(args))


def _built_for(preset) -> str:
    """What the report line adds for a preset: what the FMU is built for and its static force."""
    if preset is None:
        return ""
    table = preset.table
    force = (f"a {table.shape[0]} x {table.shape[1]} table of {table.model_name}" if table
             else "the ACRA 2012 polynomial, exact")
    return f", for {preset.built_for}; static force: {force}"
