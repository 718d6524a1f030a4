"""A joint scenario: muscles on a rotary joint, read from a TOML file or a dict.

::

    name = "antagonistic_pair"
    [joint]                      # the link and its bearing (RotaryJoint's parameters, SI)
    inertia_kg_m2 = 2.0e-4
    ...
    [[muscle]]                   # one table per muscle
    name = "flexor"
    side = 1                     # +1: it turns the joint toward larger angles
    radius_m = 0.01
    x_at_zero_m = 0.012          # its contraction at angle zero
    [muscle.model]               # as a one-muscle scenario's [model], [parameters] and [pressure]
    parameter_set = "shadow_6x300_acra2012"
    [muscle.pressure]
    source = "prescribed"
    ...

Each muscle's ``model``, ``parameters``, ``pressure``, ``chamber``, ``hysteresis`` and ``component`` tables are
read as a one-muscle scenario's (:class:`pamsim.scenario.Scenario`), so every static force model, friction and
damping law, pressure source, valve, chamber law and line a one-muscle scenario offers works per muscle, with
the same checks and messages; a component's ``load.*`` is the muscle's end.
"""

from __future__ import annotations

import copy
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..assemblies.joint import SLIDER_FRICTION_LOADS, JointMuscle, joint_assembly, slider_assembly
from ..components.pulley import LeverAttachment, Pulley, SliderTendon
from ..elements.damping import increasing
from ..scenario import Scenario, ScenarioError
from ..signal_tables import signal_from_table
from ..signals import Constant
from ..simulator import SolverOptions
from ..table_checks import TableChecker
from .body import JOINT, SLIDER, Body

JOINT_KEYS: dict[str, tuple[float | None, str]] = {
    "inertia_kg_m2": (None, "positive"), "link_mass_kg": (0.0, "non_negative"),
    "com_distance_m": (0.0, "non_negative"), "g_m_s2": (9.81, "positive"), "theta_down_rad": (0.0, "any"),
    "b_Nm_s_per_rad": (0.0, "non_negative"), "tau_coulomb_Nm": (0.0, "non_negative"),
    "theta_min_rad": (None, "any"), "theta_max_rad": (None, "any"), "restitution": (0.0, "unit"),
    "min_rebound_speed_rad_s": (1e-3, "non_negative"), "initial_angle_rad": (0.0, "any")}
"""``[joint]`` keys: default (None: required) and the range a value must lie in.  g is standard gravity
(9.81 m/s^2, as the one-muscle scenarios); min_rebound_speed_rad_s is assumed (a slower rebound than 1 mrad/s
moves the link by less than any angle a figure resolves)."""
MUSCLE_KEYS = {"name", "side", "radius_m", "x_at_zero_m", "model", "parameters", "pressure", "attachment",
               "link_attach_m", "base_attach_m", "angle_at_zero_rad", "tendon_length_m", "tendon_stiffness_N_per_m",
               "hysteresis", "chamber", "component"}
LEVER_KEYS = {"link_attach_m": "positive", "base_attach_m": "positive", "angle_at_zero_rad": "positive",
              "tendon_length_m": "non_negative"}
"""A lever attachment's keys in a ``[[muscle]]`` table (``attachment = "lever"``) and their ranges."""
SLIDER_KEYS: dict[str, tuple[float | None, str]] = {
    "mass_kg": (None, "positive"), "g_m_s2": (9.81, "positive"), "incline_rad": (math.pi / 2, "any"),
    "b_N_s_per_m": (0.0, "non_negative"), "F_coulomb_N": (0.0, "non_negative"),
    "x_min_m": (None, "any"), "x_max_m": (None, "any"), "restitution": (0.0, "unit"),
    "min_rebound_speed_m_s": (1e-3, "non_negative"), "initial_position_m": (0.0, "any")}
"""``[slider]`` keys: default (None: required) and range.  The guide is vertical unless ``incline_rad`` says
otherwise (the paper's rig); min_rebound_speed_m_s is assumed (a rebound slower than 1 mm/s moves the
carriage by less than a figure resolves).  Besides these, ``weight_N`` in place of ``mass_kg`` (the mass is
then ``weight_N / g_m_s2``, as a one-muscle scenario's ``[load]``), ``friction_load`` (:data:`SLIDER_FRICTION_LOADS`,
default ``"static_force"``) and an ``external_force`` signal table."""
SLIDER_MUSCLE_KEYS = {"name", "side", "x_at_zero_m", "model", "parameters", "pressure", "tendon_stiffness_N_per_m",
                      "hysteresis", "chamber", "component"}
