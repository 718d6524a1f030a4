"""What an FMU built for a muscle or a scenario carries: its values as start values.

``pamsim fmu build --muscle M`` and ``--scenario S`` build an FMU that *is* that muscle, or that
scenario's run, when an importer sets nothing: every parameter the FMU has starts at the muscle's
value (geometry, rating, valve, chamber, friction, damping, stops), with the muscle file's
provenance in its description, and an FMU built from a scenario also starts with the scenario's
element choices, initial state and margins, its inputs' signals (valve command, supply or
prescribed pressure, load, external force; ``input_source = scenario``) and its duration, output
step and tolerance as the ``DefaultExperiment``.  ``fmpy.simulate_fmu(path)`` with no start values
then runs what ``pamsim run S`` runs.

A :class:`Preset` holds those values; :func:`pamsim.fmu.build` writes them into the model
description and the generated C header ``pam_variables.h`` (start values, and the signals the C
core follows).
"""

from __future__ import annotations

import bisect
import hashlib
import math
from dataclasses import dataclass, field
from typing import Mapping


from ..assemblies.one_muscle import input_signals
from ..errors import InputError
from ..scenario import Scenario
from ..signals import Constant, FirstOrderLag, OnOff, PiecewiseConstant, Pwm, Ramp, Step, Trace
from .force_table import ForceTable
from .runner import ScenarioInputs, force_table_for, start_values, upper_stop_start
from .variables import INPUT_SOURCE_CHOICES, INPUTS, VARIABLES

_PARAMETERS = {v.name for v in VARIABLES if v.causality == "parameter" and v.kind == "real"}


@dataclass(frozen=True)
class InputSignal:
    """One input's signal as the FMU's C core evaluates it (``fmu/src/pam_fmu_common.c``).

    Either knots ``(knots_t_s[k], knots[k])``, interpolated linearly (as ``numpy.interp``), held
    outside them and right-continuous at a repeated time (a step: the later value from that time
    on); or, with ``lag`` = ``(time_s, initial, final, tau_s)``, ``initial`` before ``time_s`` and
    ``final + (initial - final) exp(-(t - time_s) / tau_s)`` from then on
    (:class:`pamsim.signals.FirstOrderLag`).  Every knot time and the lag's start are breakpoints:
    the co-simulation integrator stops there and a held load is checked again, as the Python
    simulator does at an input's breakpoints; in Model Exchange they are time events.
    """

    knots_t_s: tuple[float, ...] = ()
    knots: tuple[float, ...] = ()
    lag: tuple[float, float, float, float] | None = None
    text: str = ""

    def __call__(self, t_s: float) -> float:
        """The value at ``t_s`` (from the right at a breakpoint), as the C core computes it."""
        if self.lag is not None:
            time_s, initial, final, tau_s = self.lag
            return initial if t_s < time_s else final + (initial - final) * math.exp(-(t_s - time_s) / tau_s)
        ts, vs = self.knots_t_s, self.knots
        k = bisect.bisect_right(ts, t_s) - 1  # the last knot at or before t_s (numpy's costs more on a tuple)
        if k < 0:
            return vs[0]
        if k == len(ts) - 1:
            return vs[-1]
        return (vs[k + 1] - vs[k]) / (ts[k + 1] - ts[k]) * (t_s - ts[k]) + vs[k]

    @property
    def extremes(self) -> tuple[float, float]:
        """The smallest and largest value the signal takes."""
        values = self.lag[1:3] if self.lag is not None else self.knots
        return min(values), max(values)


