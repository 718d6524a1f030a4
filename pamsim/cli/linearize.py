"""``pamsim linearize SCENARIO``: a linear model of the muscle at an operating point.

Without an option the operating point is the scenario's load at rest with the
valve open and the chamber at the supply pressure; ``--contraction-mm X`` holds
X with the valve closed; ``--at-time T`` takes the state of the scenario's
simulation at T.
"""

from __future__ import annotations

import argparse
import json
import sys
import math
from pathlib import Path

from ..atomic import atomic_outputs, output_folder
from ..control.choices import FRICTION_KINDS, VALVE_SLOPES
from ..errors import InputError
from . import figure_args, finite_float

DEFAULT_OUTPUT = "out"

HYSTERESIS_FRICTION = "no Coulomb friction: the [hysteresis] elements take its place (below)"


def register(sub) -> None:
    """Add ``pamsim linearize`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("linearize", help="linear model at an operating point (python-control)",
                       description="Linearise the muscle about an operating point of a scenario (valve source); "
                                   "print A, B, C, D, poles, the mechanical mode and DC gains; write a Bode plot "
                                   "and a pole-zero map into DIR (with --json only when -o is given).")
    p.add_argument("scenario", help="scenario TOML file (valve source)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--at-time", type=finite_float, metavar="T", help="state of the simulation at T [s]")
    where.add_argument("--contraction-mm", type=finite_float, metavar="X",
                       help="hold contraction X [mm] with the valve closed")
    p.add_argument("--friction", choices=FRICTION_KINDS, default="dropped",
                   help="Coulomb friction: dropped (default), regularised, or sliding (moving load only)")
    p.add_argument("--friction-velocity-mm-s", type=finite_float, default=1.0,
                   help="velocity scale of the regularised friction [mm/s] (default 1)")
    p.add_argument("--valve-slope", choices=VALVE_SLOPES, default="mean",
                   help="valve slope at command 0: mean of fill and vent (default), fill, vent")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("-o", "--output", default=None,
                   help=f"directory for the plots (default: {DEFAULT_OUTPUT}; with --json: no plots)")
    figure_args.add_arguments(p)
    p.set_defaults(func=run)


def _listed(names: list[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return " and ".join(names) if len(names) < 3 else f"{', '.join(names[:-1])} and {names[-1]}"


def _joint_friction_line(muscles: list[str], with_hysteresis: list[str]) -> str:
    """What a joint's linearisation did with friction: the bearing's and the Coulomb friction of the muscles
    without ``[hysteresis]`` dropped, each named; the elements of the others in its place."""
    dropped = [m for m in muscles if m not in with_hysteresis]
    whose = "the bearing's" + (f" and that of muscle{'s' * (len(dropped) > 1)} {_listed(dropped)}"
                               if dropped else "")
    line = f"Coulomb friction dropped ({whose}: no linearisation at rest)"
    if with_hysteresis:
        line += (f"; the [hysteresis] elements of muscle{'s' * (len(with_hysteresis) > 1)} "
                 f"{_listed(with_hysteresis)} take "
                 f"{'its' if len(with_hysteresis) == 1 else 'their'} Coulomb friction's place (below)")
    return line


def _matrix(a) -> list[list[float]]:
    import numpy as np  # the CLI's modules import nothing heavy at the top: `pamsim --help` stays fast

    return [[float(v) for v in row] for row in np.atleast_2d(a)]


def _complex(z: complex) -> list[float]:
    return [float(z.real), float(z.imag)]


def _number(value: float) -> float | None:
    """JSON has no NaN or infinity: a mode without a finite figure is reported as null."""
    return float(value) if math.isfinite(value) else None


def report(lin) -> dict:
    """The JSON-safe figures of a :class:`~pamsim.control.linear.LinearModel`."""
    sys = lin.sys
    mode = lin.mechanical_mode()
    dc, integ = {}, {}
    for inp in sys.input_labels:
        for out in sys.output_labels:
            g0, k_int = lin.gain_at_zero(inp, out)
            dc[f"{inp}->{out}"] = g0  # None: infinite (a free integrator in the channel)
            if g0 is None:
                integ[f"{inp}->{out}"] = k_int
    omega = lin.frequency_grid_rad_s(60)
    return {
        "A": _matrix(sys.A), "B": _matrix(sys.B), "C": _matrix(sys.C), "D": _matrix(sys.D),
        "states": list(sys.state_labels), "inputs": list(sys.input_labels), "outputs": list(sys.output_labels),
        "poles": [_complex(z) for z in sys.poles()],
        "natural_frequency_Hz": _number(mode.natural_frequency_Hz),
        "damping_ratio": _number(mode.damping_ratio),
        "mechanical_poles": [_complex(z) for z in mode.poles],
        "dc_gain": dc,
        "integrator_gain_per_s": integ,
        "bode_valve_to_contraction": lin.bode(sys.input_labels[0], "contraction_m", omega),
        "operating_point": lin.op.as_dict(),
        "residual_f_x0_u0": [float(v) for v in lin.residual],
        "friction": (HYSTERESIS_FRICTION if lin.hysteresis else lin.friction.describe()),
        "valve_slope": lin.valve_slope,
        "jacobians": lin.jacobian_method,
        "dropped_states": list(lin.dropped_states),
        **({"hysteresis": lin.hysteresis.as_dict()} if lin.hysteresis else {}),
    }


def run(args: argparse.Namespace) -> int:
    """``pamsim linearize``: linearise the scenario at the operating point the options choose and print the
    figures (as JSON with ``--json``) and write the Bode and pole-zero plots (not with ``--json`` alone,
    without ``-o``); exit code 0.
    """
    from .run import is_joint, load_any_scenario

    args.figures = figure_args.options(args)
    scenario = load_any_scenario(Path(args.scenario))
    if is_joint(scenario):
        return _linearize_joint(scenario, args)
    if "motion" in scenario.spec:
        raise InputError(f"{args.scenario}: [motion]: a muscle driven by its length has no load whose dynamics "
                         "to linearise")
    if args.json and args.output is None:  # the numbers only: no file written, nothing on stderr
        print(json.dumps(_linearize(scenario, args)[1], indent=2))
        return 0
    with output_folder(args.output or DEFAULT_OUTPUT) as out:  # removed again if the operating point turns out bad
        lin, rep, names = _linearize_and_plot(scenario, args, out)
    wrote = f"wrote {', '.join(str(out / n) for n in names)}"
    if args.json:
        print(json.dumps(rep, indent=2))
        print(wrote, file=sys.stderr)  # stdout stays pure JSON
        return 0
    _print_text(lin, rep)
    print(wrote)
    return 0


def _linearize_joint(scenario, args: argparse.Namespace) -> int:
    """Muscles on a joint: the MIMO model about the equilibrium at the muscles' prescribed pressures at the
    end of the run (:func:`pamsim.joints.linear.linearize_joint`); printed, or as JSON with ``--json``."""
    import numpy as np

    from ..errors import InputError
    from ..joints.linear import linearize_joint

    given = {"--at-time": args.at_time, "--contraction-mm": args.contraction_mm, "-o": args.output,
             "--friction": None if args.friction == "dropped" else args.friction,
             "--valve-slope": None if args.valve_slope == "mean" else args.valve_slope}
    if scenario.controller is not None:
        raise InputError(f"{scenario.origin}: [controller]: its muscles' prescribed pressures are placeholders for "
                         "the controller's; linearise the joint without it (pamsim.joints.linear.linearize_joint at "
                         "the pressures you choose)")
    for flag, value in given.items():
        if value is not None:
            raise InputError(f"{flag}: a joint is linearised about its equilibrium at the muscles' final "
                             "pressures; this option is for one muscle")
    pressures = [float(np.asarray(m.source.inputs(scenario.duration_s)[0])) if hasattr(m.source, "p_gauge_Pa") else 0.0
                 for m in scenario.joint_muscles()]
    lm = linearize_joint(scenario, pressures)
    rep = {"A": _matrix(lm.A), "B": _matrix(lm.B), "C": _matrix(lm.C), "D": _matrix(lm.D), "states": list(lm.states),
           "inputs": list(lm.inputs), "outputs": list(lm.outputs), "poles": [_complex(z) for z in lm.poles()],
           "theta0_rad": lm.theta0_rad, "p0_gauge_Pa": list(lm.p0_gauge_Pa), "k0_Nm_per_rad": lm.k0_Nm_per_rad,
           "friction": _joint_friction_line([m.name for m in scenario.joint_muscles()],
                                            [name for name, _ in lm.hysteresis])}
    if lm.hysteresis:
        rep["hysteresis"] = {name: loop.as_dict() for name, loop in lm.hysteresis}
    if args.json:
        print(json.dumps(rep, indent=2))
        return 0
    np.set_printoptions(precision=6, linewidth=140)
    print(f"operating point: the joint at rest at {lm.theta0_rad:.6g} rad, muscles at "
          + ", ".join(f"{p / 1e5:g} bar" for p in lm.p0_gauge_Pa) + f"; stiffness {lm.k0_Nm_per_rad:.6g} N m/rad")
    print(f"friction: {rep['friction']}")
    for name, loop in lm.hysteresis:
        print(f"{name}: " + "\n".join(loop.lines()))
    for key in ("states", "inputs", "outputs"):
        print(f"{key + ':':8} {', '.join(rep[key])}")
    for key in ("A", "B", "C", "D"):
        print(f"{key} =\n{np.array(rep[key])}")
    print("poles [1/s]: " + ", ".join(f"{re:.6g}{im:+.6g}j" for re, im in rep["poles"]))
    return 0


def _linearize(scenario, args: argparse.Namespace):
    """Linearise at the operating point the arguments choose: (model, report).  A scenario whose valve is
    driven by PWM is linearised through its averaged valve, its input the duty; two 2/2 valves under boolean
    commands through the same model without the PWM, its input the inlet's opening
    (:func:`_boolean_pair_as_openings`)."""
    from ..control.exact import rest_pull
    from ..control.linear import linearize
    from ..control.system import FrictionTreatment
    from ..errors import InputError

    pwm = scenario.pwm_model is not None
    boolean_pair = "inlet" in scenario.spec["pressure"] and not pwm
    # The run an --at-time operating point is taken from: a PWM's averaged run, a boolean pair's own switching
    trajectory = scenario
    if boolean_pair:
        if args.valve_slope != "mean":
            raise InputError(f"--valve-slope {args.valve_slope}: two 2/2 valves are linearised in the inlet's "
                             "opening, which has no command kink to choose a slope at")
        scenario = _boolean_pair_as_openings(scenario, args.at_time or scenario.duration_s)
        pwm = True
    elif pwm:
        if args.valve_slope != "mean":
            raise InputError(f"--valve-slope {args.valve_slope}: a PWM valve is linearised through its averaged "
                             "model, whose input is the duty; it has no command kink to choose a slope at")
        scenario = trajectory = scenario.with_pwm_averaged()
    model = _at_inlet_duty(scenario, scenario.build_model())
    added = scenario.added_components
    if "hysteresis" in scenario.spec and args.friction != "dropped":
        raise InputError(f"--friction {args.friction}: the scenario's [hysteresis] elements take the Coulomb "
                         "friction's place; they are linearised in their stick state at the operating point")
    op = _operating_point(trajectory, model, rest_pull(model, added), args, pwm)
    friction = FrictionTreatment(args.friction, args.friction_velocity_mm_s * 1e-3)
    lin = linearize(model, op, friction, args.valve_slope, added=added)
    rep = report(lin)
    exhaust = getattr(model.source.valve, "exhaust_share", None)
    valves = ("the on/off valve" if "inlet" not in scenario.spec["pressure"]
              else "the inlet and exhaust 2/2 valves (the exhaust complementary)" if exhaust is None
              else f"the inlet and exhaust 2/2 valves (the exhaust open {exhaust:.4g} of the time, by its own command)")
    if boolean_pair:
        rep["valve_model"] = (f"{valves} under boolean commands, each valve's flow its opening times its orifice's "
                              "(the inlet's opening the input pwm_duty [1], the exhaust's "
                              + ("1 - pwm_duty" if exhaust is None else "held") + "); pamsim run runs their switching")
    else:
        rep["valve_model"] = (f"the averaged model of {valves} under {model.source.valve.frequency_Hz:g} Hz PWM "
                              "(the mean of its supply and exhaust paths' flows over a period), input pwm_duty [1]; "
                              "pamsim run runs its switching" if pwm
                              else f"proportional 3/3 valve, slope at command 0: {lin.valve_slope}")
    return lin, rep


def _boolean_pair_as_openings(scenario, time_s: float):
    """``scenario``'s two 2/2 valves under boolean commands as the pair whose inlet opens by its input, the
    model of the averaged PWM pair without its PWM: the inlet's command a duty equal to its opening at
    ``time_s`` from the run's start to its end, with no delays or switching times (the mean opening is then
    the duty, :meth:`pamsim.elements.pwm_average.PwmShare.share`); an exhaust with a command of its own held
    at its opening then, a complementary one still complementary (``1 - duty``)."""
    # An --at-time outside the run is refused where its state is taken (trajectory_point)
    inlet_opening, exhaust_opening, _ = (float(u) for u in scenario.build_model().source.inputs(float(time_s)))
    pressure = scenario.spec["pressure"]
    untimed = {k: 0.0 for k in ("delay_on_s", "delay_off_s", "rise_s", "fall_s")}
    inlet = {**pressure["inlet"], **untimed, "command": {
        "kind": "pwm", "start_s": 0.0, "end_s": scenario.duration_s, "frequency_Hz": 50.0,
        "duty": inlet_opening, "model": "averaged"}}
    exhaust = dict(pressure["exhaust"])
    if exhaust["command"].get("kind") == "complementary":
        exhaust.update(untimed)
    else:
        exhaust["command"] = {"kind": "constant", "value": exhaust_opening}
    return scenario.with_changes({"pressure": {"inlet": inlet, "exhaust": exhaust}})


def _at_inlet_duty(scenario, model):
    """``model``, or for two 2/2 valves whose exhaust has a command of its own, the pair averaged at the inlet's
    duty with the exhaust at its share (:meth:`pamsim.elements.valve_pair.ValvePairSource.at_inlet_duty`)."""
    import dataclasses

    from ..elements.valve_pair import ValvePairSource
    from ..errors import InputError

    if not isinstance(model.source, ValvePairSource):
        return model
    try:
        return dataclasses.replace(model, source=model.source.at_inlet_duty())
    except ValueError as exc:
        kind = scenario.spec["pressure"]["exhaust"]["command"].get("kind")
        raise InputError(f"{scenario.origin}: pressure.exhaust.command.kind = {kind!r}: pamsim linearize takes the "
                         f"pair averaged at the inlet's duty, the exhaust at a fixed share: {exc}") from None


def _operating_point(scenario, model, pull, args: argparse.Namespace, pwm: bool):
    """The operating point the arguments choose, the averaged PWM valve's for a model that has one (``pwm``)."""
    from ..control.operating_point import (averaged_pwm_equilibrium, averaged_pwm_held, held_equilibrium,
                                           open_valve_equilibrium, trajectory_point)

    supply = scenario.final_pressure_gauge_Pa
    if args.at_time is not None:
        return trajectory_point(scenario, args.at_time)
    if args.contraction_mm is not None:
        x_m = args.contraction_mm * 1e-3
        return averaged_pwm_held(model, x_m, pull=pull) if pwm else held_equilibrium(model, x_m, supply, pull=pull)
    if pwm:
        return averaged_pwm_equilibrium(model, model.source.duty, pull=pull)
    return open_valve_equilibrium(model, supply, pull=pull)