TOP_KEYS = {"name", "description", "joint", "slider", "muscle", "simulation", "solver", "controller"}
CONTROLLER_KEYS: dict[str, tuple[object, str]] = {
    "kind": (None, "text"), "sample_rate_Hz": (1000.0, "positive"), "stiffness_Nm_per_rad": (None, "positive"),
    "bandwidth_rad_s": (80.0, "positive"), "steps_time_s": ((), "list"), "steps_angle_rad": ((), "list"),
    "sine_start_s": (math.inf, "non_negative"), "sine_amplitude_rad": (0.0, "non_negative"),
    "sine_frequency_Hz": (0.0, "non_negative"), "settle_s": (0.3, "non_negative"), "spec": ({}, "table")}
"""``[controller]`` keys of a joint: default (None: required) and kind.  The defaults: a 1 kHz controller;
its PID's poles at -80 rad/s (about the shipped pair's open-loop frequency, sqrt(k/J)); 0.3 s after a
step before its error counts as settled (the pair's transients ring out within it)."""
SPEC_KEYS = ("step_angle_rms_max_rad", "sine_angle_rms_max_rad", "stiffness_rms_max_Nm_per_rad")
SOLVER_KEYS = {"method", "rtol", "max_events", "max_step_s"}
PLACEHOLDER_LOAD = {"weight_N": 1.0}
"""A muscle's one-muscle scenario needs a load; on a joint its tendon carries the load instead, and this
one is never used (the friction law reads the load from the tendon, :class:`pamsim.components.pulley.Pulley`)."""


def _fail(origin: str, key: str, value, why: str):
    TableChecker(origin, ScenarioError).fail(key, value, why)


def _table(origin: str, key: str, value) -> dict:
    if not isinstance(value, dict):
        _fail(origin, key, value, "must be a table")
    return value


def _number(origin: str, key: str, value, kind: str) -> float:
    """``value`` as a float (the scenario files' one check of a number), then within the range ``kind`` names."""
    value = TableChecker(origin, ScenarioError).number(key, value)
    rules = {"positive": (value > 0, "must be > 0"), "non_negative": (value >= 0, "must be >= 0"),
             "unit": (0 <= value <= 1, "must lie in [0, 1]"), "any": (True, "")}
    ok, why = rules[kind]
    if not ok:
        _fail(origin, key, value, why)
    return value


