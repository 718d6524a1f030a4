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
from dataclasses import dataclass
from typing import Any

from ..components import CoulombFriction, MuscleStaticForce, ViscousDamping
from ..components.linear_slider import LinearSlider
from ..components.pulley import LeverAttachment, Pulley, SliderTendon
from ..components.rotary_joint import RotaryJoint
from ..components.series_tendon import MuscleEndDamping, SeriesTendon
from ..modeling import Assembly
from .one_muscle import rewired, source_parts

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
    s: its ``[hysteresis]``), renamed ``<muscle>_<name>``."""


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
    source = rewired(source_parts(m.source, m.p0_gauge_Pa), pulley, m.name)
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
                   (f"{m.name}_friction.level_N", f"{spring}.friction_level_N"),
                   (f"{m.name}_muscle.F_static_N", f"{spring}.F_static_N"),
                   (f"{spring}.F_free_N", f"{m.name}_damping.F_free_N"),
                   (f"{m.name}_damping.v_free_m_s", f"{spring}.v_free_m_s")]
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
    extra, extra_wiring = _added_parts(m, source, node, friction_load or f"{pulley}.load_mass_kg")
    inputs = {f"{m.name}.{k}": v for k, v in source.inputs.items()}
    return parts + extra, wiring + extra_wiring, inputs


def _added_parts(m: JointMuscle, source, node: str, mass: str) -> tuple[list, list]:
    """The components on muscle ``m``, renamed after it, what they read of the rig's load read of the muscle's
    flange node ``node`` and the friction's load ``mass``, and of its pressure source of the muscle's own."""
    own = {c.name.removeprefix(f"{m.name}_"): c.name for c in source.parts}  # "chamber" -> "<muscle>_chamber"
    load = {"load.flange": f"{node}.flange", "load.x_m": f"{node}.x_m", "load.v_m_s": f"{node}.v_m_s",
            "load.mass_kg": mass}
    parts, wiring = [], []
    for a in m.added:
        c = copy.copy(a.component)
        c.name = f"{m.name}_{a.component.name}"
        parts.append(c)
        for port, target in a.connect.items():
            owner, _, rest = target.partition(".")
            if target in load:
                target = load[target]
            elif owner in own:
                target = f"{own[owner]}.{rest}"
            else:
                raise ValueError(f"muscle {m.name!r}: component {a.component.name!r}: {port} = {target!r}: on a joint "
                                 f"it reads {', '.join(load)} and its pressure source")
            wiring.append((target, f"{c.name}.{port}"))
    return parts, wiring