def input_signal(signal, unit: str) -> InputSignal:
    """``signal`` (a :mod:`pamsim.signals` signal in SI units, ``unit``) as an :class:`InputSignal`.

    Raises
    ------
    InputError
        For a signal of another kind (a Python callable), which the FMU cannot carry.
    """
    def q(x):
        return f"{x:g} {unit}" if unit else f"{x:g}"

    if isinstance(signal, Constant):
        return InputSignal((0.0,), (float(signal.value),), text=f"constant {q(signal.value)}")
    if isinstance(signal, Step):
        return InputSignal((signal.time_s,) * 2, (float(signal.initial), float(signal.final)),
                           text=f"step {q(signal.initial)} -> {q(signal.final)} at {signal.time_s:g} s")
    if isinstance(signal, Ramp):
        return InputSignal((signal.start_s, signal.end_s), (float(signal.initial), float(signal.final)),
                           text=f"ramp {q(signal.initial)} -> {q(signal.final)} over {signal.start_s:g} to "
                                f"{signal.end_s:g} s")
    if isinstance(signal, FirstOrderLag):
        return InputSignal(lag=(signal.time_s, float(signal.initial), float(signal.final), signal.tau_s),
                           text=f"step {q(signal.initial)} -> {q(signal.final)} at {signal.time_s:g} s through "
                                f"a first-order lag of {signal.tau_s:g} s")
    if isinstance(signal, Trace):
        return InputSignal(tuple(map(float, signal.t_s)), tuple(map(float, signal.values)),
                           text=f"trace of {len(signal.t_s)} points ({signal.source or 'table'})")
    if isinstance(signal, PiecewiseConstant):  # each value from its time on: a repeated knot per time
        times = signal.times_s[1:]
        return InputSignal((signal.times_s[0], *(t for t in times for _ in (0, 1))),
                           tuple(float(v) for v in signal.values[:-1] for _ in (0, 1)) + (float(signal.values[-1]),),
                           text=f"{len(signal.times_s)} steps")
    if isinstance(signal, Pwm):  # its knots, a jump as two knots at one time
        return InputSignal(signal.knots_t_s, signal.knots,
                           text=f"pwm {q(signal.low)} / {q(signal.high)} at {signal.frequency_Hz:g} Hz, duty "
                                f"{signal.duty:g}, {signal.start_s:g} to {signal.end_s:g} s")
    if isinstance(signal, OnOff):  # an on/off valve's opening: its knots too
        return InputSignal(signal.knots_t_s, signal.knots,
                           text=f"on/off valve opening, {len(signal.commands)} commanded switches")
    raise InputError(f"the FMU can carry only constant, step, ramp, lag, trace, steps and pwm signals, not {signal!r}")


@dataclass(frozen=True)
class Experiment:
    """The ``DefaultExperiment`` of an FMU built from a scenario: its run."""

    stop_time_s: float
    step_size_s: float
    tolerance: float


@dataclass(frozen=True)
class Preset:
    """The values an FMU is built with (see the module): start values with their provenance, the
    static force table, and for a scenario its inputs' signals and its run."""

    built_for: str
    starts: Mapping[str, float | int]
    sources: Mapping[str, str]
    table: ForceTable | None = None
    signals: Mapping[str, InputSignal] = field(default_factory=dict)
    experiment: Experiment | None = None
    static_force: str = "acra2012_polynomial"

    def text(self) -> str:
        """A canonical text of everything the preset puts into the FMU (hashed into its token)."""
        lines = [self.built_for, self.static_force, repr(self.experiment)]
        lines += [f"{k}={v!r} ({self.sources.get(k, '')})" for k, v in sorted(self.starts.items())]
        lines += [f"{k}: {s!r}" for k, s in sorted(self.signals.items())]
        lines.append(self.table.digest() if self.table is not None else "no table")
        return "\n".join(lines)

    def digest(self) -> str:
        """A hash of the preset's text: part of the FMU build's cache key."""
        return hashlib.sha256(self.text().encode()).hexdigest()


def _parameter_starts(scenario: Scenario) -> tuple[dict, dict]:
    """The muscle's parameters that are FMU parameters, with the provenance the muscle file (or the
    dynamics' defaults, or the scenario's overrides) gives each."""
    entries = scenario.parameters.entries
    starts = {k: float(p.value) for k, p in entries.items() if k in _PARAMETERS}
    sources = {k: entries[k].source for k in starts}
    return starts, sources