@dataclass(frozen=True)
class JointScenario:
    """A validated joint scenario: the joint's parameters (or the slider's: :attr:`body`), its muscles
    (each with the one-muscle scenario its tables make), the run's length, sampling and solver settings."""

    name: str
    spec: Mapping[str, Any] = field(repr=False)
    joint: Mapping[str, float] = field(repr=False)
    muscles: tuple[tuple[Mapping[str, Any], Scenario], ...] = field(repr=False)
    duration_s: float
    solver: SolverOptions
    origin: str = "<dict>"
    external_torque: Any = field(default=Constant(0.0), repr=False)
    """The external torque on the link [N m], a signal of time (``[joint.external_torque]``; default none)."""
    controller: Mapping[str, Any] | None = field(default=None, repr=False)
    """The ``[controller]`` table, checked (:data:`CONTROLLER_KEYS`), or None for an open-loop run."""
    body: Body = JOINT
    """The body the muscles move: a rotary joint (``[joint]``) or a linear slider (``[slider]``, whose
    parameters :attr:`joint` then holds, with ``friction_load``)."""

    @classmethod
    def from_dict(cls, spec: Mapping[str, Any], origin: str = "<dict>", base_dir: str | Path = ".") -> "JointScenario":
        """Validate ``spec`` (a TOML file's content) and return the scenario; :class:`ScenarioError`
        names the key and value of the first mistake."""
        spec = copy.deepcopy(dict(spec))
        for key in sorted(set(spec) - TOP_KEYS):
            _fail(origin, key, spec[key], f"unknown key; a joint scenario has {sorted(TOP_KEYS)}")
        sim = _table(origin, "simulation", spec.get("simulation", {}))
        name = spec.get("name", "joint")
        if not isinstance(name, str) or not name.isidentifier():
            _fail(origin, "name", name, "must be a name made of letters, digits and _")
        duration = _number(origin, "simulation.duration_s", sim.get("duration_s", 5.0), "positive")
        rate = _number(origin, "simulation.sample_rate_Hz", sim.get("sample_rate_Hz", 1000.0), "positive")
        body = _body(origin, spec)
        joint_table = dict(_table(origin, body.name, spec.get(body.name, {})))
        effort_key = "external_torque" if body is JOINT else "external_force"
        torque = joint_table.pop(effort_key, None)
        joint = (_joint if body is JOINT else _slider)(origin, joint_table if body.name in spec else None)
        external = (signal_from_table(TableChecker(origin, ScenarioError), f"{body.name}.{effort_key}", torque,
                                      f"_{body.unit}", 1.0, Path(base_dir)) if torque is not None else Constant(0.0))
        solver = _table(origin, "solver", spec.get("solver", {}))
        for key in sorted(set(solver) - SOLVER_KEYS):
            _fail(origin, f"solver.{key}", solver[key], f"unknown key; [solver] has {sorted(SOLVER_KEYS)}")
        shared = {"solver": solver, "simulation": {"duration_s": duration, "sample_rate_Hz": rate}}
        muscles = _muscles(origin, spec.get("muscle"), shared, Path(base_dir), body)
        # Each muscle's one-muscle scenario has read the [solver] table, with its checks and messages.
        if "controller" in spec and body is SLIDER:
            _fail(origin, "controller", spec["controller"], "a slider has no controller yet (the angle-stiffness "
                  "controller drives a joint)")
        controller = _controller(origin, spec["controller"], joint, muscles) if "controller" in spec else None
        scenario = cls(name, spec, joint, muscles, duration, muscles[0][1].solver, origin, external, controller, body)
        scenario._check_limits()
        return scenario

    def _check_limits(self) -> None:
        """Each muscle's contraction stays inside its own stops (the static model's range) over the
        joint's limits: beyond them its force is not defined."""
        low_key, high_key, initial_key = self.body.limit_keys
        lo, hi = self.joint[low_key], self.joint[high_key]
        for m, (table, sc) in zip(self.joint_muscles(), self.muscles):
            stops = sc.build_model().stops
            if m.lever is not None:
                phi = [m.lever["angle_at_zero_rad"] - m.side * t for t in (lo, hi)]
                if not (0.0 < min(phi) and max(phi) < math.pi):
                    _fail(self.origin, f"muscle {m.name!r}.angle_at_zero_rad", m.lever["angle_at_zero_rad"],
                          f"its lever's arms would line up within the joint's limits (arm angle from {phi[0]:.4g} to "
                          f"{phi[1]:.4g} rad, must stay inside (0, pi)): the muscle would have no lever arm there")
            for key, theta in ((low_key, lo), (high_key, hi), (initial_key, self.joint[initial_key])):
                x = contraction_m(m, theta, self.body)
                if not stops.x_low_m - 1e-12 <= x <= stops.x_high_m + 1e-12:
                    _fail(self.origin, f"{self.body.name}.{key}", theta,
                          f"muscle {table['name']!r} would contract to {x * 1e3:.2f} mm there, outside its range "
                          f"[{stops.x_low_m * 1e3:.2f}, {stops.x_high_m * 1e3:.2f}] mm (its attachment's geometry)")

    def joint_muscles(self) -> tuple[JointMuscle, ...]:
        """The muscles as the joint's assembly takes them."""
        out = []
        for table, sc in self.muscles:
            m = sc.build_model()
            lever = ({**table["lever"], "muscle_L0_m": sc.parameters["L0_m"]} if table["lever"] is not None else None)
            out.append(JointMuscle(table["name"], m.static_force, m.friction, m.damping, m.source,
                                   table["radius_m"], table["side"], table["x_at_zero_m"], sc.initial_pressure_gauge_Pa,
                                   lever, table["tendon_stiffness_N_per_m"], sc.added_components))
        return tuple(out)

    def joint_values(self) -> dict[str, float]:
        """The :class:`pamsim.components.rotary_joint.RotaryJoint` parameters, the solver's margins in
        torque (its force margins times the largest lever arm: a pulley's radius, or a bound on a lever's,
        its shorter arm); for a slider, the :class:`pamsim.components.linear_slider.LinearSlider`'s, the
        margins the solver's own."""
        if self.body is SLIDER:
            values = {k: v for k, v in self.joint.items() if k != "friction_load"}
            return {**values, "stick_margin_N": self.solver.stick_margin_N, "release_margin_N": self.solver.release_margin_N}
        r = max(t["radius_m"] if t["lever"] is None else min(t["lever"]["link_attach_m"], t["lever"]["base_attach_m"])
                for t, _ in self.muscles)
        return {**self.joint, "stick_margin_Nm": self.solver.stick_margin_N * r,
                "release_margin_Nm": self.solver.release_margin_N * r}

    def assembly(self):
        """The joint's assembly (:func:`pamsim.assemblies.joint.joint_assembly`), or the slider's
        (:func:`pamsim.assemblies.joint.slider_assembly`)."""
        if self.body is SLIDER:
            return slider_assembly(self.joint_values(), self.joint_muscles(), self.joint["g_m_s2"],
                                   self.joint["friction_load"], name=self.name)
        return joint_assembly(self.joint_values(), self.joint_muscles(), self.joint["g_m_s2"], name=self.name)


