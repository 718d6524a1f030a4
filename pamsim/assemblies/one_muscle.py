"""One muscle lifting a hanging load: the ACRA 2012 test rig as an assembly of components.

::

    valve --port-- chamber --p_gauge_Pa--> muscle, friction
                      ^ x_m, v_m_s               |
    muscle, damping, friction --flange-- load <-- external force

Model inputs: ``valve_command`` and ``supply_pressure_gauge_Pa`` (valve source) or
``prescribed_pressure_gauge_Pa`` (prescribed source), and ``external_force_N``.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..components.element import kept_component
from ..components.hanging_load import LoadMode
from ..components import (Chamber, CoulombFriction, ExternalForce, HangingLoad, MuscleStaticForce,
                          PressureSignal, ProportionalValve, SuppliedValve, ViscousDamping)
from ..components.pwm_valve import AveragedPwmValve
from ..components.spool_valve import SpoolValve
from ..components.valve_pair import ValvePair
from ..elements.pressure_source import LineValveSource, PrescribedPressure, ValveChamberSource
from ..elements.pwm_average import AveragedPwmSource
from ..elements.spool import SpoolValveSource
from ..elements.valve_pair import ValvePairSource
from ..modeling import Assembly, AssemblyError
from ..modeling.pygen import compiled_by_mode, outputs_by_mode
from ..signals import Constant



@dataclass(frozen=True)
class SourceParts:
    """The components of a pressure source, their wiring (to each other and to ``load.x_m``,
    ``load.v_m_s``), the model inputs they take, in the order of the source's ``inputs(t)``, and the
    component whose output ``p_gauge_Pa`` is the muscle's pressure."""

    parts: list
    wiring: list
    inputs: dict
    pressure: str


@dataclass(frozen=True)
class AddedComponent:
    """A component added to the rig, and what its ports and inputs connect to (``{"flange": "load.flange"}``:
    a port or input of its own, then a port or output of the rig or of another added component)."""

    component: Any
    connect: dict


def one_muscle_assembly(model, x0_m: float = 0.0, p0_gauge_Pa: float | None = None,
                        stick_margin_N: float = 1e-7, release_margin_N: float = 2e-7,
                        added: tuple = (), friction_direction: str = "load.slip_direction") -> Assembly:
    """The assembly of a :class:`pamsim.model.MuscleModel`'s elements (its static force, friction,
    damping, load, stops and pressure source), starting at rest at ``x0_m`` with the chamber at
    ``p0_gauge_Pa`` (ambient if None).  The margins are the simulator's
    (:class:`pamsim.simulator.SolverOptions`).  The pressure source's components come from
    :data:`SOURCE_PARTS`; ``added`` (:class:`AddedComponent` s) come after the rig's own, so the
    rig's states and outputs keep their places.  ``friction_direction`` is the output that gives the
    friction its direction: the load's (+1 or -1 sliding, 0 held), or an added component's (a
    linearisation's smooth treatment of the Coulomb term)."""
    load = kept_component(HangingLoad, "load", {
        "mass_kg": model.load.mass_kg, "g_m_s2": model.load.g_m_s2, "x_low_m": model.stops.x_low_m,
        "x_high_m": model.stops.x_high_m, "restitution": model.stops.restitution,
        "min_rebound_speed_m_s": model.stops.min_rebound_speed_m_s,
        "stick_margin_N": stick_margin_N, "release_margin_N": release_margin_N, "initial_contraction_m": x0_m})
    # Kept components: a sweep's cases differ in a few numbers, and making a component costs more than its key.
    forces = (kept_component(MuscleStaticForce, "muscle", model.static_force),
              kept_component(CoulombFriction, "friction", model.friction),
              kept_component(ViscousDamping, "damping", model.damping))
    return rig_assembly(load, source_parts(model.source, p0_gauge_Pa), forces, added, friction_direction)


