"""Operating points of the muscle for linearisation.

Three kinds:

``open_valve``
    Valve fully open to a supply pressure, the chamber at supply pressure,
    the load at rest where ``F_static(x, p_supply) = W - F_ext``.  The valve
    flow is in its laminar branch (pressure ratio 1).
``held_pressure``
    A target contraction held with the valve closed (command 0): the chamber
    holds the pressure where ``F_static(x, p) = W - F_ext``.  A 3/3 valve
    cannot fill and vent at once, so no balance of inflow and outflow exists;
    a closed valve at the holding pressure is its only equilibrium away from
    the supply pressure.
``trajectory``
    The state of a scenario's hybrid simulation at a given time, with the
    inputs at that time.  It need not be an equilibrium; the residual
    ``f(x0, u0)`` is reported.
``pwm_averaged`` and ``pwm_averaged_held``
    The averaged model of an on/off valve under PWM (:mod:`pamsim.elements.pwm_average`), its input
    the duty: at the scenario's duty, the chamber where the mean flows of the supply and exhaust paths
    cancel and the load at rest there; or a target contraction held at the duty whose mean flow
    cancels at the holding pressure.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import brentq

from ..backends import simulate
from ..constants import PA_PER_BAR
from ..elements.pwm_average import AveragedPwmSource
from ..errors import InputError
from ..model import Mode, MuscleModel
from ..static import equilibrium_contraction_m, max_load_N
from .system import MusclePlant


@dataclass(frozen=True)
class OperatingPoint:
    """States ``(x_m, v_m_s, p_abs_Pa, air_mass_kg)`` and inputs ``(valve_command, supply_gauge_Pa, F_ext_N)``.

    ``mode`` is the hybrid mode of the load there (stick for an equilibrium).  ``line_states``: the states
    of the components added to the rig there (``{"reservoir.p_abs_Pa": ...}``), where the operating point
    knows them (a run's); an equilibrium's come from the components at rest
    (:func:`pamsim.control.exact.held_line_states`).  ``motion_sign``: the sign of the load's last nonzero
    velocity up to a run's point (+1 contracting, -1 extending), 0 where it never moved or at an
    equilibrium; the branch of a hysteresis at rest (:mod:`pamsim.control.loop_point`).
    """

    states: np.ndarray
    inputs: np.ndarray
    kind: str
    mode: Mode
    description: str
    line_states: dict = field(default_factory=dict)
    motion_sign: int = 0

    def as_dict(self) -> dict:
        """The operating point as JSON-ready values: kind, mode, description, states and inputs."""
        out = {"kind": self.kind, "mode": self.mode.label, "description": self.description,
               "states": [float(v) for v in self.states], "inputs": [float(v) for v in self.inputs]}
        if self.line_states:
            out["line_states"] = {k: float(v) for k, v in self.line_states.items()}
        return out


def _load_N(model: MuscleModel, F_ext_N: float) -> float:
    """Force the muscle must supply at rest: the weight less any helping external force [N]."""
    return model.load.weight_N - F_ext_N


def _who(pull) -> str:
    """What pulls the load at rest, for a message: the muscle, or the muscle with the added components
    (:func:`pamsim.control.exact.rest_pull`), so that a spring's pull is not laid on the muscle."""
    added = getattr(pull, "added_names", None)
    return "the muscle" if added is None else f"the muscle with {added}"


def _shares(pull, x_m: float, p_gauge_Pa: float) -> str:
    """``, where the muscle pulls a N and component 'spring' b N``: each puller's share at ``x_m``,
    ``p_gauge_Pa``, with components added; nothing for the muscle alone."""
    if getattr(pull, "added_names", None) is None:
        return ""
    muscle = float(pull.static_force.force_N(x_m, p_gauge_Pa))
    return f", where the muscle pulls {muscle:.2f} N and {pull.added_names} {float(pull.added_N(x_m, p_gauge_Pa)):.2f} N"


def _rest_states(model: MuscleModel, x_m: float, p_gauge_Pa: float) -> np.ndarray:
    # The chamber's two states: a spool's come with the inputs (pamsim.control.linear)
    return np.array([x_m, 0.0, *model.source.initial_state(x_m, p_gauge_Pa)[:2]], dtype=float)


def open_valve_equilibrium(model: MuscleModel, supply_gauge_Pa: float, F_ext_N: float = 0.0,
                           pull=None) -> OperatingPoint:
    """The load at rest with the valve fully open and the chamber at supply pressure.

    ``pull`` is what pulls the load at rest (``force_N(x_m, p_gauge_Pa)``): the muscle's static force,
    or with components added to the rig :func:`pamsim.control.exact.rest_pull`.

    Raises
    ------
    InputError
        If the load exceeds the muscle's force capability at that pressure (it
        stays on the lower stop) or the muscle still out-pulls it at the upper
        stop (no free equilibrium).
    """
    MusclePlant(model)  # checks the source type
    load = _load_N(model, F_ext_N)
    pull = pull or model.static_force
    x_high = model.stops.x_high_m
    x_eq = equilibrium_contraction_m(pull, supply_gauge_Pa, load, x_high)
    bar = supply_gauge_Pa / PA_PER_BAR
    if x_eq <= model.stops.x_low_m:
        cap = max_load_N(pull, supply_gauge_Pa, x_high)
        raise InputError(f"a load of {load:.2f} N is beyond the force capability of {_who(pull)} at {bar:g} bar "
                         f"({cap:.2f} N): it rests on the lower stop, no equilibrium to linearise about")
    if x_eq >= x_high:
        raise InputError(f"at {bar:g} bar {_who(pull)} out-pulls {load:.2f} N up to its upper stop "
                         f"({x_high * 1e3:.1f} mm{_shares(pull, x_high, supply_gauge_Pa)}): "
                         "no free equilibrium to linearise about")
    return OperatingPoint(_rest_states(model, x_eq, supply_gauge_Pa), np.array([1.0, supply_gauge_Pa, F_ext_N]),
                          "open_valve", Mode.STICK,
                          f"valve open, chamber at the {bar:g} bar supply, load {load:.2f} N at rest at "
                          f"{x_eq * 1e3:.3f} mm")


def contraction_range_m(model: MuscleModel) -> tuple[float, float]:
    """Contractions at which a held equilibrium is accepted: above the lower stop, within the fitted range."""
    return model.stops.x_low_m, min(model.stops.x_high_m, model.fit_range.x_max_m)


def holding_pressure_Pa(model: MuscleModel, x_m: float, load_N: float, p_max_gauge_Pa: float, pull=None) -> float:
    """Gauge pressure [Pa] in [0, p_max_gauge_Pa] at which ``F_static(x, p) = load_N`` (``pull``, if given,
    in place of the static force: see :func:`open_valve_equilibrium`).

    Raises
    ------
    InputError
        If the load needs more than ``p_max_gauge_Pa`` there, or the muscle's
        elastic force alone already exceeds it (it would need a vacuum).
    """
    pull = pull or model.static_force
    F = pull.force_N
    lo, hi = F(x_m, 0.0) - load_N, F(x_m, p_max_gauge_Pa) - load_N
    if hi < 0.0:
        raise InputError(f"holding {load_N:.2f} N at {x_m * 1e3:g} mm needs more than the "
                         f"{p_max_gauge_Pa / PA_PER_BAR:g} bar supply ({_who(pull)} can hold "
                         f"{F(x_m, p_max_gauge_Pa):.2f} N there{_shares(pull, x_m, p_max_gauge_Pa)}): the load is beyond "
                         "its force capability at this contraction")
    if lo > 0.0:
        raise InputError(f"at {x_m * 1e3:g} mm {_who(pull).replace('the muscle', 'the unpressurised muscle', 1)} "
                         f"already pulls {F(x_m, 0.0):.2f} N{_shares(pull, x_m, 0.0)}, "
                         f"more than the {load_N:.2f} N load: it cannot be held there at a gauge pressure >= 0")
    return float(brentq(lambda p: F(x_m, p) - load_N, 0.0, p_max_gauge_Pa, xtol=1e-9))


def held_equilibrium(model: MuscleModel, x_m: float, supply_gauge_Pa: float, F_ext_N: float = 0.0,
                     pull=None) -> OperatingPoint:
    """The load held at contraction ``x_m`` by a closed valve and the pressure that balances it (``pull``:
    see :func:`open_valve_equilibrium`).

    Raises
    ------
    InputError
        If ``x_m`` is outside :func:`contraction_range_m` or the holding
        pressure is not between atmospheric and the supply pressure.
    """
    MusclePlant(model)
    lo, hi = contraction_range_m(model)
    if not lo < x_m < hi:
        raise InputError(f"contraction {x_m * 1e3:g} mm is outside the model's range ({lo * 1e3:g} mm, "
                         f"{hi * 1e3:g} mm): above the lower stop and within the static polynomial's fitted range")
    p = holding_pressure_Pa(model, x_m, _load_N(model, F_ext_N), supply_gauge_Pa, pull)
    return OperatingPoint(_rest_states(model, x_m, p), np.array([0.0, supply_gauge_Pa, F_ext_N]),
                          "held_pressure", Mode.STICK,
                          f"valve closed, chamber holding {p / PA_PER_BAR:.4f} bar, load "
                          f"{_load_N(model, F_ext_N):.2f} N at rest at {x_m * 1e3:g} mm")


def trajectory_point(scenario, time_s: float) -> OperatingPoint:
    """The state of ``scenario``'s hybrid simulation at ``time_s`` and the inputs then.

    Raises
    ------
    InputError
        If ``time_s`` is not in (0, duration].
    """
    if not 0.0 < time_s <= scenario.duration_s:
        raise InputError(f"--at-time {time_s:g} s: must lie in (0, {scenario.duration_s:g}] s, the scenario's duration")
    model = scenario.build_model()
    MusclePlant(model)
    result = simulate(scenario.with_changes({"simulation": {"duration_s": float(time_s)}}))
    p_abs = result.p_gauge_Pa[-1] + model.source.p_atm_Pa
    states = np.array([result.x_m[-1], result.v_m_s[-1], p_abs, result.signals["air_mass_kg"][-1]], dtype=float)
    # A valve pair's inputs are (inlet, exhaust, supply): the inlet's opening is the averaged model's duty
    inputs = model.source.inputs(float(time_s))
    command, supply = inputs[0], inputs[-1]
    mode = result.final_mode
    added = {f"{a.component.name}.{v.name}" for a in scenario.added_components for v in a.component.states}
    line = {name: float(values[-1]) for name, values in result.signals.items() if name in added}
    line.update({f"valve.{name}": float(result.signals[name][-1]) for name in model.source.state_names[2:]})
    moved = np.flatnonzero(result.v_m_s != 0.0)
    return OperatingPoint(states, np.array([command, supply, model.load.external_N(float(time_s))], dtype=float),
                          "trajectory", mode,
                          f"state of the simulation at t = {time_s:g} s ({mode.label}): x = {states[0] * 1e3:.3f} mm, "
                          f"v = {states[1] * 1e3:.3f} mm/s, p = {(p_abs - model.source.p_atm_Pa) / PA_PER_BAR:.4f} bar",
                          line, int(np.sign(result.v_m_s[moved[-1]])) if moved.size else 0)



def _averaged_source(model: MuscleModel) -> AveragedPwmSource:
    if not isinstance(model.source, AveragedPwmSource):
        raise InputError("this operating point is the averaged PWM valve's: the model needs a PWM command run "
                         "with model = 'averaged'")
    return model.source


def averaged_pwm_equilibrium(model: MuscleModel, duty: float, F_ext_N: float = 0.0, pull=None) -> OperatingPoint:
    """The load at rest with the averaged PWM valve at ``duty``: the chamber at the pressure where the supply
    and exhaust paths' mean flows cancel (the supply's for a 2/2 valve), the load where ``pull`` (see
    :func:`open_valve_equilibrium`) holds it there.

    Raises
    ------
    InputError
        If the valve never opens at ``duty``, or the load finds no free equilibrium at that pressure.
    """
    src = _averaged_source(model)
    try:
        p_abs = src.balance_pressure_Pa(duty, src.chamber.start_temperature_K(src.T_supply_K))
    except ValueError as exc:
        raise InputError(f"duty {duty:g}: {exc}; no equilibrium to linearise about") from None
    op = open_valve_equilibrium(model, p_abs - src.p_atm_Pa, F_ext_N, pull)
    supply = float(src.supply_gauge_Pa.final_value)
    w_supply, w_exhaust = src.valve.shares(duty)
    return replace(op, inputs=np.array([duty, supply, F_ext_N]), kind="pwm_averaged",
                   description=f"PWM averaged at duty {duty:g} (supply path open {w_supply:.4g}, exhaust path "
                               f"{w_exhaust:.4g} of a period), chamber at {(p_abs - src.p_atm_Pa) / PA_PER_BAR:.4f} "
                               f"bar where their mean flows cancel, load {_load_N(model, F_ext_N):.2f} N at rest at "
                               f"{op.states[0] * 1e3:.3f} mm")


def averaged_pwm_held(model: MuscleModel, x_m: float, F_ext_N: float = 0.0, pull=None) -> OperatingPoint:
    """The load held at contraction ``x_m`` by the averaged PWM valve: the chamber at the holding pressure
    (:func:`held_equilibrium`) and the duty at which the two paths' mean flows cancel there (0 for a 2/2
    valve, which then stays closed).

    Raises
    ------
    InputError
        As :func:`held_equilibrium`, or if no duty in [0, 1] holds that pressure.
    """
    src = _averaged_source(model)
    supply = float(src.supply_gauge_Pa.final_value)
    op = held_equilibrium(model, x_m, supply, F_ext_N, pull)
    p_abs = float(op.states[2])
    T = src.chamber.start_temperature_K(src.T_supply_K)

    def flow(duty):
        return src.valve.inflow_kg_s(duty, p_abs, T, supply + src.p_atm_Pa, src.T_supply_K, src.p_atm_Pa)

    if flow(0.0) == 0.0:
        duty = 0.0
    elif flow(0.0) < 0.0 < flow(1.0):
        duty = float(brentq(flow, 0.0, 1.0, xtol=1e-12))
    else:
        raise InputError(f"no duty in [0, 1] holds {(p_abs - src.p_atm_Pa) / PA_PER_BAR:.4f} bar at {x_m * 1e3:g} mm "
                         "with this PWM valve: its mean flow does not change sign")
    return replace(op, inputs=np.array([duty, supply, F_ext_N]), kind="pwm_averaged_held",
                   description=f"PWM averaged at duty {duty:.6g}, chamber holding "
                               f"{(p_abs - src.p_atm_Pa) / PA_PER_BAR:.4f} bar, load {_load_N(model, F_ext_N):.2f} N "
                               f"at rest at {x_m * 1e3:g} mm")