def contraction_m(m: JointMuscle, theta_rad: float, body: Body = JOINT) -> float:
    """Muscle ``m``'s contraction at joint angle ``theta_rad`` (on a slider, ``body``: at that position), by
    its attachment's own kinematics."""
    if body is SLIDER:
        return SliderTendon.kinematics(None, {"x_at_zero_m": m.x_at_zero_m, "side": m.side}, theta_rad)[0]
    if m.lever is None:
        return Pulley.kinematics(None, {"x_at_zero_m": m.x_at_zero_m, "side": m.side, "radius_m": m.radius_m}, theta_rad)[0]
    return LeverAttachment.kinematics(None, {**m.lever, "side": m.side}, theta_rad)[0]


def load_joint_scenario(path: str | Path) -> JointScenario:
    """Read and validate a joint scenario file."""
    path = Path(path)
    try:
        spec = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ScenarioError(f"{path}: {exc}") from exc
    if not is_joint_spec(spec):
        raise ScenarioError(f"{path}: not a joint scenario (it has no [joint], [slider] or [[muscle]] tables)")
    return JointScenario.from_dict(spec, origin=str(path), base_dir=path.parent)


def is_joint_spec(spec: Mapping[str, Any]) -> bool:
    """Whether a scenario file's content describes muscles on a joint or a slider (it has ``[joint]``,
    ``[slider]`` or ``[[muscle]]``)."""
    return "joint" in spec or "slider" in spec or isinstance(spec.get("muscle"), list)


def _body(origin: str, spec: Mapping[str, Any]) -> Body:
    """The body a scenario's muscles move: a joint unless it has a ``[slider]`` table (and no ``[joint]``)."""
    if "slider" in spec and "joint" in spec:
        _fail(origin, "slider", spec["slider"], "a scenario has a [joint] or a [slider], not both")
    return SLIDER if "slider" in spec else JOINT


def _slider(origin: str, table) -> dict:
    if not isinstance(table, dict):
        raise ScenarioError(f"{origin}: [slider] is missing (the carriage's mass and stops)")
    load = table.get("friction_load", "static_force")
    if load not in SLIDER_FRICTION_LOADS:
        _fail(origin, "slider.friction_load", load, f"must be one of {list(SLIDER_FRICTION_LOADS)}")
    table = {k: v for k, v in table.items() if k != "friction_load"}
    if "weight_N" in table:
        if "mass_kg" in table:
            _fail(origin, "slider.weight_N", table["weight_N"], "give mass_kg or weight_N, not both")
        weight = _number(origin, "slider.weight_N", table.pop("weight_N"), "positive")
        g = _number(origin, "slider.g_m_s2", table.get("g_m_s2", SLIDER_KEYS["g_m_s2"][0]), "positive")
        table["mass_kg"] = weight / g  # as a one-muscle scenario's [load] reads a weight
    out = _checked(origin, "slider", table, SLIDER_KEYS)
    return {**out, "friction_load": load}


def _joint(origin: str, table) -> dict[str, float]:
    if not isinstance(table, dict):
        raise ScenarioError(f"{origin}: [joint] is missing (the link's inertia and limits)")
    return _checked(origin, "joint", table, JOINT_KEYS)