def rig_assembly(load: HangingLoad, source: "SourceParts", forces: tuple, added: tuple = (),
                 friction_direction: str = "load.slip_direction", name: str = "one_muscle") -> Assembly:
    """The rig's assembly from its components: the ``load``, the pressure ``source``'s parts, and
    ``forces``, the components named ``muscle``, ``friction`` and ``damping`` on the load's flange
    (any with the ports and variables of :class:`MuscleStaticForce`, :class:`CoulombFriction` and
    :class:`ViscousDamping`); ``added`` and ``friction_direction`` as :func:`one_muscle_assembly`
    takes them."""
    parts = [load, *source.parts]
    pressure, wiring, inputs = source.pressure, list(source.wiring), dict(source.inputs)
    parts += [*forces, kept_component(ExternalForce, "external")]
    # The flange adds the forces in this order, as pamsim always has: static, damping, friction.
    wiring += [("load.flange", "muscle.flange"), ("load.flange", "damping.flange"), ("load.flange", "friction.flange"),
               (f"{pressure}.p_gauge_Pa", "muscle.p_gauge_Pa"), (f"{pressure}.p_gauge_Pa", "friction.p_gauge_Pa"),
               ("load.mass_kg", "friction.mass_kg"), (friction_direction, "friction.direction"),
               ("friction.level_N", "load.friction_level_N"), ("external.F_external_N", "load.F_external_N"),
               ("load.v_m_s", "external.v_m_s")]
    inputs["external_force_N"] = "external.F_N"
    if any(target == "chamber.port" for extra in added for target in extra.connect.values()):
        wiring = unsettled(wiring)
    for extra in added:
        parts.append(extra.component)
        for own, target in extra.connect.items():
            if "." in target:
                wiring.append((target, f"{extra.component.name}.{own}"))
            else:
                drive_input(inputs, target, f"{extra.component.name}.{own}")
    return Assembly(parts, wiring, inputs, name=name)


def unsettled(wiring: list, chamber: str = "chamber") -> list:
    """``wiring`` with the chamber (the component ``chamber``) settling onto its own pressure (not at all)
    instead of its valve's: an added component feeds it too (a tube from a reservoir), so the pressure it
    approaches is not the valve's supply pressure, and settling onto that would make air."""
    own = (f"{chamber}.p_abs_Pa", f"{chamber}.p_settle_abs_Pa")
    return [own if b == own[1] else (a, b) for a, b in wiring]


def drive_input(inputs: dict, model_input: str, ref: str) -> None:
    """Let the model input ``model_input`` drive the component input ``ref`` too (a connection's target
    without a component: one of the rig's model inputs, such as a supply's set pressure)."""
    if model_input not in inputs:
        raise AssemblyError(f"connection of {ref}: {model_input!r} is neither a component's port or output "
                            f"(\"name.port\") nor a model input of the rig ({', '.join(inputs)})")
    drives = inputs[model_input]
    inputs[model_input] = ((drives,) if isinstance(drives, str) else tuple(drives)) + (ref,)


VALVE_CHAMBER_WIRING = (("chamber.port", "valve.port"), ("load.x_m", "chamber.x_m"), ("load.v_m_s", "chamber.v_m_s"),
                        ("valve.p_settle_abs_Pa", "chamber.p_settle_abs_Pa"))
"""How a ``chamber`` on the load's flange and the ``valve`` that fills it are wired."""


def _chamber_and_valve(src: ValveChamberSource, p0_gauge_Pa: float | None, valve_class, command: str) -> SourceParts:
    """The ``chamber`` of ``src`` and its ``valve`` (a component of ``valve_class`` around ``src.valve``), the
    valve's first input taking the model input named ``command``."""
    return SourceParts(
        [kept_component(Chamber, "chamber", src.chamber, src.p_atm_Pa, p0_gauge_Pa or 0.0,
                        src.chamber.start_temperature_K(src.T_supply_K)),
         kept_component(valve_class, "valve", src.valve, src.T_supply_K, src.p_atm_Pa, src.chamber.R_J_per_kg_K)],
        list(VALVE_CHAMBER_WIRING),
        {command: f"valve.{valve_class.inputs[0].name}", "supply_pressure_gauge_Pa": "valve.supply_gauge_Pa"}, "chamber")


def _valve_parts(src: ValveChamberSource, p0_gauge_Pa: float | None) -> SourceParts:
    return _chamber_and_valve(src, p0_gauge_Pa, ProportionalValve, "valve_command")


def _averaged_pwm_parts(src: AveragedPwmSource, p0_gauge_Pa: float | None) -> SourceParts:
    return _chamber_and_valve(src, p0_gauge_Pa, AveragedPwmValve, "pwm_duty")


def _spool_parts(src: SpoolValveSource, p0_gauge_Pa: float | None) -> SourceParts:
    """The chamber and the spool valve that fills it, or that discharges into ``src.outlet_port`` (a tube's
    inlet), where the chamber settles onto its own pressure (see :func:`_line_valve_parts`)."""
    plain = _chamber_and_valve(src, p0_gauge_Pa, SpoolValve, "valve_command")
    if not src.outlet_port:
        return plain
    wiring = [(src.outlet_port, "valve.port"), ("load.x_m", "chamber.x_m"), ("load.v_m_s", "chamber.v_m_s"),
              ("chamber.p_abs_Pa", "chamber.p_settle_abs_Pa")]
    return SourceParts(plain.parts, wiring, plain.inputs, "chamber")


