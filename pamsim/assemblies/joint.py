"""Muscles on a rotary joint: an antagonistic pair, or any number, each on its own pulley.

::

    flexor_valve -- flexor_chamber --p--> flexor_muscle, flexor_friction
                                              | flange
    flexor_muscle, flexor_damping, flexor_friction -- flexor_pulley --shaft-- joint -- extensor_pulley ...

Each muscle brings its own static force, friction, damping and pressure source (any of the one-muscle
rig's: a valve and chamber, a prescribed pressure), its components named after it
(``flexor_chamber.p_gauge_Pa``).  Model inputs: each muscle's source inputs, prefixed with its name
(``flexor.valve_command``), and the joint's ``tau_external_Nm``.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace
from typing import Any

from ..components import CoulombFriction, MuscleStaticForce, ViscousDamping
from ..components.linear_slider import LinearSlider
from ..components.pulley import LeverAttachment, Pulley, SliderTendon
from ..components.rotary_joint import RotaryJoint
from ..components.series_tendon import MuscleEndDamping, SeriesTendon, end_wiring
from ..elements.pressure_source import PrescribedPressure
from ..modeling import Assembly
from ..signals import Constant
from .one_muscle import AddedComponent, drive_input, rewired, source_parts, unsettled

@dataclass(frozen=True)
class JointMuscle:
    """One muscle on the joint: its ``name`` (an identifier, the prefix of its components), its
    elements (``static_force``, ``friction``, ``damping``, pressure ``source``, as a
    :class:`pamsim.model.MuscleModel` holds them), its pulley (``radius_m``, ``side`` +1 or -1,
    contraction ``x_at_zero_m`` at angle zero) or lever (``lever``), and its chamber's initial gauge pressure
    (``p0_gauge_Pa``, None: ambient)."""

    name: str
    static_force: Any
    friction: Any
    damping: Any
    source: Any
    radius_m: float
    side: float
    x_at_zero_m: float
    p0_gauge_Pa: float | None = None
    lever: dict | None = None
    """A lever attachment's parameters (:class:`pamsim.components.pulley.LeverAttachment`, ``side`` and
    ``g_m_s2`` aside) in place of the pulley (``radius_m`` and ``x_at_zero_m`` then unused)."""
    tendon_stiffness_N_per_m: float | None = None
    """The stiffness of a spring in series with the muscle (:class:`pamsim.components.series_tendon.SeriesTendon`);
    None: a rigid tendon."""
    added: tuple = ()
    """Components on the muscle, wired as on the one-muscle rig's load (:class:`pamsim.assemblies.one_muscle.AddedComponent`
    s: its ``[hysteresis]`` and ``[[component]]`` tables), renamed ``<muscle>_<name>``."""


def at_prescribed_pressure(m: JointMuscle) -> JointMuscle:
    """Muscle ``m`` with its pressure a model input (a prescribed pressure, as the statics, the linearisation
    and the stiffness controller take it).  A component of the muscle's that reads its source's pressure reads
    the prescribed one; one wired into the source otherwise (a tube, a reservoir, a supply: the pneumatics the
    prescribed pressure replaces) is left out, with whatever is wired to it in turn."""
    old = source_parts(m.source, None)
    prescribed = PrescribedPressure(Constant(0.0))
    new = source_parts(prescribed, None)
    own, pressure = {c.name for c in old.parts}, f"{old.pressure}.p_gauge_Pa"
    kept = list(m.added)
    # What the source's own wiring reaches besides itself (the reservoir a valve draws from, the tube it feeds).
    dropped = {ref.partition(".")[0] for pair in old.wiring for ref in pair} - own - {"load"}

    def pneumatic(a) -> bool:
        if a.component.name in dropped:
            return True
        for target in a.connect.values():
            owner, dot, _ = target.partition(".")
            if (owner in own and target != pressure) or owner in dropped or (not dot and target not in new.inputs):
                return True
        return False

    while any(pneumatic(a) for a in kept):
        for a in [a for a in kept if pneumatic(a)]:
            kept.remove(a)
            dropped.add(a.component.name)
    added = tuple(AddedComponent(a.component, {k: f"{new.pressure}.p_gauge_Pa" if t == pressure else t
                                               for k, t in a.connect.items()}) for a in kept)
    return replace(m, source=prescribed, added=added)


def attachment_name(m: JointMuscle, body: str = "joint") -> str:
    """The name of the component that attaches muscle ``m`` to the ``body``: on a joint ``<muscle>_pulley``
    or ``<muscle>_lever``, on a slider ``<muscle>_tendon``."""
    if body == "slider":
        return f"{m.name}_tendon"
    return f"{m.name}_lever" if m.lever is not None else f"{m.name}_pulley"


def joint_assembly(joint_values: dict, muscles: tuple[JointMuscle, ...], g_m_s2: float,
                   name: str = "joint") -> Assembly:
    """The assembly of a :class:`RotaryJoint` with parameters ``joint_values`` and ``muscles`` on it.

    Model inputs: each muscle's pressure source inputs as ``<muscle>.<input>``, then
    ``tau_external_Nm``.
    """
    def attach(m: JointMuscle):
        if m.lever is not None:
            return LeverAttachment(attachment_name(m), {**m.lever, "side": m.side, "g_m_s2": g_m_s2})
        return Pulley(attachment_name(m), {"radius_m": m.radius_m, "side": m.side, "x_at_zero_m": m.x_at_zero_m,
                                           "g_m_s2": g_m_s2})

    return _body_assembly(RotaryJoint("joint", joint_values), muscles, attach, "tau_external_Nm", name)


SLIDER_FRICTION_LOADS = ("static_force", "slider_mass")
"""What a slider's muscles' load-dependent friction reads as their load: the mass whose weight is each
muscle's static force (as on a joint), or the slider's own mass (the paper's rig, where the load the
friction law was measured with is the hanging mass)."""


def slider_assembly(slider_values: dict, muscles: tuple[JointMuscle, ...], g_m_s2: float,
                    friction_load: str = "static_force", name: str = "slider") -> Assembly:
    """The assembly of a :class:`LinearSlider` with parameters ``slider_values`` and ``muscles`` on it,
    each on a :class:`SliderTendon` (its ``side`` and ``x_at_zero_m``; ``radius_m`` and ``lever`` unused);
    ``friction_load`` one of :data:`SLIDER_FRICTION_LOADS`.

    Model inputs: each muscle's pressure source inputs as ``<muscle>.<input>``, then ``F_external_N``.
    """
    if friction_load not in SLIDER_FRICTION_LOADS:
        raise ValueError(f"friction_load must be one of {SLIDER_FRICTION_LOADS}, not {friction_load!r}")

    def attach(m: JointMuscle):
        return SliderTendon(attachment_name(m, "slider"), {"side": m.side, "x_at_zero_m": m.x_at_zero_m, "g_m_s2": g_m_s2})

    load = "slider.mass_kg" if friction_load == "slider_mass" else None
    return _body_assembly(LinearSlider("slider", slider_values), muscles, attach, "F_external_N", name, load)


def _body_assembly(body, muscles, attach, external: str, name: str, friction_load: str | None = None) -> Assembly:
    """``body`` with each of ``muscles`` on the attachment ``attach(muscle)`` makes, its external input
    ``external``; the muscles' friction reads its load from ``friction_load`` (None: the attachment's)."""
    parts: list = [body]
    wiring: list = []
    inputs: dict = {}
    for m in muscles:
        own, own_wiring, own_inputs = _muscle_parts(m, attach(m), body, friction_load)
        parts += own
        wiring += own_wiring
        inputs.update(own_inputs)
    inputs[external] = f"{body.name}.{external}"
    return Assembly(parts, wiring, inputs, name=name)


def series_spring_name(m: JointMuscle) -> str:
    """The name of the spring in series with muscle ``m`` (:class:`SeriesTendon`), when its tendon is elastic."""
    return f"{m.name}_series_spring"


def _muscle_parts(m: JointMuscle, attach, body, friction_load: str | None) -> tuple[list, list, dict]:
    """A muscle's components, wiring and model inputs, its components prefixed with its name.

    With a rigid tendon the attachment is the node of the muscle's flange, and the muscle's friction
    reads the body's slip and adds its level to the body's; with an elastic one a :class:`SeriesTendon`
    is, the attachment's flange carries the spring's pull, and the friction reads the muscle's own motion.
    """
    pulley, elastic = attach.name, m.tendon_stiffness_N_per_m is not None
    # The chamber's volume follows the muscle's own end: on an elastic tendon the spring's node, not the path.
    end = series_spring_name(m) if elastic else pulley
    source = rewired(source_parts(m.source, m.p0_gauge_Pa), end, m.name, tuple(a.component.name for a in m.added))
    damping = (MuscleEndDamping if elastic else ViscousDamping)(f"{m.name}_damping", m.damping)
    parts = [*source.parts, MuscleStaticForce(f"{m.name}_muscle", m.static_force),
             CoulombFriction(f"{m.name}_friction", m.friction), damping, attach]
    p = f"{source.pressure}.p_gauge_Pa"
    port = attach.body.name
    node, moves = pulley, f"{pulley}.direction"
    wiring = [*source.wiring, (f"{pulley}.{port}", f"{body.name}.{port}")]
    if elastic:
        node = spring = series_spring_name(m)
        parts.append(SeriesTendon(spring, {"k_N_per_m": m.tendon_stiffness_N_per_m}))
        moves = f"{spring}.direction"
        wiring += [(f"{spring}.path", f"{pulley}.flange"), (f"{spring}.level_on_body_N", f"{pulley}.friction_level_N"),
                   *end_wiring(spring, f"{m.name}_muscle", f"{m.name}_friction", f"{m.name}_damping")]
    else:
        wiring.append((f"{m.name}_friction.level_N", f"{pulley}.friction_level_N"))
    # The flange adds the forces in the one-muscle rig's order: static, damping, friction.
    wiring += [(f"{node}.flange", f"{m.name}_muscle.flange"),
               (f"{node}.flange", f"{m.name}_damping.flange"), (f"{node}.flange", f"{m.name}_friction.flange"),
               (p, f"{m.name}_muscle.p_gauge_Pa"), (p, f"{m.name}_friction.p_gauge_Pa"),
               (friction_load or f"{pulley}.load_mass_kg", f"{m.name}_friction.mass_kg"),
               (moves, f"{m.name}_friction.direction"),
               (f"{m.name}_muscle.F_static_N", f"{pulley}.F_static_N"),
               (f"{body.name}.slip_direction", f"{pulley}.joint_direction")]
    inputs = {f"{m.name}.{k}": v for k, v in source.inputs.items()}
    # On an elastic tendon what is added on the muscle's end joins the spring node's balance (its port others).
    extra, extra_wiring = _added_parts(m, source, node, f"{node}.others" if elastic else f"{node}.flange",
                                       friction_load or f"{pulley}.load_mass_kg", inputs)
    if any(target == "chamber.port" for a in m.added for target in a.connect.values()):
        wiring = unsettled(wiring, f"{m.name}_chamber")
    return parts + extra, wiring + extra_wiring, inputs


def _added_parts(m: JointMuscle, source, node: str, flange: str, mass: str, inputs: dict) -> tuple[list, list]:
    """The components on muscle ``m`` (its ``[hysteresis]``, its lines and reservoirs), renamed after it, wired
    as on the one-muscle rig: what they read of the rig's load read of the muscle's flange node ``node`` (its
    flange port ``flange``) and the friction's load ``mass``; a reference to the rig's muscle, friction,
    damping, pressure source or another of the muscle's components, of the muscle's own; a model input (a
    supply's set pressure), the muscle's own input of that name in ``inputs``, which then drives them too."""
    prefix = f"{m.name}_"
    names = {c.name.removeprefix(prefix): c.name for c in source.parts}  # "chamber" -> "<muscle>_chamber"
    names.update({k: prefix + k for k in ("muscle", "friction", "damping")})
    names.update({a.component.name: prefix + a.component.name for a in m.added})
    load = {"load.flange": flange, "load.x_m": f"{node}.x_m", "load.v_m_s": f"{node}.v_m_s",
            "load.mass_kg": mass}
    parts, wiring = [], []
    massless = flange != f"{node}.flange"
    for a in m.added:
        # on the massless end of an elastic tendon, without forces that read its velocity (MaxwellSlip's damping)
        c = a.component.on_massless_end() if massless and hasattr(a.component, "on_massless_end") else a.component
        c = copy.copy(c)
        c.name = names[a.component.name]
        parts.append(c)
        for port, target in a.connect.items():
            owner, dot, rest = target.partition(".")
            if target in load:
                wiring.append((load[target], f"{c.name}.{port}"))
            elif dot and owner in names:
                wiring.append((f"{names[owner]}.{rest}", f"{c.name}.{port}"))
            elif not dot:
                drive_input(inputs, f"{m.name}.{target}", f"{c.name}.{port}")
            else:
                raise ValueError(f"muscle {m.name!r}: component {a.component.name!r}: {port} = {target!r}: on a joint "
                                 f"it reads {', '.join(load)}, the muscle's own components and its model inputs")
    return parts, wiring