def _checked(origin: str, where: str, table: dict, keys: dict) -> dict[str, float]:
    """A body's table checked against ``keys`` (:data:`JOINT_KEYS`, :data:`SLIDER_KEYS`): known keys, the
    required ones, their ranges, and limits in order with the start between them."""
    for key in sorted(set(table) - set(keys)):
        _fail(origin, f"{where}.{key}", table[key], f"unknown key; [{where}] has {sorted(keys)}")
    out = {}
    for key, (default, kind) in keys.items():
        if key not in table and default is None:
            raise ScenarioError(f"{origin}: {where}.{key} is required")
        out[key] = _number(origin, f"{where}.{key}", table.get(key, default), kind)
    low, high, initial = (JOINT if where == "joint" else SLIDER).limit_keys
    if out[low] >= out[high]:
        _fail(origin, f"{where}.{low}", out[low], f"must be below {where}.{high} = {out[high]!r}")
    if not out[low] <= out[initial] <= out[high]:
        _fail(origin, f"{where}.{initial}", out[initial], f"must lie between the {where}'s limits")
    return out


def _muscles(origin: str, tables, shared: dict, base_dir: Path, body: Body = JOINT) -> tuple:
    if not isinstance(tables, list) or not tables:
        raise ScenarioError(f"{origin}: no [[muscle]] tables (a {body.name} needs at least one muscle)")
    seen, out = set(), []
    for k, table in enumerate(tables):
        where = f"muscle[{k}]"
        if not isinstance(table, dict):
            _fail(origin, where, table, "must be a table")
        name = table.get("name")
        if not isinstance(name, str) or not name.isidentifier():
            _fail(origin, f"{where}.name", name, "must be a name made of letters, digits and _")
        if name in seen:
            _fail(origin, f"{where}.name", name, "is given to two muscles")
        seen.add(name)
        out.append(_muscle(origin, f"muscle {name!r}", table, shared, base_dir, body))
    return tuple(out)


def _muscle(origin: str, where: str, table: dict, shared: dict, base_dir: Path, body: Body = JOINT):
    for key in ("model", "parameters", "pressure"):
        if key in table:
            _table(origin, f"{where}.{key}", table[key])
    allowed = MUSCLE_KEYS if body is JOINT else SLIDER_MUSCLE_KEYS
    for key in sorted(set(table) - allowed):
        _fail(origin, f"{where}.{key}", table[key], f"unknown key; a [[muscle]] on a {body.name} has {sorted(allowed)}")
    if "pressure" not in table:
        raise ScenarioError(f"{origin}: {where} has no [muscle.pressure] table: every muscle needs a pressure input")
    values = _attachment(origin, where, table, body)
    one = {"model": table.get("model", {}), "parameters": table.get("parameters", {}), "pressure": table["pressure"],
           "load": PLACEHOLDER_LOAD, **shared}
    if "hysteresis" in table:  # read as a one-muscle scenario's: its elements take the muscle's friction's place
        one["hysteresis"] = _table(origin, f"{where}.hysteresis", table["hysteresis"])
    if "chamber" in table:  # the chamber's law, as a one-muscle scenario's [chamber]
        one["chamber"] = _table(origin, f"{where}.chamber", table["chamber"])
    if "component" in table:  # its line, reservoir, ...: as a one-muscle scenario's [[component]] tables
        one["component"] = table["component"]
    scenario = Scenario.from_dict(one, name=table["name"], base_dir=base_dir, origin=f"{origin}: {where}")
    values["tendon_stiffness_N_per_m"] = _tendon_stiffness(origin, where, table, scenario)
    return values, scenario


def _attachment(origin: str, where: str, table: dict, body: Body) -> dict:
    """A muscle's name, side and attachment (a pulley's radius and contraction at zero, or a lever's geometry;
    on a slider, its contraction at zero), checked."""
    side = table.get("side")
    if side not in (1, -1) or isinstance(side, bool):
        _fail(origin, f"{where}.side", side, f"must be 1 (it moves the {body.name} toward larger {body.noun}s) or -1")
    attachment = table.get("attachment", "pulley")
    if attachment not in ("pulley", "lever"):
        _fail(origin, f"{where}.attachment", attachment, "must be 'pulley' (radius_m, x_at_zero_m) or 'lever' "
              f"({', '.join(LEVER_KEYS)})")
    own = set(LEVER_KEYS) if attachment == "lever" else {"radius_m", "x_at_zero_m"}
    for key in sorted((set(LEVER_KEYS) | {"radius_m", "x_at_zero_m"}) - own):
        if key in table:
            _fail(origin, f"{where}.{key}", table[key], f"not a key of attachment = {attachment!r}")
    values = {"name": table["name"], "side": float(side), "radius_m": 0.0, "x_at_zero_m": 0.0, "lever": None}
    if body is SLIDER:
        values["x_at_zero_m"] = _number(origin, f"{where}.x_at_zero_m", table.get("x_at_zero_m", 0.0), "any")
    elif attachment == "pulley":
        values["radius_m"] = _number(origin, f"{where}.radius_m", table.get("radius_m"), "positive")
        values["x_at_zero_m"] = _number(origin, f"{where}.x_at_zero_m", table.get("x_at_zero_m", 0.0), "any")
    else:
        values["lever"] = {k: _number(origin, f"{where}.{k}", table.get(k), kind) for k, kind in LEVER_KEYS.items()}
    return values


