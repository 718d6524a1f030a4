"""A position controller designed on the linear model and run on the hybrid model.

Design (``docs/control.md``): LQR with integral action on the linearisation
at a held operating point (valve closed), states contraction, velocity and
chamber pressure plus the integral of the position error; the reference
enters through the holding pressure of the target (static feedforward).  The
velocity is estimated from the position by a first-order filter, so the
controller needs a position and a pressure sensor only.

On the nonlinear model the controller runs as part of the pressure source
(:class:`ClosedLoopValveSource`): its states (error integral, position filter)
sit beside the chamber states, and the valve command it computes is clipped to
[-1, 1].  As components (:class:`PositionController` between the chamber and the
valve, registered for the one-muscle assembly), :func:`~pamsim.simulator.simulate_model`
integrates the loop with the load's own stick/slip modes.  The controller is continuous-time (an
analogue of a controller sampled much faster than the 4 Hz mechanical mode).

Non-linear parts of the law:

* valve saturation with back-calculation anti-windup of the integral;
* a deadband on the integrated error: inside it the integral stops, which
  keeps Coulomb friction from driving a stick-slip limit cycle (the integral
  would otherwise ramp the pressure of a stuck load until it jumps past the
  target, and back).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping

import control as ct
import numpy as np

from ..assemblies.one_muscle import SourceParts, register_source, source_parts
from ..constants import PA_PER_BAR
from ..elements.pressure_source import ValveChamberSource
from ..errors import InputError
from ..table_checks import number_problem, shown
from ..model import MuscleModel
from ..modeling import Component, Equations, Symbols, Var, smath
from ..result import Result
from ..scenario import Scenario, load_scenario
from ..signals import Constant, Step, max_step_hint_s
from ..backends import simulate
from .linear import LinearModel, linearize
from .operating_point import held_equilibrium, holding_pressure_Pa
from .reduced import (full_linearisation, line_components, loop_poles, needs_reduction, reduced_model,
                      refuse_unsupported_line)
from .system import FrictionTreatment, MusclePlant

# [controller] keys: name -> (default or None if required, unit factor to SI)
_CONTROLLER_KEYS: dict[str, tuple[Any, float]] = {
    "kind": ("lqr_integral", 1.0),
    "target_contraction_mm": (None, 1e-3),
    "step_time_s": (None, 1.0),
    "design_contraction_mm": (None, 1e-3),
    "max_position_error_mm": (None, 1e-3),
    "max_velocity_mm_s": (None, 1e-3),
    "max_pressure_error_bar": (None, PA_PER_BAR),
    "max_integral_mm_s": (None, 1e-3),
    "max_command": (1.0, 1.0),
    "velocity_filter_time_s": (None, 1.0),
    "integrator_deadband_mm": (0.0, 1e-3),
    "antiwindup_time_s": (None, 1.0),
    "spec": ({}, 1.0),
}
_SPEC_KEYS = ("rise_time_max_s", "overshoot_max_percent", "settling_time_max_s", "settling_band_mm",
              "steady_state_error_max_mm")


@dataclass(frozen=True)
class ControllerConfig:
    """The ``[controller]`` table of a scenario, in SI units (see ``docs/control.md``)."""

    target_contraction_m: float
    step_time_s: float
    design_contraction_m: float
    max_position_error_m: float
    max_velocity_m_s: float
    max_pressure_error_Pa: float
    max_integral_m_s: float
    max_command: float
    velocity_filter_time_s: float
    integrator_deadband_m: float
    antiwindup_time_s: float
    spec: Mapping[str, float]

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> "ControllerConfig":
        """Read and validate ``[controller]``.

        Raises
        ------
        InputError
            Naming the file and key for a missing, unknown or non-positive entry.
        """
        where = scenario.origin
        # The design drops the muscle's friction, so Maxwell-slip or Bouc-Wen friction changes the plant, not it;
        # the volumes of a line the valve feeds are designed without and checked with (pamsim.control.reduced).
        refuse_unsupported_line(scenario)
        table = _controller_table(scenario.spec.get("controller"), where)
        # The numbers in the order of _CONTROLLER_KEYS, then the spec: the first mistake is the one reported.
        values = {_si_name(key): _controller_number(table, key, where) * factor
                  for key, (_, factor) in _CONTROLLER_KEYS.items() if key not in ("kind", "spec")}
        spec = _controller_spec(table.get("spec", {}), where)
        if not 0.0 < values["step_time_s"] < scenario.duration_s:
            raise InputError(f"{where}: controller.step_time_s = {values['step_time_s']:g}: must lie inside the "
                             f"simulation (0, {scenario.duration_s:g}) s")
        return cls(spec=spec, **values)


def _controller_table(table: Any, where: str) -> dict:
    """The ``[controller]`` table, its keys known and its kind the one implemented.

    Parameters
    ----------
    table : the scenario's ``controller`` entry (None when it has none).
    where : the scenario's origin, for the messages.

    Raises
    ------
    InputError
        No table, an unknown key (the first, in the file's order), or a kind other than ``lqr_integral``.
    """
    if not isinstance(table, dict):
        raise InputError(f"{where}: missing table [controller] (see docs/control.md)")
    for key in table:
        if key not in _CONTROLLER_KEYS:
            raise InputError(f"{where}: unknown key controller.{key} (known: {', '.join(_CONTROLLER_KEYS)})")
    if table.get("kind", "lqr_integral") != "lqr_integral":
        raise InputError(f"{where}: controller.kind = {table['kind']!r}: only 'lqr_integral' is implemented")
    return table


def _controller_number(table: Mapping[str, Any], key: str, where: str) -> float:
    """``controller.KEY`` in the file's unit (its default when it has one and is not given).

    Raises
    ------
    InputError
        A required key missing, a value that is not a finite number, or one that is not positive
        (``integrator_deadband_mm`` may be 0: no deadband).
    """
    default = _CONTROLLER_KEYS[key][0]
    if key not in table and default is None:
        raise InputError(f"{where}: missing key controller.{key}")
    raw = table.get(key, default)
    why = number_problem(raw)
    if why:
        raise InputError(f"{where}: controller.{key} = {shown(raw)}: {why}")
    if raw < 0 or (raw == 0 and key != "integrator_deadband_mm"):
        raise InputError(f"{where}: controller.{key} = {raw!r}: must be positive")
    return float(raw)


def _si_name(key: str) -> str:
    """The :class:`ControllerConfig` field of a ``[controller]`` key: its unit suffix in SI."""
    return key.replace("_mm_s", "_m_s").replace("_mm", "_m").replace("_bar", "_Pa")


def _controller_spec(spec: Any, where: str) -> dict[str, float]:
    """``[controller.spec]``: the step response's requirements, each a positive number.

    Raises
    ------
    InputError
        Not a table, a key outside :data:`_SPEC_KEYS`, or a value that is not a positive number.
    """
    if not isinstance(spec, dict) or any(k not in _SPEC_KEYS for k in spec):
        raise InputError(f"{where}: controller.spec must be a table with keys from {', '.join(_SPEC_KEYS)}")
    for key, raw in spec.items():
        why = number_problem(raw) or (None if raw > 0 else "must be positive")
        if why:
            raise InputError(f"{where}: controller.spec.{key} = {shown(raw)}: {why}")
    return {k: float(v) for k, v in spec.items()}


@dataclass(frozen=True)
class LqrDesign:
    """Gains ``K = [K_x, K_v, K_p, K_z]`` of ``u = -K [x - r, v, p - p_ff(r), z]`` with ``z' = x - r``.

    ``linear`` is the plant linearisation it was designed on, ``closed_loop_poles``
    the poles of the linear loop with the state feedback (ideal velocity).  For a valve with a spool or a
    line (:mod:`pamsim.control.reduced`), ``linear`` is the reduced model's, ``full_linear`` the full
    linearisation and ``full_loop_poles`` the poles of the controller (velocity filter included) around it.
    """

    K: np.ndarray
    linear: LinearModel
    closed_loop_poles: np.ndarray
    model: MuscleModel
    full_linear: LinearModel | None = None
    full_loop_poles: np.ndarray | None = None


def design_lqr(model: MuscleModel, config: ControllerConfig, supply_gauge_Pa: float, added: tuple = ()) -> LqrDesign:
    """LQR with integral action on the held-pressure linearisation at the design contraction.

    Bryson's rule sets the weights: each state and the command are divided by
    their largest acceptable value.  Coulomb friction is dropped from the
    design model (no linearisation at rest); the valve slope at command 0 is
    the mean of filling and venting.  A spool valve or a line the valve feeds (``added``) is designed on
    the reduced model and checked on the full one (:mod:`pamsim.control.reduced`).

    Raises
    ------
    InputError
        If the controller designed on the reduced model does not stabilise the full linearisation.
    """
    op = held_equilibrium(model, config.design_contraction_m, supply_gauge_Pa)
    reduced = needs_reduction(model, added)
    lin = linearize(reduced_model(model) if reduced else model, op, FrictionTreatment("dropped"), "mean")
    plant = lin.sys[["contraction_m", "p_gauge_Pa"], "valve_command"]
    labels = list(lin.sys.state_labels)
    if labels != ["x_m", "v_m_s", "p_abs_Pa"]:
        raise InputError(f"the design model has states {labels}; expected x_m, v_m_s, p_abs_Pa")
    A, B = plant.A, plant.B
    # Augment with z' = x - r (r = 0 in deviation variables).
    A_aug = np.block([[A, np.zeros((3, 1))], [np.array([[1.0, 0.0, 0.0, 0.0]])]])
    B_aug = np.vstack([B, [[0.0]]])
    Q = np.diag([config.max_position_error_m ** -2, config.max_velocity_m_s ** -2,
                 config.max_pressure_error_Pa ** -2, config.max_integral_m_s ** -2])
    R = np.array([[config.max_command ** -2]])
    K, _, poles = ct.lqr(A_aug, B_aug, Q, R)
    design = LqrDesign(np.asarray(K, dtype=float).ravel(), lin, np.asarray(poles), model)
    return _checked_on_full(design, config, op, added) if reduced else design


def _checked_on_full(design: LqrDesign, config: ControllerConfig, op, added: tuple) -> LqrDesign:
    """``design`` with the full linearisation of its model at ``op`` and the poles of its loop around it."""
    full = full_linearisation(design.model, op, added)
    poles = loop_poles(full, controller_system(design, config))
    if np.max(poles.real) >= 0.0:
        worst = poles[np.argmax(poles.real)]
        raise InputError(f"the controller designed on the reduced model (spool instant, no line, the gas adiabatic) "
                         f"does not stabilise the full linearisation: pole {worst:.4g} 1/s (a spool or a line slower "
                         "than the loop: raise pressure.spool.natural_frequency_Hz or slow the loop down)")
    return dataclasses.replace(design, full_linear=full, full_loop_poles=poles)


@dataclass(frozen=True)
class ClosedLoopValveSource:
    """A :class:`ValveChamberSource` whose command comes from the position controller.

    States: chamber pressure [Pa], air mass [kg], error integral ``z`` [m s]
    and the position filter ``x_f`` [m] of the velocity estimate
    ``(x - x_f) / tau``.  Inputs at time t: reference [m], feedforward
    holding pressure [Pa gauge], supply pressure [Pa gauge], the reference's
    velocity [m/s] (0 for a step: its impulse is left out, as the design's
    step response assumes) and the valve command that keeps the chamber on the
    feedforward pressure (0 for a step).
    """

    plant: ValveChamberSource
    K: tuple[float, float, float, float]
    reference_m: Any
    feedforward_gauge_Pa: Any
    velocity_filter_time_s: float
    deadband_m: float
    antiwindup_time_s: float
    reference_velocity_m_s: Any = Constant(0.0)
    feedforward_command: Any = Constant(0.0)
    name: str = "closed_loop_valve"
    state_names: tuple[str, ...] = ("p_abs_Pa", "air_mass_kg", "z_error_integral_m_s", "x_filter_m")

    @property
    def p_atm_Pa(self) -> float:
        """Ambient pressure [Pa] of the plant."""
        return self.plant.p_atm_Pa

    def initial_state(self, x_m: float, p_gauge_Pa: float | None = None) -> list[float]:
        """At rest at ``x_m`` with the chamber at the feedforward (holding) pressure of the initial reference."""
        p = self.feedforward_gauge_Pa(0.0) if p_gauge_Pa is None else p_gauge_Pa
        plant = self.plant.initial_state(x_m, p)
        return plant[:2] + [0.0, x_m] + plant[2:]  # a spool's states after the controller's, as the parts have them

    def inputs(self, t_s) -> tuple:
        """``(reference [m], feedforward gauge pressure [Pa], supply gauge pressure [Pa], reference velocity
        [m/s], feedforward command [1])`` at ``t_s`` [s]."""
        return (self.reference_m(t_s), self.feedforward_gauge_Pa(t_s), self.plant.supply_gauge_Pa(t_s),
                self.reference_velocity_m_s(t_s), self.feedforward_command(t_s))

    @property
    def signals(self) -> tuple:
        """The signals of :meth:`inputs`, in its order: reference [m], feedforward and supply gauge pressures [Pa],
        reference velocity [m/s], feedforward command [1]."""
        return (self.reference_m, self.feedforward_gauge_Pa, self.plant.supply_gauge_Pa, self.reference_velocity_m_s,
                self.feedforward_command)

    def pressure_gauge_Pa(self, s, inputs):
        """Gauge pressure [Pa] of the chamber: its absolute pressure state less the ambient pressure."""
        return s[0] - self.p_atm_Pa

    def pressure_trace_Pa(self, t_s, S):
        """Gauge pressure [Pa] along a trace, as the plant's."""
        return self.plant.pressure_trace_Pa(t_s, S)

    def command(self, s, x_m, inputs):
        """(clipped, unclipped) valve command for source states ``s`` at contraction ``x_m``."""
        r, p_ff, _, v_ref, u_ff = inputs
        Kx, Kv, Kp, Kz = self.K
        v_hat = (x_m - s[3]) / self.velocity_filter_time_s
        raw = u_ff - (Kx * (x_m - r) + Kv * (v_hat - v_ref) + Kp * (s[0] - self.p_atm_Pa - p_ff) + Kz * s[2])
        return smath.clip(raw, -1.0, 1.0), raw

    def controller_rates(self, s, x_m, inputs, u, raw) -> tuple:
        """(d error integral / dt [m], d position filter / dt [m/s]) for the command ``u`` (clipped) and
        ``raw`` (unclipped)."""
        e = x_m - inputs[0]
        dead = e - smath.clip(e, -self.deadband_m, self.deadband_m)  # zero inside the deadband
        # Back-calculation: while the valve saturates, bleed the integral so that the
        # unclipped command returns to the limit within antiwindup_time_s.
        dz = dead + (raw - u) / (self.K[3] * self.antiwindup_time_s)
        return dz, (x_m - s[3]) / self.velocity_filter_time_s

    def derivatives(self, s, x_m, v_m_s, inputs) -> tuple[float, ...]:
        """Rates of pressure, air mass, error integral and position filter, with the valve at the controller's
        (clipped) command.
        """
        u, raw = self.command(s, x_m, inputs)
        plant = self.plant.derivatives(_plant_states(s), x_m, v_m_s, (float(u), inputs[2]))
        return tuple(plant[:2]) + self.controller_rates(s, x_m, inputs, u, raw) + tuple(plant[2:])

    @property
    def max_input_step_s(self) -> float:
        """Longest step over which every input is monotonic: a held load's solver must not step over a rise
        and fall of the reference (a sampled reference's spacing), or it misses the release."""
        return min(self.plant.max_input_step_s, max_step_hint_s(*self.signals))

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where the reference or the supply pressure jumps."""
        return self.reference_m.breakpoints + tuple(getattr(self.plant.supply_gauge_Pa, "breakpoints", ()))

    def outputs(self, t_s, S, x_m) -> dict[str, np.ndarray]:
        """Extra trace columns: air mass, valve flow and command, supply pressure, gas temperature, reference,
        feedforward, error integral and velocity estimate.
        """
        inputs = self.inputs(t_s)
        u, _ = self.command(S, x_m, inputs)
        mdot, T_gas = self.plant.inflow_kg_s(_plant_states(S), self.plant.chamber.volume_m3(x_m), (u, inputs[2]))
        zero = 0.0 * np.asarray(t_s, dtype=float)
        spool = dict(zip(self.plant.state_names[2:], S[4:]))
        return {**spool, "air_mass_kg": S[1], "valve_mass_flow_kg_s": np.asarray(mdot, dtype=float) + zero,
                "valve_command": np.asarray(u, dtype=float) + zero, "supply_gauge_Pa": inputs[2] + zero,
                "gas_temperature_K": T_gas, "reference_m": np.asarray(inputs[0], dtype=float) + zero,
                "feedforward_gauge_Pa": np.asarray(inputs[1], dtype=float) + zero,
                "z_error_integral_m_s": S[2], "velocity_estimate_m_s": (x_m - S[3]) / self.velocity_filter_time_s}


def _plant_states(s) -> list:
    """The plant's states among a :class:`ClosedLoopValveSource`'s: the chamber's two, then a spool's (after the
    controller's two)."""
    return [s[0], s[1], *s[4:]]


class PositionController(Component):
    """The controller of :class:`ClosedLoopValveSource` as a component: it reads the contraction and
    the chamber pressure, the reference and the feedforward, and drives the valve's command.

    States: the error integral and the position filter of the velocity estimate.  The law is the
    source's own (:meth:`ClosedLoopValveSource.command`, :meth:`ClosedLoopValveSource.controller_rates`),
    called with symbols.
    """

    parameters = (Var("Kx_per_m", "1/m", "gain on the position"), Var("Kv_s_per_m", "s/m", "gain on the velocity"),
                  Var("Kp_per_Pa", "1/Pa", "gain on the pressure"), Var("Kz_per_m_s", "1/(m s)", "gain on the integral"),
                  Var("velocity_filter_time_s", "s", "time constant of the velocity estimate"),
                  Var("deadband_m", "m", "error band in which the integral stops"),
                  Var("antiwindup_time_s", "s", "back-calculation time of the integral"),
                  Var("p_atm_Pa", "Pa", "ambient pressure"))
    inputs = (Var("x_m", "m", "contraction"), Var("p_abs_Pa", "Pa", "absolute chamber pressure"),
              Var("reference_m", "m", "contraction reference"),
              Var("feedforward_gauge_Pa", "Pa", "holding pressure of the reference"),
              Var("reference_velocity_m_s", "m/s", "velocity of the reference (0 for a step)"),
              Var("feedforward_command", "1", "valve command that keeps the chamber on the feedforward pressure"))
    states = (Var("z_error_integral_m_s", "m s", "integral of the position error", 0.1),
              Var("x_filter_m", "m", "position filter of the velocity estimate", 1e-2))
    outputs = (Var("command", "1", "valve command, clipped to [-1, 1]"),)

    def __init__(self, name: str, source: "ClosedLoopValveSource"):
        self.source = source
        Kx, Kv, Kp, Kz = source.K
        super().__init__(name, {"Kx_per_m": Kx, "Kv_s_per_m": Kv, "Kp_per_Pa": Kp, "Kz_per_m_s": Kz,
                                "velocity_filter_time_s": source.velocity_filter_time_s,
                                "deadband_m": source.deadband_m, "antiwindup_time_s": source.antiwindup_time_s,
                                "p_atm_Pa": source.p_atm_Pa})

    def equations(self, s: Symbols) -> Equations:
        """The source's control law on symbols: the command, and the rates of the error integral and the
        position filter.
        """
        P = s.p
        law = dataclasses.replace(self.source, K=(P["Kx_per_m"], P["Kv_s_per_m"], P["Kp_per_Pa"], P["Kz_per_m_s"]),
                                  velocity_filter_time_s=P["velocity_filter_time_s"], deadband_m=P["deadband_m"],
                                  antiwindup_time_s=P["antiwindup_time_s"],
                                  plant=dataclasses.replace(self.source.plant, p_atm_Pa=P["p_atm_Pa"]))
        x = s.u["x_m"]
        states = (s.u["p_abs_Pa"], 0.0, s.x["z_error_integral_m_s"], s.x["x_filter_m"])
        inputs = (s.u["reference_m"], s.u["feedforward_gauge_Pa"], 0.0, s.u["reference_velocity_m_s"],
                  s.u["feedforward_command"])
        u, raw = law.command(states, x, inputs)
        dz, dxf = law.controller_rates(states, x, inputs, u, raw)
        return Equations(der={"z_error_integral_m_s": dz, "x_filter_m": dxf}, outputs={"command": u},
                         initial={"z_error_integral_m_s": 0.0, "x_filter_m": x})


def _closed_loop_parts(source: "ClosedLoopValveSource", p0_gauge_Pa: float | None) -> SourceParts:
    """The closed loop's pressure source as components: the chamber (starting at ``p0_gauge_Pa``, or
    the feedforward pressure of the first reference), the controller, and the valve it drives."""
    p0 = source.feedforward_gauge_Pa(0.0) if p0_gauge_Pa is None else p0_gauge_Pa
    # The plant's own chamber and valve (a spool valve, one that discharges into a line), wired as without the
    # controller, which takes the valve's command input.
    plant = source_parts(source.plant, p0)
    chamber, valve = plant.parts
    wiring = [*plant.wiring, ("load.x_m", "controller.x_m"), ("chamber.p_abs_Pa", "controller.p_abs_Pa"),
              ("controller.command", "valve.command")]
    inputs = {"reference_m": "controller.reference_m", "feedforward_gauge_Pa": "controller.feedforward_gauge_Pa",
              "supply_pressure_gauge_Pa": plant.inputs["supply_pressure_gauge_Pa"],
              "reference_velocity_m_s": "controller.reference_velocity_m_s",
              "feedforward_command": "controller.feedforward_command"}
    return SourceParts([chamber, PositionController("controller", source), valve], wiring, inputs, "chamber")


register_source(ClosedLoopValveSource, _closed_loop_parts)


def closed_loop_model(scenario: Scenario, config: ControllerConfig, design: LqrDesign) -> MuscleModel:
    """The scenario's model with its valve driven by the controller."""
    model = scenario.build_model()
    MusclePlant(model)  # a valve source is required
    supply = scenario.final_pressure_gauge_Pa
    x0 = scenario.initial_contraction_m
    W = model.load.weight_N
    p0 = holding_pressure_Pa(model, x0, W, supply) if x0 > 0 else 0.0
    target = held_equilibrium(model, config.target_contraction_m, supply)  # also validates the target
    p1 = float(target.states[2]) - model.source.p_atm_Pa
    source = ClosedLoopValveSource(model.source, tuple(float(k) for k in design.K),
                                   Step(config.step_time_s, x0, config.target_contraction_m),
                                   Step(config.step_time_s, p0, p1), config.velocity_filter_time_s,
                                   config.integrator_deadband_m, config.antiwindup_time_s,
                                   state_names=(*model.source.state_names[:2], "z_error_integral_m_s", "x_filter_m",
                                                *model.source.state_names[2:]))
    return dataclasses.replace(model, source=source)


def step_metrics(t_s: np.ndarray, x_m: np.ndarray, step_time_s: float, x0_m: float, x1_m: float,
                 settling_band_m: float, tail_s: float = 0.3) -> dict[str, float]:
    """Rise time (10-90 %), overshoot [% of the step], settling time into ``settling_band_m``,
    steady-state error (mean over the last ``tail_s``) and the peak-to-peak motion in that tail.

    Times are measured from the step.  A response that never rises or
    settles gets ``inf``.
    """
    after = t_s >= step_time_s
    t, x = t_s[after] - step_time_s, x_m[after]
    dx = x1_m - x0_m
    frac = (x - x0_m) / dx
    t10 = t[np.argmax(frac >= 0.1)] if np.any(frac >= 0.1) else math.inf
    t90 = t[np.argmax(frac >= 0.9)] if np.any(frac >= 0.9) else math.inf
    outside = np.flatnonzero(np.abs(x - x1_m) > settling_band_m)
    if outside.size == 0:
        settle = 0.0
    elif outside[-1] == len(t) - 1:
        settle = math.inf
    else:
        settle = float(t[outside[-1] + 1])
    tail = t >= t[-1] - tail_s
    return {"rise_time_s": float(t90 - t10), "overshoot_percent": float(max(0.0, np.max(frac) - 1.0) * 100.0),
            "settling_time_s": settle, "steady_state_error_mm": float(abs(np.mean(x[tail]) - x1_m) * 1e3),
            "tail_peak_to_peak_mm": float(np.ptp(x[tail]) * 1e3)}


def controller_system(design: LqrDesign, config: ControllerConfig) -> ct.StateSpace:
    """The linear controller, velocity filter included, as a python-control system.

    Inputs ``contraction_m``, ``p_gauge_Pa`` (deviations from the design point) and
    the reference ``r_m``; output ``valve_command``; no saturation or deadband.
    """
    Kx, Kv, Kp, Kz = design.K
    tau = config.velocity_filter_time_s
    # Holding-pressure slope dp_ff/dr at the design point, for the reference feedforward.
    h = 1e-5
    lin = design.linear
    supply = float(lin.op.inputs[1])
    model = design.model
    load = model.load.weight_N - float(lin.op.inputs[2])
    g_ff = (holding_pressure_Pa(model, config.design_contraction_m + h, load, supply)
            - holding_pressure_Pa(model, config.design_contraction_m - h, load, supply)) / (2 * h)
    # Controller states z (error integral), x_f (filter); inputs contraction, pressure, reference.
    return ct.ss([[0.0, 0.0], [0.0, -1.0 / tau]],
                 [[1.0, 0.0, -1.0], [1.0 / tau, 0.0, 0.0]],
                 [[-Kz, Kv / tau]],
                 [[-(Kx + Kv / tau), -Kp, Kx + Kp * g_ff]],
                 states=["z_error_integral_m_s", "x_filter_m"], inputs=["contraction_m", "p_gauge_Pa", "r_m"],
                 outputs=["valve_command"], name="lqr")


def linear_step_prediction(design: LqrDesign, config: ControllerConfig, x0_m: float,
                           duration_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Contraction [m] of the linear loop (no saturation, deadband or friction) for the same step.

    The controller, with its velocity filter, is built as a python-control
    system and closed around the plant linearisation by signal name.
    """
    model_plant = (design.full_linear or design.linear).sys[["contraction_m", "p_gauge_Pa"], :]
    ctrl = controller_system(design, config)
    loop = ct.interconnect([model_plant, ctrl], inplist=["r_m", "supply_gauge_Pa", "F_ext_N"],
                           outlist=["contraction_m", "valve_command"], inputs=["r_m", "supply_gauge_Pa", "F_ext_N"],
                           outputs=["contraction_m", "valve_command"], name="linear_loop")
    t = np.linspace(0.0, duration_s, 2001)
    resp = ct.forced_response(loop[:, "r_m"], t, np.full_like(t, config.target_contraction_m - x0_m))
    return t, x0_m + resp.outputs[0]


@dataclass
class ClosedLoopRun:
    """A closed-loop run: the hybrid result, the design, the metrics and the spec check."""

    result: Result
    design: LqrDesign
    config: ControllerConfig
    metrics: dict[str, float]
    linear_t_s: np.ndarray
    linear_x_m: np.ndarray
    linear_metrics: dict[str, float]

    def failures(self) -> list[str]:
        """The spec items this run misses (empty when it meets its specification)."""
        m, s = self.metrics, self.config.spec
        checks = (("rise_time_max_s", m["rise_time_s"], "rise time {:.3f} s > {:.3f} s"),
                  ("overshoot_max_percent", m["overshoot_percent"], "overshoot {:.2f} % > {:.2f} %"),
                  ("settling_time_max_s", m["settling_time_s"], "settling time {:.3f} s > {:.3f} s"),
                  ("steady_state_error_max_mm", m["steady_state_error_mm"], "steady-state error {:.3f} mm > {:.3f} mm"))
        return [msg.format(value, s[key]) for key, value, msg in checks if key in s and not value <= s[key]]

    def summary(self) -> dict:
        """The run as JSON-ready figures: gains, design poles (and the loop's around the full linearisation, for a
        reduced design), metrics of the run and of the linear prediction, the specification and what the run
        misses, events and wall time.
        """
        return {"scenario": self.result.name, "gains_K": [float(k) for k in self.design.K],
                "gain_order": ["x_m", "v_m_s", "p_gauge_Pa", "z_error_integral_m_s"],
                "design_poles": [[float(p.real), float(p.imag)] for p in self.design.closed_loop_poles],
                **({} if self.design.full_loop_poles is None else {"full_loop_poles": [
                    [float(p.real), float(p.imag)] for p in np.sort_complex(self.design.full_loop_poles)]}),
                "metrics": self.metrics, "linear_prediction_metrics": self.linear_metrics,
                "spec": dict(self.config.spec), "meets_spec": not self.failures(), "failures": self.failures(),
                "events": int(self.result.stats["events"]), "wall_time_s": float(self.result.wall_time_s)}


@dataclass(frozen=True)
class ClosedLoopDesign:
    """A scenario's controller: its ``[controller]`` table, the LQR design, and the scenario's model
    with its valve driven by the controller (:func:`closed_loop_model`)."""

    scenario: Scenario
    config: ControllerConfig
    design: LqrDesign
    model: MuscleModel


def design_closed_loop(scenario: Scenario | str, overrides: Mapping[str, Any] | None = None) -> ClosedLoopDesign:
    """Read the ``[controller]`` table of ``scenario`` (with ``overrides``), design the controller and
    put it in the scenario's model.

    Parameters
    ----------
    scenario : Scenario or path
        A scenario with a valve source and a ``[controller]`` table.
    overrides : mapping, optional
        Replacement ``[controller]`` keys.

    Raises
    ------
    InputError
        For a bad ``[controller]`` table, a source other than a valve or an unreachable target.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if overrides:
        spec = dict(scenario.spec)
        spec["controller"] = {**spec.get("controller", {}), **overrides}
        scenario = Scenario.from_dict(spec, scenario.name, scenario.base_dir, scenario.origin)
    config = ControllerConfig.from_scenario(scenario)
    design = design_lqr(scenario.build_model(), config, scenario.final_pressure_gauge_Pa, line_components(scenario))
    return ClosedLoopDesign(scenario, config, design, closed_loop_model(scenario, config, design))


def run_closed_loop(scenario: Scenario | str, overrides: Mapping[str, Any] | None = None,
                    progress: Callable[[float], None] | None = None, backend: str = "python") -> ClosedLoopRun:
    """Design the controller of ``scenario`` and run it on the hybrid model.

    Parameters
    ----------
    scenario : Scenario or path
        A scenario with a valve source and a ``[controller]`` table.
    overrides : mapping, optional
        Replacement ``[controller]`` keys (e.g. ``{"integrator_deadband_mm": 0}``
        to see the friction limit cycle).
    progress : callable, optional
        Called with the simulated time reached (python backend, see :func:`~pamsim.simulator.simulate_model`).
    backend : str
        A name of :data:`pamsim.backends.BACKENDS`: each runs the same assembly, controller included
        (the native backend on the generic C engine, the FMU backends through the FMU of the assembly).
    """
    loop = design_closed_loop(scenario, overrides)
    scenario, config, design = loop.scenario, loop.config, loop.design
    result = simulate(scenario, backend, progress, model=loop.model)
    x0 = scenario.initial_contraction_m
    band = config.spec.get("settling_band_mm", 0.5) * 1e-3
    metrics = step_metrics(result.t_s, result.x_m, config.step_time_s, x0, config.target_contraction_m, band)
    t_lin, x_lin = linear_step_prediction(design, config, x0, scenario.duration_s - config.step_time_s)
    lin_metrics = step_metrics(t_lin, x_lin, 0.0, x0, config.target_contraction_m, band)
    return ClosedLoopRun(result, design, config, metrics, t_lin + config.step_time_s, x_lin, lin_metrics)
