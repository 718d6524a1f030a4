"""The exact stick/slip and end-stop mode machine of a body with one degree of freedom, written once.

A hanging load (a position along a line) and a rotary joint (an angle) move the same way: they slide
under the net force (torque) of everything on them, or are held, by friction or on a stop; they stop
at a stop with a rebound or none, stick where their velocity reaches zero and friction can hold them,
and are released when the net force beats friction.  :func:`stick_slip` writes those modes' equations
for a body whose net force and Coulomb level its component has summed; the component names them.

The modes are :class:`BodyMode`'s values (docs/model.md sec. 4 gives the rules).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import Any

from ..modeling.smath import if_else


class BodyMode(IntEnum):
    """Friction / contact mode of a body with one degree of freedom (``SLIP_UP``: its position grows)."""

    SLIP_DOWN = -1
    STICK = 0
    SLIP_UP = 1
    STOP_LOW = 2
    STOP_HIGH = 3

    @property
    def is_slip(self) -> bool:
        """Whether the body slides in this mode (up or down)."""
        return self in (BodyMode.SLIP_UP, BodyMode.SLIP_DOWN)

    @property
    def label(self) -> str:
        """The mode's name in results and events (``slip_up``, ``stick``...)."""
        return self.name.lower()


EVENT_NAMES = {
    BodyMode.SLIP_UP: ("velocity_zero", "stop_high"),
    BodyMode.SLIP_DOWN: ("velocity_zero", "stop_low"),
    BodyMode.STICK: ("release_up", "release_down"),
    BodyMode.STOP_LOW: ("release_up", None),
    BodyMode.STOP_HIGH: (None, "release_down"),
}
"""What a crossing of each indicator means in each mode (None: that indicator never crosses there)."""


def event_name(mode: BodyMode, fired: int, to: BodyMode, others: tuple[str, ...] = ()) -> str:
    """The name of an event that left ``mode`` for ``to`` with the indicators in the bit mask ``fired``:
    a stop reached takes precedence over a velocity reaching zero (as in the transition), and a
    release is named by the direction the body takes.  Bits past the body's two are the indicators of
    other components, named ``others`` (an element's slip): an event of theirs alone takes its name."""
    if not fired & 3 and fired >> 2 and mode == to:
        return others[(fired >> 2).bit_length() - 1]
    if mode.is_slip:
        return EVENT_NAMES[mode][1] if fired & 2 else EVENT_NAMES[mode][0]
    return "release_up" if to == BodyMode.SLIP_UP else "release_down"


@dataclass(frozen=True)
class Contact:
    """A body's stops and the rules at them and at rest (each a number or a symbol).

    ``low``, ``high``: the stops; ``restitution``: the rebound's share of the speed at a stop, none
    below ``min_rebound``; ``stick_margin``: a stopping body is held unless the net force beats friction
    by more; ``release_margin``: a held body is released when the net force beats friction by this;
    ``v_tol``, ``pos_tol``: the shifts of the velocity and stop indicators for an integrator that cannot
    tell a segment's start from a crossing (:attr:`pamsim.modeling.Equations.indicator_margins`)."""

    low: Any
    high: Any
    restitution: Any
    min_rebound: Any
    stick_margin: Any
    release_margin: Any
    v_tol: float
    pos_tol: float


@dataclass(frozen=True)
class BodyEquations:
    """:func:`stick_slip`'s equations: the velocity the body reports (zero when held) and its
    acceleration; indicators, their margins, the mode decided at rest, the jump at an event (position,
    velocity, mode); the friction that acts on it (when held, whatever holds it), the reaction of a
    stop, and the starting mode."""

    v_reported: Any
    accel: Any
    indicators: tuple
    margins: tuple
    rest_mode: Any
    jump_pos: Any
    jump_vel: Any
    jump_mode: Any
    friction: Any
    stop_reaction: Any
    slip_direction: Any
    initial_mode: Any


def stick_slip(q, pos, vel, net, level, inertia, contact: Contact, fired: tuple, pos0) -> BodyEquations:
    """The modes of a body at ``pos`` moving at ``vel`` in mode ``q``, with Coulomb level ``level`` (>= 0)
    and ``inertia`` (mass or moment of inertia), under the net force ``net``: the sum of the forces on
    it, friction's ``-q level`` included while it slides and none while it is held (it is then at rest,
    and friction holds whatever it must).  ``fired`` flags the indicators that crossed (at an event);
    ``pos0`` is where it starts, at rest."""
    M = BodyMode
    slip = q * q == 1
    up = q == M.SLIP_UP
    low, high = q == M.STOP_LOW, q == M.STOP_HIGH
    v_reported = if_else(slip, vel, 0.0)
    accel = if_else(slip, net / inertia, 0.0)
    eps = contact.release_margin
    z_slip = (if_else(up, vel, -vel), if_else(up, contact.high - pos, pos - contact.low))
    z_held = (if_else(high, 1.0, level + eps - net), if_else(low, 1.0, level + eps + net))
    indicators = tuple(if_else(slip, a, b) for a, b in zip(z_slip, z_held))
    margins = (if_else(slip, contact.v_tol, 0.0), if_else(slip, contact.pos_tol, 0.0))
    margin = contact.stick_margin
    rest = if_else(slip, q, if_else((1 - high) * (net - level > margin), float(M.SLIP_UP),
                                    if_else((1 - low) * (-net - level > margin), float(M.SLIP_DOWN), q)))
    at_stop = slip * fired[1]
    stopped = slip * (1 - at_stop) * fired[0]
    rebound = contact.restitution * abs(vel)
    bounces = rebound > contact.min_rebound
    jump_pos = if_else(at_stop, if_else(up, contact.high, contact.low), pos)
    jump_vel = if_else(at_stop, if_else(bounces, if_else(up, -rebound, rebound), 0.0), if_else(stopped, 0.0, vel))
    jump_mode = if_else(at_stop, if_else(bounces, -q, if_else(up, float(M.STOP_HIGH), float(M.STOP_LOW))),
                        if_else(stopped, float(M.STICK), q))
    held_by_friction = (q == M.STICK) + low * (net > 0.0) + high * (net < 0.0)
    on_stop = low * (net <= 0.0) + high * (net >= 0.0)
    return BodyEquations(
        v_reported=v_reported, accel=accel, indicators=indicators, margins=margins, rest_mode=rest,
        jump_pos=jump_pos, jump_vel=jump_vel, jump_mode=jump_mode,
        friction=if_else(slip, -q * level, if_else(held_by_friction, -net, 0.0)),
        stop_reaction=if_else(on_stop, -net, 0.0), slip_direction=if_else(slip, q, 0.0),
        initial_mode=if_else(pos0 <= contact.low, float(M.STOP_LOW),
                             if_else(pos0 >= contact.high, float(M.STOP_HIGH), float(M.STICK))))
