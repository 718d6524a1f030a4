"""The body the muscles move: a rotary joint, or a linear slider.  Both are bodies with one degree of
freedom, run the same way; this names their variables so that scenarios, runs and results speak of
each in its own units (an angle in rad and torques in N m, a position in m and forces in N)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Body:
    """How a body's variables are named: its component (and scenario table) ``name``, its coordinate
    ``position`` and its rate ``velocity``, the prefix ``effort`` and ``unit`` of the efforts on it
    (``tau_gravity_Nm``, ``F_gravity_N``), what an attachment puts on it (``attach_effort``), and its
    scenario table's limit keys (lower, upper, initial)."""

    name: str
    position: str
    velocity: str
    effort: str
    unit: str
    attach_effort: str
    limit_keys: tuple[str, str, str]
    noun: str

    def effort_name(self, what: str) -> str:
        """The name of one of the efforts on the body: ``effort_name("gravity")`` is ``tau_gravity_Nm``."""
        return f"{self.effort}_{what}_{self.unit}"

    @property
    def external(self) -> str:
        """The model input of the external effort on the body."""
        return self.effort_name("external")

    @property
    def min_key(self) -> str:
        """The key of the smallest value of the coordinate in a result's peaks (``theta_min_rad``)."""
        stem, _, unit = self.position.rpartition("_")
        return f"{stem}_min_{unit}"


JOINT = Body("joint", "theta_rad", "omega_rad_s", "tau", "Nm", "tau_Nm",
             ("theta_min_rad", "theta_max_rad", "initial_angle_rad"), "angle")
"""A rotary joint (:class:`pamsim.components.rotary_joint.RotaryJoint`)."""

SLIDER = Body("slider", "x_m", "v_m_s", "F", "N", "F_N", ("x_min_m", "x_max_m", "initial_position_m"), "position")
"""A linear slider (:class:`pamsim.components.linear_slider.LinearSlider`)."""

BODIES = {b.name: b for b in (JOINT, SLIDER)}
"""The bodies by name (a scenario's ``[joint]`` or ``[slider]`` table)."""