def _valve_pair_parts(src: ValvePairSource, p0_gauge_Pa: float | None) -> SourceParts:
    """The chamber and the two 2/2 valves that fill and vent it: the model input ``valve_command`` drives the
    inlet, ``exhaust_command`` the exhaust."""
    plain = _chamber_and_valve(src, p0_gauge_Pa, ValvePair, "valve_command")
    inputs = {"valve_command": "valve.inlet_command", "exhaust_command": "valve.exhaust_command",
              "supply_pressure_gauge_Pa": "valve.supply_gauge_Pa"}
    return SourceParts(plain.parts, plain.wiring, inputs, "chamber")


def _line_valve_parts(src: LineValveSource, p0_gauge_Pa: float | None) -> SourceParts:
    """The valve and chamber of a line: the valve's supply side on ``src.supply_port`` (if given), its outlet
    on ``src.outlet_port`` (if given, else the chamber).  The chamber settles onto its valve's pressure only
    where that valve feeds it directly from a supply input, as :func:`_valve_parts` wires it; otherwise the
    pressure it approaches is a volume's that moves (a tube's, a reservoir's), and it settles onto its own
    pressure, that is not at all."""
    plain = _valve_parts(src, p0_gauge_Pa)
    if not (src.supply_port or src.outlet_port):
        return plain
    chamber, valve = plain.parts
    inputs = dict(plain.inputs)
    if src.supply_port:
        valve = kept_component(SuppliedValve, "valve", src.valve, src.T_supply_K, src.p_atm_Pa,
                               src.chamber.R_J_per_kg_K)
        inputs["supply_pressure_gauge_Pa"] = ()
    wiring = [(src.outlet_port or "chamber.port", "valve.port"), ("load.x_m", "chamber.x_m"),
              ("load.v_m_s", "chamber.v_m_s"), ("chamber.p_abs_Pa", "chamber.p_settle_abs_Pa")]
    if src.supply_port:
        wiring.append((src.supply_port, "valve.supply"))
    return SourceParts([chamber, valve], wiring, inputs, "chamber")


def _prescribed_parts(src: PrescribedPressure, p0_gauge_Pa: float | None) -> SourceParts:
    return SourceParts([kept_component(PressureSignal, "pressure")], [], {"prescribed_pressure_gauge_Pa": "pressure.p_in_gauge_Pa"},
                       "pressure")


SOURCE_PARTS: dict[type, Callable[[Any, float | None], SourceParts]] = {
    ValveChamberSource: _valve_parts, LineValveSource: _line_valve_parts, AveragedPwmSource: _averaged_pwm_parts,
    SpoolValveSource: _spool_parts, ValvePairSource: _valve_pair_parts, PrescribedPressure: _prescribed_parts}
"""``{pressure source class: parts(source, initial gauge pressure or None)}``.  A source defined above
this layer (a controller's) registers its own with :func:`register_source`."""


def register_source(cls: type, parts: Callable[[Any, float | None], SourceParts]) -> None:
    """Let ``one_muscle_assembly`` build a muscle driven by pressure sources of class ``cls``."""
    SOURCE_PARTS[cls] = parts


def source_parts(src, p0_gauge_Pa: float | None) -> SourceParts:
    """The components of pressure source ``src`` (:data:`SOURCE_PARTS`, by its class or a base class), its
    chamber at ``p0_gauge_Pa`` at the start (None: the source's own)."""
    for cls in type(src).__mro__:
        if cls in SOURCE_PARTS:
            return SOURCE_PARTS[cls](src, p0_gauge_Pa)
    raise TypeError(f"no components for the pressure source {type(src).__name__} "
                    f"(pamsim.assemblies.one_muscle.register_source names them)")


def rewired(source: SourceParts, node: str, prefix: str = "", others: tuple[str, ...] = ()) -> SourceParts:
    """``source``'s parts reading from component ``node`` what they read from the rig's load (its
    ``x_m`` and ``v_m_s``), renamed ``<prefix>_<name>`` if ``prefix`` is given, with their wiring and
    inputs; a reference to one of the components ``others`` (a line the valve feeds) is renamed alike."""
    names = {c: f"{prefix}_{c}" if prefix else c for c in others}
    names.update({c.name: f"{prefix}_{c.name}" if prefix else c.name for c in source.parts})
    parts = []
    for c in source.parts:
        renamed = copy.copy(c)
        renamed.name = names[c.name]
        parts.append(renamed)

    def ref(r: str) -> str:
        owner, _, rest = r.partition(".")
        if owner == "load":
            return f"{node}.{rest}"
        return f"{names.get(owner, owner)}.{rest}"

    wiring = [(ref(a), ref(b)) for a, b in source.wiring]
    inputs = {k: tuple(ref(v) for v in ((vs,) if isinstance(vs, str) else vs)) for k, vs in source.inputs.items()}
    return SourceParts(parts, wiring, {k: v[0] if len(v) == 1 else v for k, v in inputs.items()}, names[source.pressure])


