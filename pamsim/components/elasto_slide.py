"""Elasto-slide elements: a spring in series with a slider, on the load's flange.

N of them in parallel are the Maxwell-slip model of hysteresis (M. Vo-Minh, T. Tjahjowidodo, H. Ramon and
H. Van Brussel, "A new approach to modeling hysteresis in a pneumatic artificial muscle using the
Maxwell-slip model", IEEE/ASME Transactions on Mechatronics 16(1), 2011).  An element follows the load
with its spring's deflection ``z`` while its force is below its slip force ``F``, and slips, ``z`` held at
its slip displacement ``+-delta``, while the load moves on the same way.  It sticks again the moment the
load turns back.  Its force on the load is ``-k z``, with ``k = F / delta``.

The switches are exact.  Reaching the slip displacement is an event (the indicator ``delta - |z|``
crosses zero) whose jump puts ``z`` exactly on it; exactly there, the element slips while the load pushes
outward, a condition of the state alone, so an element needs no mode of its own.  Letting go needs no
event: ``dz/dt`` there is ``v`` on one side of ``v = 0`` and ``0`` on the other, continuous, and the load's
turning is its own event while it slides.  ``delta`` is a constant, so a slip force that follows the
pressure and the load (:class:`~pamsim.components.maxwell_slip_friction.MaxwellSlip`) moves the spring's stiffness with it and never the limit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else


@dataclass(frozen=True)
class Element:
    """One element's equations (:func:`element`): the rate of its deflection, its force on the load, whether it
    slips, its event indicator and its deflection after an event."""

    rate: Any
    force: Any
    slipping: Any
    indicator: Any
    jump: Any


def element(z, v, k, delta, fired, c=0.0, stuck=None) -> Element:
    """An elasto-slide element at deflection ``z`` under a load moving at ``v``, of stiffness ``k`` >= 0 and
    slip displacement ``delta`` > 0 (slip force ``k delta``); ``fired``: its indicator crossed (at an event).
    ``c``: a damper beside the spring, that acts while the element sticks (presliding damping, as in
    the generalized Maxwell-slip model): ``-c dz/dt``, zero while it slips.  ``stuck``: None, the element
    switches as above; True or False, it is held sticking or slipping whatever its state (a linearisation
    within one stick state: the same equations, the switch left out)."""
    # On the limit means there, where the event's jump put it, within 5e-13 of delta either way (1e-12 on
    # z^2): an integrator's dense output can round a held deflection a few ulps outward, and an implicit
    # one's (BDF's) a few ulps inward, which counted as having left the limit, and the next outward step
    # crossed it again (an element at rest on its limit at a massless muscle end switched every few
    # microseconds).  A deflection that reaches the band from inside slips there without an event, its force
    # the limit's to 5e-13.  A state further past it inside a step keeps the indicator below zero, so that
    # the crossing is found.
    at_limit = (z * z >= delta * delta * (1.0 - 1e-12)) * (z * z <= delta * delta * (1.0 + 1e-12))
    slipping = at_limit * (v * z > 0.0) if stuck is None else (not stuck)
    rate = if_else(slipping, 0.0, v)
    # Not clipped at the limit: a trial state past it inside a step (the event lies in that step, and the
    # step ends where it is located) sees the spring's force go on smoothly.  Clipped, the force had a kink
    # there, and the native engine's error estimate rejected two or three steps at every element's slip.
    force = -k * z - c * rate
    return Element(rate=rate, force=force, slipping=slipping,
                   indicator=if_else(at_limit, 1.0, delta - if_else(z >= 0.0, z, -z)),
                   jump=if_else(fired, if_else(z >= 0.0, delta, -delta), z))


class ElastoSlide(Component):
    """One element of constant stiffness ``k_N_per_m`` and slip force ``F_slip_N`` (slip displacement
    ``F / k``): a branch on the load's flange, added with a ``[[component]]`` table.

    States ``z_m``, the spring's deflection (it grows with the contraction while the element sticks), and
    ``E_element_J``, the work the load has done on the element, ``-F v``: what its spring holds plus what
    its slider has dissipated.
    """

    parameters = (positive("k_N_per_m", "N/m", "stiffness of the element's spring"),
                  positive("F_slip_N", "N", "force at which the element's slider slips"))
    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    states = (Var("z_m", "m", "deflection of the element's spring", 1e-3),
              Var("E_element_J", "J", "work done by the load on the element (spring energy + slip losses)", 0.1))
    outputs = (Var("F_N", "N", "the element's force on the load along x"),
               Var("slipping", "1", "1 while the element slips, 0 while it sticks"),
               Var("E_spring_J", "J", "elastic energy in the element's spring"))
    n_indicators = 1
    indicator_names = ("slip",)

    def equations(self, s: Symbols) -> Equations:
        """The element of :func:`element` with slip displacement ``F / k``."""
        k, F = s.p["k_N_per_m"], s.p["F_slip_N"]
        z, v = s.x["z_m"], s.port["flange"]["v_m_s"]
        e = element(z, v, k, F / k, s.fired[0])
        return Equations(
            der={"z_m": e.rate, "E_element_J": -e.force * v},
            outputs={"F_N": e.force, "slipping": if_else(e.slipping, 1.0, 0.0), "E_spring_J": 0.5 * k * z * z},
            port={"flange": {"F_N": e.force}}, indicators=(e.indicator,), transition={"z_m": e.jump},
            initial={"z_m": 0.0, "E_element_J": 0.0})
