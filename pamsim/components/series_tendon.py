"""A tendon with series elasticity: a spring between a muscle's end and its attachment on a body.

With a rigid tendon the muscle's contraction is the one its attachment's path gives (``x_path``), and
its friction acts on the body it turns.  With a spring of stiffness ``k`` in series the muscle's end is
a node of its own, at contraction ``x`` (a state): the tendon stretches by ``x - x_path`` and pulls
``T = k max(x - x_path, 0)`` on both (it only pulls), and the muscle's friction and damping act at the
muscle's end, not on the body.

The muscle's end is massless (its fitting weighs grams against the body's inertia: pamsim's choice,
docs/joints.md).  Its forces then balance at every instant::

    F_static(x, p) - F_damp(v) - F_c sgn(v) = T

which gives its velocity without a mode: held (``v = 0`` exactly) while ``|F_static - T| <= F_c``,
else the velocity at which the damping takes what friction leaves,
``v = F_damp^-1(F_static - T -+ F_c)``.  Components added on the muscle's end (Maxwell-slip, Bouc-Wen or
Prandtl-Ishlinskii elements in the friction's place, a spring) act on the node's port ``others``, and their
summed force ``F_others`` joins the static force: ``F_static + F_others - T``.  None of them may pull with
a force that depends on the end's velocity (a damper, an element's presliding damping): the velocity is
what the balance gives, and such a force would be an algebraic loop.  The velocity is continuous in the
state (a dead zone, not a switch), so the muscle's stick and slip need no event; its kinks at
``|F_static - T| = F_c`` are left to the integrator's step control, as a tendon's slack is.  It needs a
damping law whose force grows strictly with speed (:func:`pamsim.elements.damping.increasing`); the
paper's, with ``D1 < 0``, does not.
"""

from __future__ import annotations

from ..elements.damping import increasing
from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import fmax, if_else
from .damping import ViscousDamping


class MuscleEndDamping(ViscousDamping):
    """:class:`ViscousDamping` that also gives the velocity at which its force equals a given one (the
    inverse of its law), for a :class:`SeriesTendon`'s massless muscle end."""

    inputs = (Var("F_free_N", "N", "force left to the damping at the muscle's end"),)
    outputs = ViscousDamping.outputs + (Var("v_free_m_s", "m/s", "velocity at which the damping force is F_free_N"),)

    def __init__(self, name: str, element):
        # Without a law that grows through zero the massless end has no velocity, or several, for a force: the
        # integrator would fail far from here ("step size underflow"), so the law is refused where it is given.
        if not increasing(element):
            raise ValueError(f"damping {getattr(element, 'name', type(element).__name__)!r} on a massless muscle "
                             "end (a muscle on an elastic tendon): its force must grow with speed through zero; "
                             "use damping = 'linear', or 'paper' with D1_N_s_per_m > 0")
        super().__init__(name, element)

    def equations(self, s: Symbols) -> Equations:
        """The damping's equations, and the inverse of its law at ``F_free_N``."""
        eq = super().equations(s)
        eq.outputs["v_free_m_s"] = self.element_call(s, "velocity_m_s", s.u["F_free_N"])
        return eq


class SeriesTendon(Component):
    """A spring of stiffness ``k_N_per_m`` in series with a muscle: the node of the muscle's flange (its
    static force, damping and friction are branches on it) and a branch on its attachment's flange
    (which then carries the tendon's pull ``T`` to the body).

    Inputs: the muscle's static force, its Coulomb level, and the velocity its damping gives for the
    force left after friction (``F_free_N`` out, ``v_free_m_s`` in: :class:`MuscleEndDamping`).  The node
    ``others`` (optional) carries the components added on the muscle's end; their force joins the static
    force in the balance.
    State ``x_m``: the muscle's contraction; it starts at the path's (the tendon unstretched).
    Output ``level_on_body_N`` is zero: the muscle's friction acts at its end and reaches the body
    only through the tendon's force.
    """

    parameters = (positive("k_N_per_m", "N/m", "stiffness of the tendon in series with the muscle"),)
    ports = (Port("flange", TRANSLATIONAL, "node"), Port("path", TRANSLATIONAL, "branch"),
             Port("others", TRANSLATIONAL, "node", optional=True))
    inputs = (Var("F_static_N", "N", "the muscle's static force"),
              Var("friction_level_N", "N", "the muscle's Coulomb friction level"),
              Var("v_free_m_s", "m/s", "velocity at which the muscle's damping takes F_free_N"))
    states = (Var("x_m", "m", "the muscle's contraction", 0.01),)
    outputs = (Var("x_m", "m", "the muscle's contraction"),
               Var("v_m_s", "m/s", "the muscle's contraction velocity"),
               Var("stretch_m", "m", "the tendon's stretch, x_m less the path's contraction (negative: slack)"),
               Var("F_tendon_N", "N", "the tendon's pull (zero when slack)"),
               Var("F_free_N", "N", "force left to the damping: F_static - T beyond the friction band, else 0"),
               Var("direction", "1", "+1 or -1 while the muscle contracts or extends, 0 while held"),
               Var("E_elastic_J", "J", "elastic energy stored in the tendon"),
               Var("level_on_body_N", "N", "Coulomb level the muscle brings to the body's stick/slip (none)"))

    def equations(self, s: Symbols) -> Equations:
        """The muscle end's velocity from its dead zone, the tendon's pull on both sides."""
        k, path = s.p["k_N_per_m"], s.port["path"]
        x, level = s.x["x_m"], s.u["friction_level_N"]
        stretch = x - path["x_m"]
        T = k * fmax(stretch, 0.0)
        drive = s.u["F_static_N"] + s.port["others"]["F_N"] - T
        # ">=": the same value at the band's edge (0), and there the slope of the side outside it.  Without
        # friction (level 0, as the statics and the linearisation read an end's balance) a root found exactly
        # at drive = 0 then has d free / d drive = 1, as its neighbours do, not the band's 0 (a stiffness of NaN).
        free = if_else(drive >= level, drive - level, if_else(drive <= -level, drive + level, 0.0))
        v = s.u["v_free_m_s"]  # exactly zero at free == 0: every law's inverse is
        taut_stretch = fmax(stretch, 0.0)
        return Equations(
            der={"x_m": v},
            outputs={"x_m": x, "v_m_s": v, "stretch_m": stretch, "F_tendon_N": T, "F_free_N": free,
                     "direction": if_else(free > 0.0, 1.0, if_else(free < 0.0, -1.0, 0.0)),
                     "E_elastic_J": 0.5 * k * taut_stretch * taut_stretch, "level_on_body_N": 0.0},
            port={"flange": {"x_m": x, "v_m_s": v}, "others": {"x_m": x, "v_m_s": v}, "path": {"F_N": T}},
            initial={"x_m": path["x_m"]})


def end_wiring(spring: str, muscle: str, friction: str, damping: str) -> list[tuple[str, str]]:
    """How a muscle's static force (``muscle``), Coulomb friction (``friction``) and damping (``damping``, a
    :class:`MuscleEndDamping`) feed the balance of its end on the :class:`SeriesTendon` ``spring``: the
    force the spring's node balances, the friction's level, and the damping's force out and velocity back."""
    return [(f"{friction}.level_N", f"{spring}.friction_level_N"), (f"{muscle}.F_static_N", f"{spring}.F_static_N"),
            (f"{spring}.F_free_N", f"{damping}.F_free_N"), (f"{damping}.v_free_m_s", f"{spring}.v_free_m_s")]