def input_signals(model) -> dict:
    """The signals of the model inputs of ``model``'s assembly, by the flat model's names and in its order:
    the pressure source's (its ``signals``, named by its :class:`SourceParts`), then the external force."""
    names = source_parts(model.source, None).inputs
    external = model.load.external_force_N
    return {**dict(zip(names, model.source.signals)),
            "external_force_N": external if external is not None else Constant(0.0)}


_STICK = int(LoadMode.STICK)

RIG_COMPONENTS = frozenset({"load", "muscle", "friction", "damping", "external", "chamber", "valve", "pressure",
                            "controller"})
"""The rig's own components (every pressure source's included); any other was added to it."""

RUN_FUNCTIONS = ("f", "y", "z", "transition", "rest_mode", "x0")
"""The generated functions a run uses (one set per load mode, shared by the backends through
:func:`pamsim.modeling.pygen.compiled_by_mode`'s cache)."""

OUTPUT_COLUMNS = {"muscle.F_static_N": "F_static_N", "load.F_friction_N": "F_friction_N",
                  "damping.F_damping_N": "F_damping_N", "load.F_gravity_N": "F_gravity_N",
                  "external.F_external_N": "F_external_N", "load.F_stop_N": "F_stop_N",
                  "load.F_coulomb_level_N": "F_coulomb_level_N", "valve.mass_flow_kg_s": "valve_mass_flow_kg_s",
                  "chamber.gas_temperature_K": "gas_temperature_K", "chamber.wall_heat_W": "wall_heat_W",
                  "chamber.wall_area_m2": "wall_area_m2"}
"""The rig's outputs under the names results have always given them, in the order of their columns
(an output of a component added to the rig keeps its namespaced name); the last two are the thermal
chamber's alone."""


class RigOutputs:
    """The generated outputs of a run of the rig, computed when first asked for: at the samples (``t``,
    states ``Y`` one row per state, ``modes``), and at rest at the end."""

    def __init__(self, assembly: Assembly, model, t, Y, modes):
        self.code = compiled_by_mode(assembly, "load", RUN_FUNCTIONS)
        self.p = assembly.parameter_values()
        self.added = {c.name for c in assembly.components} - RIG_COMPONENTS
        self.added_states = [f"{c.name}.{v.name}" for c in assembly.components if c.name in self.added for v in c.states]
        self.model, self.t, self.Y, self.modes = model, t, Y, modes

    def inputs(self, t):
        """The model inputs at times ``t``, in the flat model's order: the source's, then the external force."""
        return [*self.model.source.inputs(t), self.model.load.external_N(t)]

    def sampled(self) -> dict:
        """``{column: array at the samples}``: the rig's outputs under :data:`OUTPUT_COLUMNS`' names, and
        every output of a component added to the rig under its namespaced name."""
        out = outputs_by_mode(self.code, self.p, list(self.Y), self.inputs(self.t), self.modes)
        columns = {column: out[name] for name, column in OUTPUT_COLUMNS.items() if name in out}
        columns.update({name: values for name, values in out.items() if name.split(".", 1)[0] in self.added})
        return columns

    def rest_forces(self) -> tuple[float, float]:
        """Net force on the load at rest at the last sample, and the Coulomb level [N] there."""
        code = self.code[_STICK]
        y = [float(v) for v in self.Y[:, -1]]
        y[1] = 0.0
        (out,) = code.y(y, [float(np.asarray(v)) for v in self.inputs(float(self.t[-1]))], self.p, ())
        names = code.names["outputs"]
        return float(out[names.index("load.F_net_N")]), float(out[names.index("load.F_coulomb_level_N")])


def scenario_assembly(scenario, model=None) -> Assembly:
    """The assembly of a :class:`pamsim.scenario.Scenario`: its model (``model``, if given, in its place:
    one with another pressure source), start, the solver's margins and the components it adds."""
    opts = scenario.solver
    return one_muscle_assembly(model or scenario.build_model(), scenario.initial_contraction_m,
                               scenario.initial_pressure_gauge_Pa, opts.stick_margin_N, opts.release_margin_N,
                               scenario.added_components)