def _tendon_stiffness(origin: str, where: str, table: dict, scenario: Scenario) -> float | None:
    """A muscle's ``tendon_stiffness_N_per_m`` (None: a rigid tendon), checked: positive, and the muscle's
    damping one that a massless muscle end can move under (:func:`pamsim.elements.damping.increasing`)."""
    key = "tendon_stiffness_N_per_m"
    if key not in table:
        return None
    k = _number(origin, f"{where}.{key}", table[key], "positive")
    damping = scenario.build_model().damping
    if not increasing(damping):
        _fail(origin, f"{where}.model.damping", getattr(damping, "name", type(damping).__name__),
              f"a muscle on an elastic tendon ({key} = {k:g}) needs damping that grows with speed through zero "
              "(its end is massless and moves at the speed its damping allows): use damping = 'linear', or "
              "'paper' with D1_N_s_per_m > 0")
    c = table.get("hysteresis", {}).get("damping_N_s_per_m", 0.0)
    if c != 0.0:
        _fail(origin, f"{where}.hysteresis.damping_N_s_per_m", c,
              f"presliding damping cannot act on the end of a muscle on an elastic tendon ({key} = {k:g}): the end "
              "is massless and moves at the speed the balance of its forces gives, which a force that depends on "
              "that speed would make a loop; leave it out (0), or make the tendon rigid")
    return k


def _controller(origin: str, table, joint: dict, muscles) -> dict:
    """The ``[controller]`` table checked: its keys, kinds and ranges, steps inside the joint's limits, two
    muscles on prescribed pressures (the controller's outputs take their place)."""
    table = _table(origin, "controller", table)
    for key in sorted(set(table) - set(CONTROLLER_KEYS)):
        _fail(origin, f"controller.{key}", table[key], f"unknown key; [controller] has {sorted(CONTROLLER_KEYS)}")
    if table.get("kind") != "angle_stiffness":
        _fail(origin, "controller.kind", table.get("kind"), "must be 'angle_stiffness' (angle tracking at a commanded stiffness)")
    out = {"kind": "angle_stiffness"}
    for key, (default, kind) in CONTROLLER_KEYS.items():
        if key in ("kind", "spec", "steps_time_s", "steps_angle_rad"):
            continue
        if key not in table and default is None:
            raise ScenarioError(f"{origin}: controller.{key} is required")
        out[key] = _number(origin, f"controller.{key}", table.get(key, default), kind) if key in table else default
    out["steps_time_s"], out["steps_angle_rad"] = _steps(origin, table, joint)
    _check_sine(origin, out, joint)
    spec = _table(origin, "controller.spec", table.get("spec", {}))
    for key in sorted(set(spec) - set(SPEC_KEYS)):
        _fail(origin, f"controller.spec.{key}", spec[key], f"unknown key; [controller.spec] has {list(SPEC_KEYS)}")
    out["spec"] = {key: _number(origin, f"controller.spec.{key}", v, "positive") for key, v in spec.items()}
    _check_controlled(origin, muscles)
    return out


def _check_sine(origin: str, controller: dict, joint: dict) -> None:
    """The sinusoid about the last step's angle stays between the joint's limits."""
    centre = controller["steps_angle_rad"][-1] if controller["steps_angle_rad"] else 0.0
    a = controller["sine_amplitude_rad"]
    if a > 0 and not (joint["theta_min_rad"] < centre - a and centre + a < joint["theta_max_rad"]):
        _fail(origin, "controller.sine_amplitude_rad", a,
              f"the sinusoid about {centre:g} rad (the last step's angle) must stay between the joint's limits")


