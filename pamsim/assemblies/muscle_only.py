"""A muscle alone, its length and lengthening velocity given, its force read back: the muscle of a rig
whose mechanics another tool owns.

::

    valve --port-- chamber --p_gauge_Pa--> muscle, friction
                      ^ x_m, v_m_s               |
    muscle, damping, friction --flange-- motion <-- length_m, lengthening_velocity_m_s

Model inputs: the pressure source's (``valve_command`` and ``supply_pressure_gauge_Pa``, or
``prescribed_pressure_gauge_Pa``), then ``length_m`` and ``lengthening_velocity_m_s``.  The force is the
output ``motion.F_N``.
"""

from __future__ import annotations

from ..components import CoulombFriction, MuscleStaticForce, ViscousDamping
from ..components.prescribed_motion import PrescribedMotion
from ..modeling import Assembly
from .one_muscle import rewired, source_parts

MOTION_INPUTS = {"length_m": "motion.length_m", "lengthening_velocity_m_s": "motion.velocity_m_s"}
"""The model inputs that move the muscle, and the component inputs they drive."""


LOAD_TO_MOTION = {"load.flange": "motion.flange", "load.x_m": "motion.x_m", "load.v_m_s": "motion.v_m_s",
                  "load.mass_kg": "motion.load_mass_kg"}
"""What a component added to the rig reads of its load, on a muscle alone (the load's mass: the one the
friction law reads there, the static force over g)."""


def muscle_only_assembly(model, L0_m: float, g_m_s2: float, p0_gauge_Pa: float | None = None,
                         added: tuple = ()) -> Assembly:
    """The muscle of ``model`` (a :class:`pamsim.model.MuscleModel`: its static force, friction, damping and
    pressure source; its load and stops are not used) of rest length ``L0_m``, its chamber at
    ``p0_gauge_Pa`` at the start (None: the source's own), with the components ``added`` to it
    (:class:`pamsim.assemblies.one_muscle.AddedComponent` s, a scenario's hysteresis among them), their
    connections to the load read as :data:`LOAD_TO_MOTION` says.

    Raises
    ------
    ValueError
        For an added component wired to a part of the load a muscle alone does not have.
    """
    source = rewired(source_parts(model.source, p0_gauge_Pa), "motion")
    parts = [PrescribedMotion("motion", {"L0_m": L0_m, "g_m_s2": g_m_s2}), *source.parts,
             MuscleStaticForce("muscle", model.static_force), CoulombFriction("friction", model.friction),
             ViscousDamping("damping", model.damping)]
    p = f"{source.pressure}.p_gauge_Pa"
    # The flange adds the forces in the one-muscle rig's order: static, damping, friction.
    wiring = [*source.wiring, ("motion.flange", "muscle.flange"), ("motion.flange", "damping.flange"),
              ("motion.flange", "friction.flange"), (p, "muscle.p_gauge_Pa"), (p, "friction.p_gauge_Pa"),
              ("motion.load_mass_kg", "friction.mass_kg"), ("motion.direction", "friction.direction"),
              ("muscle.F_static_N", "motion.F_static_N")]
    for extra in added:
        parts.append(extra.component)
        for own, target in extra.connect.items():
            if target.startswith("load.") and target not in LOAD_TO_MOTION:
                raise ValueError(f"component {extra.component.name!r}: {own} = {target!r}: a muscle alone has no load; "
                                 f"it offers {', '.join(LOAD_TO_MOTION)}")
            wiring.append((LOAD_TO_MOTION.get(target, target), f"{extra.component.name}.{own}"))
    return Assembly(parts, wiring, {**source.inputs, **MOTION_INPUTS}, name="muscle_only")
