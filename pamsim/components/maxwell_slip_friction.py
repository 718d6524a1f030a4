"""The Maxwell-slip model of a muscle's friction: N elasto-slide elements (:mod:`.elasto_slide`) in parallel
on the load's flange, whose slip forces are shares of a friction law's level.

Element ``i`` has a slip displacement ``delta_i`` and a share ``w_i``: its slip force is ``w_i F_c`` and its
stiffness ``w_i F_c / delta_i``, with ``F_c(x, p, m)`` the level of any law of :mod:`pamsim.elements.friction`
(the paper's load-dependent law scales with pressure and load).  With one element of share 1, as
``delta -> 0`` it is that law's Coulomb friction: the stiff spring holds the load where Coulomb friction
sticks it, and slips at the same level.  It takes the place of the rig's Coulomb friction, whose law it
reads (:class:`pamsim.components.CoulombFriction` is then ``"none"``).

The same elements on an envelope of the contraction are the generalized Prandtl-Ishlinskii operator in its
stop form: element ``j``'s deflection is the stop ``E_rj[g(x)] = g(x) - P_rj[g(x)]`` of threshold ``r_j`` on
``g(x) = s tanh(x / s)``, and its force ``-w_j E_rj``, so the elements' force is the operator
``sum w_j P_rj[g(x)]`` less its elastic part ``sum w_j g(x)`` (which the muscle's static force holds).  With a
constant level of 1 N, shares ``w_j r_j`` and slip displacements ``r_j`` give stiffnesses ``w_j``
(:func:`prandtl_ishlinskii`).
"""

from __future__ import annotations

from ..elements.friction import ConstantCoulomb
from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, non_negative, positive
from ..modeling.smath import if_else, tanh
from .elasto_slide import element
from .element import ElementParameters
from .friction import PROBE_POINTS, _level_N

MAX_ELEMENTS = 100
"""The most elements a model takes (each is two states and an event indicator)."""


def _branches(branches, n: int) -> tuple[int, ...] | None:
    """``branches`` as a tuple of ``n`` stick states (see :class:`MaxwellSlip`), or None."""
    if branches is None:
        return None
    out = tuple(int(b) for b in branches)
    if len(out) != n or not set(out) <= {-1, 0, 1}:
        raise ValueError(f"branches {branches}: one of 0 (stick), +1 or -1 (slip that way) per element")
    return out


def _parameters(n: int, envelope: bool, damped: bool) -> tuple:
    """The declared parameters of ``n`` elements, their presliding damping if ``damped``, and the envelope's
    scale if they deflect on one."""
    idx = range(1, n + 1)
    scale = (positive("envelope_scale_m", "m", "scale s of the envelope s tanh(x / s) the elements deflect on"),)
    damping = (non_negative("damping_N_s_per_m", "N s/m", "presliding damping, shared as the level"),)
    return (*(positive(f"delta{i}_m", "m", f"slip displacement of element {i}") for i in idx),
            *(non_negative(f"share{i}", "1", f"element {i}'s share of the friction level") for i in idx),
            *(damping if damped else ()), *(scale if envelope else ()))


