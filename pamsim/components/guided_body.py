"""A body guided along one coordinate and driven by the branches on its port: a rotary joint's link (an
angle, torques) or a linear slider's carriage (a position, forces).  Their equations are the same but
for the names and the gravity term, and are written once here; the modes are
:func:`pamsim.components.stick_slip.stick_slip`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..modeling import Component, Equations, Symbols
from ..modeling.smath import if_else
from .stick_slip import BodyMode, Contact, stick_slip


@dataclass(frozen=True)
class BodyNames:
    """A guided body's names: its port, coordinate and rate, inertia, the guide's (bearing's) viscous and
    Coulomb parameters, the stops, the rebound and the margins, the start, and the efforts' prefix and
    unit (``tau``, ``Nm``: ``tau_gravity_Nm``; the port carries ``tau_Nm`` and ``tau_level_Nm``)."""

    port: str
    position: str
    velocity: str
    inertia: str
    viscous: str
    coulomb: str
    low: str
    high: str
    min_rebound: str
    stick_margin: str
    release_margin: str
    initial: str
    effort: str
    unit: str

    def effort_name(self, what: str = "") -> str:
        """``tau_Nm``, or with ``what`` ``tau_<what>_Nm``."""
        return f"{self.effort}_{what}_{self.unit}" if what else f"{self.effort}_{self.unit}"


class GuidedBody(Component):
    """Sliding: ``I dv/dt = E + E_gravity - b v - q E_c + E_ext``, with ``E`` the efforts of the branches on
    the port (their muscles' friction ``-q level`` among them while sliding, ``q`` = +1 or -1), the
    gravity effort from :meth:`gravity`, ``b`` and ``E_c`` the guide's viscous and Coulomb friction.
    Held (stuck, or on a stop): the coordinate is constant and the port reports zero velocity.  The
    Coulomb level that decides sticking and release is ``E_c`` plus the branches' levels.

    States ``E_viscous_J``, ``E_coulomb_J`` and ``W_external_J``: the energy the guide dissipates,
    viscous and Coulomb, and the work of the external effort.  A subclass names its variables
    (:attr:`names`, :class:`BodyNames`), declares them, and gives its gravity.
    """

    modes = BodyMode
    n_indicators = 2
    names: BodyNames
    event_tolerances: tuple[float, float]
    """The shifts of the velocity and stop indicators (:class:`pamsim.components.stick_slip.Contact`)."""

    def gravity(self, P, position):
        """The gravity effort on the body at ``position`` and its potential energy [J]."""
        raise NotImplementedError

    def extra_outputs(self, P) -> dict:
        """Outputs of the subclass's own, past the common ones."""
        return {}

    def equations(self, s: Symbols) -> Equations:
        N, P = self.names, s.p
        q, pos, vel = s.mode, s.x[N.position], s.x[N.velocity]
        port = s.port[N.port]
        external = s.u[N.effort_name("external")]
        direction = if_else(q * q == 1, q, 0.0)
        vel_reported = if_else(q * q == 1, vel, 0.0)
        gravity, potential = self.gravity(P, pos)
        viscous = -P[N.viscous] * vel_reported
        # The branches' efforts hold their muscles' friction while sliding; the guide's is added here.
        net = port[N.effort_name()] + gravity + viscous - direction * P[N.coulomb] + external
        level = port[N.effort_name("level")] + P[N.coulomb]
        contact = Contact(P[N.low], P[N.high], P["restitution"], P[N.min_rebound], P[N.stick_margin],
                          P[N.release_margin], *self.event_tolerances)
        pos0 = P[N.initial]
        b = stick_slip(q, pos, vel, net, level, P[N.inertia], contact, s.fired, pos0)
        guide = if_else(q * q == 1, -direction * P[N.coulomb], 0.0)
        e = N.effort_name
        return Equations(
            der={N.position: b.v_reported, N.velocity: b.accel,
                 "E_viscous_J": P[N.viscous] * vel_reported * vel_reported,
                 "E_coulomb_J": P[N.coulomb] * abs(vel_reported),
                 "W_external_J": external * vel_reported},
            outputs={N.position: pos, N.velocity: b.v_reported, **self.extra_outputs(P), e("gravity"): gravity,
                     e("muscles"): port[e()], e("applied"): external,
                     e("friction"): if_else(q * q == 1, guide, b.friction),
                     e("stop"): b.stop_reaction, e("coulomb_level"): level,
                     "kinetic_energy_J": 0.5 * P[N.inertia] * vel * vel, "potential_energy_J": potential,
                     e("net"): net, "slip_direction": b.slip_direction},
            port={N.port: {N.position: pos, N.velocity: b.v_reported}},
            indicators=b.indicators, indicator_margins=b.margins,
            transition={N.position: b.jump_pos, N.velocity: b.jump_vel, "mode": b.jump_mode},
            rest_mode=b.rest_mode,
            initial={N.position: pos0, N.velocity: 0.0, "E_viscous_J": 0.0, "E_coulomb_J": 0.0,
                     "W_external_J": 0.0, "mode": b.initial_mode})