def _linearize_and_plot(scenario, args: argparse.Namespace, out: Path):
    """:func:`_linearize` and write the plots; (model, report, file names)."""
    from ..control.plots import bode_figure, pole_zero_figure
    from ..figure_style import save

    lin, rep = _linearize(scenario, args)
    stem = f"{scenario.name}_linear"
    fmt, dpi = args.figures
    names = [f"{stem}_bode.{fmt}", f"{stem}_pzmap.{fmt}"]
    with atomic_outputs(out, names) as tmp:
        save(bode_figure(lin), tmp[names[0]], dpi=dpi)
        save(pole_zero_figure(lin), tmp[names[1]], dpi=dpi)
    return lin, rep, names


def _print_text(lin, rep: dict) -> None:
    import numpy as np

    np.set_printoptions(precision=6, linewidth=140)
    print(f"operating point: {lin.op.description}")
    if rep["inputs"][0] == "pwm_duty":
        print(f"friction: {rep['friction']}; Jacobians: {lin.jacobian_method}")
        print(f"valve: {rep['valve_model']}")
    else:
        print(f"friction: {rep['friction']}; valve slope at command 0: {lin.valve_slope}; "
              f"Jacobians: {lin.jacobian_method}")
    if lin.dropped_states:
        print(f"dropped (unobservable, decoupled): {', '.join(lin.dropped_states)}")
    if lin.hysteresis:
        print("\n".join(lin.hysteresis.lines()))
    print(f"states:  {', '.join(rep['states'])}")
    print(f"inputs:  {', '.join(rep['inputs'])}")
    print(f"outputs: {', '.join(rep['outputs'])}")
    for key in ("A", "B", "C", "D"):
        print(f"{key} =\n{np.array(rep[key])}")
    print("poles [1/s]: " + ", ".join(f"{re:.6g}{im:+.6g}j" for re, im in rep["poles"]))
    mode = lin.mechanical_mode()
    print(f"mechanical mode: natural frequency {mode.natural_frequency_Hz:.4g} Hz, "
          f"damping ratio {mode.damping_ratio:.4g}")
    _print_dc_gains(rep)
    if np.max(np.abs(lin.residual)) > 0 and lin.op.kind == "trajectory":
        print("note: not an equilibrium; f(x0, u0) = " + ", ".join(f"{v:.4g}" for v in lin.residual))


def _print_dc_gains(rep: dict) -> None:
    """The DC gains to the contraction, the valve's input first (per unit duty or command)."""
    first = rep["inputs"][0]
    unit = "duty" if first == "pwm_duty" else "command"
    g0 = rep["dc_gain"][f"{first}->contraction_m"]
    if g0 is None:
        k = rep["integrator_gain_per_s"][f"{first}->contraction_m"]
        print(f"DC gain {first} -> contraction: infinite (the closed valve integrates the {unit}); "
              f"integrator gain {k * 1e3:.4g} mm/s per unit {unit}")
    else:
        print(f"DC gain {first} -> contraction: {g0 * 1e3:.4g} mm per unit {unit}")
    for key, value in rep["dc_gain"].items():
        if key.endswith("contraction_m") and not key.startswith(first):
            print(f"DC gain {key}: " + ("infinite" if value is None else f"{value:.6g} m per SI unit"))