class MaxwellSlip(ElementParameters, Component):
    """``N = len(deltas_m)`` elements on the flange, the level from the friction law ``element``.

    Parameters ``delta<i>_m`` and ``share<i>`` per element (``i`` from 1), and the law's.  Inputs: the
    muscle's gauge pressure and the load's mass, as the law reads them.  States per element: ``z<i>_m``,
    its spring's deflection, and ``E_element<i>_J``, the work the load has done on it (spring energy plus slip
    losses).  Outputs: the total force ``F_N``, the level ``level_N``, each element's force and whether it
    slips.

    ``damping_N_s_per_m``: the presliding damping, a parameter; None, no such term (:meth:`on_massless_end`).
    ``branches`` (:meth:`held`): each element held in one stick state, for a linearisation: 0 sticking,
    +1 or -1 slipping that way, its deflection then the constant ``+-delta<i>_m`` and no state; no events.
    """

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    inputs = (Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"), Var("mass_kg", "kg", "load mass"))
    indicator_names: tuple[str, ...] = ()

    model_name = "maxwell_slip"
    """The ``[hysteresis] model`` these elements are (``pi`` for :func:`prandtl_ishlinskii`)."""

    def __init__(self, name: str, element, deltas_m, shares, damping_N_s_per_m: float = 0.0, branches=None,
                 envelope_scale_m: float | None = None):
        if not 1 <= len(deltas_m) <= MAX_ELEMENTS or len(shares) != len(deltas_m):
            raise ValueError(f"{len(deltas_m)} slip displacements and {len(shares)} shares: give 1 to "
                             f"{MAX_ELEMENTS} of each")
        n = self.n_elements = len(deltas_m)
        idx = range(1, n + 1)
        self.branches = _branches(branches, n)
        self.envelope_scale_m = envelope_scale_m
        self.extra_parameters = _parameters(n, envelope_scale_m is not None, damping_N_s_per_m is not None)
        # Held slipping, an element's deflection is a constant: it is no state (a linearisation drops it).
        self.states = (*(Var(f"z{i}_m", "m", f"deflection of element {i}'s spring", 1e-3) for i in idx
                         if not self._held_slipping(i)),
                       *(Var(f"E_element{i}_J", "J", f"work done by the load on element {i}", 0.1) for i in idx))
        self.outputs = (Var("F_N", "N", "the elements' force on the load along x"),
                        Var("level_N", "N", "the friction law's level, the elements' slip forces' sum over shares"),
                        *(Var(f"F{i}_N", "N", f"element {i}'s force on the load") for i in idx),
                        *(Var(f"slipping{i}", "1", f"1 while element {i} slips") for i in idx))
        self.n_indicators = n if self.branches is None else 0  # held in their stick states: no switch
        self.indicator_names = tuple(f"slip{i}" for i in idx)[:self.n_indicators]
        values = self.wrap(element, _level_N, PROBE_POINTS)
        values.update({f"delta{i}_m": float(d) for i, d in zip(idx, deltas_m)})
        values.update({f"share{i}": float(w) for i, w in zip(idx, shares)})
        if damping_N_s_per_m is not None:
            values["damping_N_s_per_m"] = float(damping_N_s_per_m)
        if envelope_scale_m is not None:
            values["envelope_scale_m"] = float(envelope_scale_m)
        super().__init__(name, values)

    def structure_key(self) -> tuple:
        """The key of :class:`ElementParameters`, with the number of elements: it shapes the code."""
        return super().structure_key() + (self.n_elements, self.branches, self.envelope_scale_m is None,
                                           "damping_N_s_per_m" in self.values)

    def _held_slipping(self, i: int) -> bool:
        """Whether element ``i`` (from 1) is held slipping (``branches``)."""
        return self.branches is not None and self.branches[i - 1] != 0

    def held(self, branches) -> "MaxwellSlip":
        """This model with each element held in a stick state (``branches``: per element 0 sticking, +1 or -1
        slipping that way, at its slip displacement), its equations otherwise the same, and no events: what a
        linearisation within one stick state differentiates."""
        return self._copy(self.values.get("damping_N_s_per_m"), branches)

    def on_massless_end(self) -> "MaxwellSlip":
        """These elements without the presliding damping term (and its parameter), for a node whose velocity
        its balance of forces gives (:class:`pamsim.components.series_tendon.SeriesTendon`'s muscle end):
        there a force that depends on the velocity is an algebraic loop.  Their damping must be 0."""
        if self.values.get("damping_N_s_per_m", 0.0) != 0.0:
            raise ValueError(f"{self.name}: presliding damping {self.values['damping_N_s_per_m']:g} N s/m on a "
                             "massless node")
        return self._copy(None, self.branches)

    def _copy(self, damping_N_s_per_m: float | None, branches) -> "MaxwellSlip":
        """These elements with the presliding damping ``damping_N_s_per_m`` (None: no such term) and the stick
        states ``branches``, the rest as they are."""
        n = self.n_elements
        out = MaxwellSlip(self.name, self.element, [self.values[f"delta{i}_m"] for i in range(1, n + 1)],
                          [self.values[f"share{i}"] for i in range(1, n + 1)], damping_N_s_per_m, branches,
                          self.values.get("envelope_scale_m"))
        out.model_name = self.model_name
        return out

    def held_state(self, p_abs_Pa: float) -> dict[str, float]:
        """The states at rest, relaxed (every deflection 0), whatever the pressure ``p_abs_Pa``."""
        return {v.name: 0.0 for v in self.states}

    def equations(self, s: Symbols) -> Equations:
        """Each element of :func:`~pamsim.components.elasto_slide.element` at its share of the law's level."""
        u, flange = s.u, s.port["flange"]
        v = flange["v_m_s"]
        if self.envelope_scale_m is not None:  # the elements deflect on g(x) = s tanh(x / s): at g'(x) v
            slope = tanh(flange["x_m"] / s.p["envelope_scale_m"])
            v_elements = v * (1.0 - slope * slope)
        else:
            v_elements = v
        level = self.element_call(s, "level_N", flange["x_m"], u["p_gauge_Pa"], u["mass_kg"])
        der, outputs, jumps, indicators, total = {}, {"level_N": level}, {}, [], 0.0
        for i in range(1, self.n_elements + 1):
            delta = s.p[f"delta{i}_m"]
            share = s.p[f"share{i}"]
            branch = None if self.branches is None else self.branches[i - 1]
            z = branch * delta if self._held_slipping(i) else s.x[f"z{i}_m"]
            c = share * s.p["damping_N_s_per_m"] if "damping_N_s_per_m" in self.values else 0.0
            e = element(z, v_elements, share * level / delta, delta, s.fired[i - 1] if branch is None else 0.0,
                        c, None if branch is None else branch == 0)
            if not self._held_slipping(i):
                der[f"z{i}_m"] = e.rate
            der[f"E_element{i}_J"] = -e.force * v
            outputs.update({f"F{i}_N": e.force, f"slipping{i}": if_else(e.slipping, 1.0, 0.0)})
            if branch is None:
                jumps[f"z{i}_m"] = e.jump
                indicators.append(e.indicator)
            total = total + e.force
        outputs["F_N"] = total
        return Equations(der=der, outputs=outputs, port={"flange": {"F_N": total}}, indicators=tuple(indicators),
                         transition=jumps, initial={v.name: 0.0 for v in self.states})


def prandtl_ishlinskii(name: str, thresholds_m, weights_N_per_m, envelope_scale_m: float | None = None) -> MaxwellSlip:
    """The generalized Prandtl-Ishlinskii operator's hysteretic part on the load's flange (see the module's
    docstring): thresholds ``r_j`` [m] (> 0), weights ``w_j`` [N/m] (>= 0), the envelope's scale [m] (None:
    the classical operator, ``g(x) = x``).  Its forces are its own, not a friction law's."""
    pi = MaxwellSlip(name, ConstantCoulomb(1.0), list(thresholds_m),
                     [float(w) * float(r) for w, r in zip(weights_N_per_m, thresholds_m)], 0.0, None, envelope_scale_m)
    pi.model_name = "pi"
    return pi