def _check_controlled(origin: str, muscles) -> None:
    """Two muscles, each on a prescribed pressure (the controller's output takes its place)."""
    for t, sc in muscles:
        if sc.spec["pressure"]["source"] != "prescribed":
            _fail(origin, f"muscle {t['name']!r}.pressure.source", sc.spec["pressure"]["source"],
                  "under a [controller] a muscle's pressure is the controller's output: give source = 'prescribed'")
    if len(muscles) != 2:
        _fail(origin, "controller.kind", "angle_stiffness", f"drives two muscles, not {len(muscles)}")


def _steps(origin: str, table: dict, joint: dict) -> tuple[tuple[float, ...], tuple[float, ...]]:
    times, angles = table.get("steps_time_s", []), table.get("steps_angle_rad", [])
    for key, values in (("steps_time_s", times), ("steps_angle_rad", angles)):
        if not isinstance(values, list):
            _fail(origin, f"controller.{key}", values, "must be a list of numbers")
    times = [_number(origin, f"controller.steps_time_s[{k}]", v, "non_negative") for k, v in enumerate(times)]
    angles = [_number(origin, f"controller.steps_angle_rad[{k}]", v, "any") for k, v in enumerate(angles)]
    if len(times) != len(angles):
        _fail(origin, "controller.steps_angle_rad", f"{len(angles)} values", f"must be as many as steps_time_s ({len(times)})")
    for k in range(1, len(times)):
        if times[k] <= times[k - 1]:
            _fail(origin, f"controller.steps_time_s[{k}]", times[k], f"must be after steps_time_s[{k - 1}] = {times[k - 1]:g}")
    for k, a in enumerate(angles):
        if not joint["theta_min_rad"] < a < joint["theta_max_rad"]:
            _fail(origin, f"controller.steps_angle_rad[{k}]", a, "must lie between the joint's limits")
    return tuple(times), tuple(angles)


def slider_of_rig(scenario: Scenario) -> JointScenario:
    """The one-muscle rig of ``scenario`` (a hanging load) as a slider: a vertical guide whose carriage is
    the load, between the rig's stops, pulled up by the muscle's tendon, the muscle's friction reading the
    carriage's mass (``friction_load = "slider_mass"``), with the same pressure source, external force,
    sampling and solver.  While the muscle pulls, both are the same equations; they differ where it
    would push (a tendon goes slack) and in the slider's energy states, which the integrator's error
    control also weighs.

    The rig's ``[chamber]``, ``[hysteresis]`` and ``[[component]]`` tables become the muscle's (a component's
    ``load.*`` is then the muscle's end on the carriage).

    Raises
    ------
    ScenarioError
        For a rig with a controller, which a slider scenario does not carry.
    """
    if "controller" in scenario.spec:
        _fail(scenario.origin, "controller", "...", "a rig with it has no slider form")
    stops, spec = scenario.build_model().stops, scenario.spec
    sim = dict(spec.get("simulation", {}))
    x0 = float(sim.pop("initial_contraction_m", 0.0))
    slider = {"mass_kg": scenario.mass_kg, "g_m_s2": scenario.parameters["g_m_s2"], "incline_rad": math.pi / 2,
              "x_min_m": stops.x_low_m, "x_max_m": stops.x_high_m, "restitution": stops.restitution,
              "min_rebound_speed_m_s": stops.min_rebound_speed_m_s, "initial_position_m": x0,
              "friction_load": "slider_mass"}
    if "external_force" in spec["load"]:
        slider["external_force"] = spec["load"]["external_force"]
    muscle = {"name": "muscle", "side": 1, "x_at_zero_m": 0.0, "model": spec.get("model", {}),
              "parameters": spec.get("parameters", {}), "pressure": spec["pressure"],
              **{key: spec[key] for key in ("chamber", "hysteresis", "component") if key in spec}}
    name = re.sub(r"\W", "_", f"{scenario.name}_slider")
    out = {"name": name if name.isidentifier() else f"rig_{name}", "slider": slider, "muscle": [muscle], "simulation": sim,
           "solver": {k: v for k, v in spec.get("solver", {}).items() if k in SOLVER_KEYS}}
    return JointScenario.from_dict(out, origin=f"{scenario.origin} (as a slider)", base_dir=scenario.base_dir)