def for_muscle(scenario: Scenario) -> Preset:
    """The preset of ``pamsim fmu build --muscle M [--static-force NAME]``: ``scenario`` names the
    muscle, its parameter overrides and the static model; only those reach the FMU (its load, pressure
    and timing are the smallest a scenario needs, not the muscle's, so the inputs keep the FMU's
    defaults)."""
    starts, sources = _parameter_starts(scenario)
    model = scenario.spec["model"]
    table = force_table_for(scenario)
    starts["static_force_model"] = 1 if table is not None else 0
    sources["static_force_model"] = f"{model['static_force']} of muscle {model['muscle']}"
    built = scenario.build_model()
    starts["x_high_m"] = upper_stop_start(built)
    sources["x_high_m"] = (f"the upper stop of muscle {model['muscle']} with {model['static_force']} "
                           f"({built.stops.upper_basis})")
    return Preset(f"muscle {model['muscle']}", starts, sources, table, static_force=model["static_force"])


SIGNAL_UNITS = {"valve_command": "", "pwm_duty": "", "exhaust_command": "", "supply_pressure_gauge_Pa": "Pa", "prescribed_pressure_gauge_Pa": "Pa",
                "load_mass_kg": "kg", "external_force_N": "N", "reference_m": "m", "feedforward_gauge_Pa": "Pa",
                "reference_velocity_m_s": "m/s", "feedforward_command": ""}
"""The unit of each input a scenario can drive, as the signals' descriptions show it (the last four: a
position controller's, :mod:`pamsim.control.closed_loop`)."""


def scenario_signals(scenario: Scenario, names, model=None) -> dict[str, InputSignal]:
    """The scenario's signals of the inputs ``names`` (of :data:`SIGNAL_UNITS`), as the FMU carries them.

    ``model``: the scenario's model with its pressure source replaced (a controller's), whose assembly's
    inputs (:func:`pamsim.assemblies.one_muscle.input_signals`) take the place of the scenario's.

    Raises
    ------
    InputError
        For an input signal the FMU cannot carry, naming the input.
    """
    inputs = ScenarioInputs(scenario)
    raw = {"valve_command": Constant(0.0), "supply_pressure_gauge_Pa": Constant(0.0),
           "prescribed_pressure_gauge_Pa": Constant(0.0), "load_mass_kg": Constant(scenario.mass_kg)}
    raw.update(input_signals(inputs.model if model is None else model))
    signals = {}
    for name in names:
        try:
            signals[name] = input_signal(raw[name], SIGNAL_UNITS[name])
        except InputError as exc:
            raise InputError(f"{scenario.origin}: input {name}: {exc}") from None
    return signals


def for_scenario(scenario: Scenario) -> Preset:
    """The preset of ``pamsim fmu build --scenario S``: the muscle's parameters, the scenario's
    choices, initial state and margins, its inputs as signals and its run.

    Raises
    ------
    InputError
        For a scenario the FMU cannot represent (:func:`pamsim.fmu.runner.start_values`), or an input
        signal it cannot carry.
    """
    if "controller" in scenario.spec:
        raise InputError(f"{scenario.origin}: controller: the one-muscle FMU has no controller, so it would run "
                         "this scenario open loop; pamsim fmu build --scenario builds the FMU of its assembly, "
                         "controller included")
    where = f"scenario {scenario.name} ({scenario.origin})"
    starts, sources = _parameter_starts(scenario)
    for name, value in start_values(scenario).items():
        if name not in starts:
            starts[name] = value
            sources[name] = where
    signals = scenario_signals(scenario, INPUTS)
    for name in INPUTS:
        starts[name] = signals[name](0.0)
        sources[name] = f"{where} at t = 0 s; with input_source = scenario it follows {signals[name].text}"
    starts["input_source"] = INPUT_SOURCE_CHOICES.index("scenario")
    sources["input_source"] = where
    opts = scenario.solver
    experiment = Experiment(scenario.duration_s, 1.0 / opts.sample_rate_Hz, opts.rtol)
    return Preset(where, starts, sources, force_table_for(scenario), signals, experiment,
                  scenario.spec["model"]["static_force"])
