"""A muscle alone, its length and lengthening velocity given, its force read back: the muscle of a rig
whose mechanics another tool owns.

::

    valve --port-- chamber --p_gauge_Pa--> muscle, friction
                      ^ x_m, v_m_s               |
    muscle, damping, friction --flange-- motion <-- length_m, lengthening_velocity_m_s

Model inputs: the pressure source's (``valve_command`` and ``supply_pressure_gauge_Pa``, or
``prescribed_pressure_gauge_Pa``), then ``length_m`` and ``lengthening_velocity_m_s``.  The force is the
output ``motion.F_N``.

On an elastic tendon (``tendon_stiffness_N_per_m``) the length given is the tendon's path, and a
:class:`~pamsim.components.series_tendon.SeriesTendon` named ``series_spring`` sits between it and the muscle,
whose end (its contraction the state ``series_spring.x_m``) is massless: the muscle's static force, damping
and friction, and whatever is added on the load, act there, and ``motion.F_N`` is the tendon's pull.
"""

from __future__ import annotations

from ..components import CoulombFriction, MuscleStaticForce, ViscousDamping
from ..components.prescribed_motion import PrescribedMotion
from ..components.series_tendon import MuscleEndDamping, SeriesTendon, end_wiring
from ..modeling import Assembly
from .one_muscle import rewired, source_parts

MOTION_INPUTS = {"length_m": "motion.length_m", "lengthening_velocity_m_s": "motion.velocity_m_s"}
"""The model inputs that move the muscle, and the component inputs they drive."""


MUSCLE_ONLY_COMPONENTS = frozenset({"motion", "series_spring"})
"""The names of this assembly's own components beyond the one-muscle rig's
(:data:`pamsim.assemblies.one_muscle.RIG_COMPONENTS`): a component added to a muscle cannot take them,
since a scenario's muscle may be run alone on a length, or coupled to another tool through this assembly."""


LOAD_TO_MOTION = {"load.flange": "motion.flange", "load.x_m": "motion.x_m", "load.v_m_s": "motion.v_m_s",
                  "load.mass_kg": "motion.load_mass_kg"}
"""What a component added to the rig reads of its load, on a muscle alone (the load's mass: the one the
friction law reads there, the static force over g)."""


LOAD_TO_SPRING = {"load.flange": "series_spring.others", "load.x_m": "series_spring.x_m",
                  "load.v_m_s": "series_spring.v_m_s",
                  "load.mass_kg": "motion.load_mass_kg"}
"""The same on an elastic tendon: what is added on the load acts on the muscle's end, the spring's node."""


def muscle_only_assembly(model, L0_m: float, g_m_s2: float, p0_gauge_Pa: float | None = None,
                         added: tuple = (), tendon_stiffness_N_per_m: float | None = None) -> Assembly:
    """The muscle of ``model`` (a :class:`pamsim.model.MuscleModel`: its static force, friction, damping and
    pressure source; its load and stops are not used) of rest length ``L0_m``, its chamber at
    ``p0_gauge_Pa`` at the start (None: the source's own), with the components ``added`` to it
    (:class:`pamsim.assemblies.one_muscle.AddedComponent` s, a scenario's hysteresis among them), their
    connections to the load read as :data:`LOAD_TO_MOTION` says; on a tendon of stiffness
    ``tendon_stiffness_N_per_m`` (None: rigid) as the module's docstring says, and :data:`LOAD_TO_SPRING`.

    Raises
    ------
    ValueError
        For an added component wired to a part of the load a muscle alone does not have, or one that cannot
        act on a massless end (a Maxwell-slip element's presliding damping); on an elastic tendon, for a
        damping law whose force does not grow with speed through zero (the paper's ``D1 < 0``, or none).
    """
    elastic = tendon_stiffness_N_per_m is not None
    end, load = ("series_spring", LOAD_TO_SPRING) if elastic else ("motion", LOAD_TO_MOTION)
    source = rewired(source_parts(model.source, p0_gauge_Pa), end)
    parts = [PrescribedMotion("motion", {"L0_m": L0_m, "g_m_s2": g_m_s2}), *source.parts,
             MuscleStaticForce("muscle", model.static_force), CoulombFriction("friction", model.friction),
             (MuscleEndDamping if elastic else ViscousDamping)("damping", model.damping)]
    p = f"{source.pressure}.p_gauge_Pa"
    wiring = list(source.wiring)
    if elastic:
        parts.append(SeriesTendon(end, {"k_N_per_m": tendon_stiffness_N_per_m}))
        wiring += [(f"{end}.path", "motion.flange"), *end_wiring(end, "muscle", "friction", "damping")]
    # The flange adds the forces in the one-muscle rig's order: static, damping, friction.
    wiring += [(f"{end}.flange", "muscle.flange"), (f"{end}.flange", "damping.flange"),
               (f"{end}.flange", "friction.flange"), (p, "muscle.p_gauge_Pa"), (p, "friction.p_gauge_Pa"),
               ("motion.load_mass_kg", "friction.mass_kg"), (f"{end}.direction", "friction.direction"),
               ("muscle.F_static_N", "motion.F_static_N")]
    for extra in added:
        component = extra.component
        if elastic and hasattr(component, "on_massless_end"):
            component = component.on_massless_end()
        parts.append(component)
        for own, target in extra.connect.items():
            if target.startswith("load.") and target not in load:
                raise ValueError(f"component {component.name!r}: {own} = {target!r}: a muscle alone has no load; "
                                 f"it offers {', '.join(load)}")
            wiring.append((load.get(target, target), f"{component.name}.{own}"))
    return Assembly(parts, wiring, {**source.inputs, **MOTION_INPUTS}, name="muscle_only")
