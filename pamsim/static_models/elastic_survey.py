"""Linear- and neo-Hookean-elastic bladder models of miniature muscles from the survey.

S-24 Hocking (polynomial stress-strain), S-26 Pillsbury (pressure-dependent
stress, an assumed combination), S-27 Sangian (dead band, thin-tube elastic
pressure), S-14 Trivedi (neo-Hookean inflation).  Contraction ``x`` [m], gauge
pressure ``p`` [Pa], force [N].
"""

from __future__ import annotations

import math

from .base import StaticModelSpec
from .braid_base import WALL, BladderModel, BraidModel
from .real_math import sqrt
from .sources import SURVEY

HOCKING_OPTIONAL = {"hocking_E2_Pa": 0.0, "hocking_E3_Pa": 0.0, "hocking_P_c_Pa": 0.0}


class Hocking(BladderModel):
    """Survey eq. (37) with ``4 pi N^2`` (printed ``4 pi N``: dimensionally wrong):

    ``F = (p - P_c)(3 l^2 - b^2)/(4 pi N^2) + (V_b/l) sum E_i (l/l0 - 1)^i
    - (t l^2/(2 pi N^2 r)) sum E_i (r/r0 - 1)^i``, ``t`` the current thickness
    (constant bladder volume), ``E_1 = E_bladder_Pa``.  Variant ``"tips"`` uses
    Hocking's corrected length ``l - 2 (pi/2 - 1)(r - r0)`` (survey, after eq. 38).

    Pillsbury (survey eq. 39, ``name = "pillsbury"``) makes every ``E_i`` linear in
    pressure, ``E_iI + E_iS p``, and adds Chou and Hannaford's thickness term.
    """

    def __init__(self, params, variant="plain", *, name="hocking"):
        self.name = name
        self.tip_factor = 2.0 * (math.pi / 2.0 - 1.0) if variant == "tips" else 0.0
        super().__init__(params, variant)
        if name == "pillsbury":
            self.E_I = (params["pillsbury_E1I_Pa"], params["pillsbury_E2I_Pa"])
            self.E_S = (params["pillsbury_E1S"], params["pillsbury_E2S"])
            self.P_c = 0.0
            self.chou = (self.g.b * self.g.t0 / self.g.N, math.pi * self.g.t0 ** 2)
        else:
            self.E_I = (params["E_bladder_Pa"], params["hocking_E2_Pa"], params["hocking_E3_Pa"])
            self.E_S = (0.0,) * len(self.E_I)
            self.P_c = params["hocking_P_c_Pa"]
            self.chou = None
        self.k_hoop = 1.0 / (2.0 * math.pi * self.g.N ** 2)

    def _stress(self, strain, p):
        total, power = 0.0, strain
        for e_i, e_s in zip(self.E_I, self.E_S):
            total = total + (e_i + e_s * p) * power
            power = power * strain
        return total

    def force_N(self, x_m, p_gauge_Pa):
        g = self.g
        L = self.effective_length_m(x_m)
        r = g.radius_m(L)
        t = g.thickness_m(L, r)
        F = ((p_gauge_Pa - self.P_c) * (3.0 * L * L - self.b2) * self.k_gaylord
             + g.Vb / L * self._stress(L / self.L0 - 1.0, p_gauge_Pa)
             - t * L * L * self.k_hoop / r * self._stress(r / g.r0 - 1.0, p_gauge_Pa))
        if self.chou:
            s = sqrt(1.0 - L * L / self.b2)
            F = F + p_gauge_Pa * (self.chou[0] * (2.0 * s - 1.0 / s) - self.chou[1])
        return F


class Sangian(BraidModel):
    """Survey eq. (40), rebuilt (``"corrected"``):

    ``F = pi r0^2 (q1 (1 - eps)^2 - q2) (p - Pbar - (E t0 b/(2 pi N r0^2))
    (sqrt(1 - (l/l0)^2 cos^2(theta0)) - sin(theta0)))``: the bracket is the
    thin-tube elastic pressure ``E t0 (r - r0)/r0^2``, zero at rest and reducing
    the effective pressure.  ``"printed"`` keeps the paper's ``+`` signs.
    """

    name = "sangian"

    def __init__(self, params, variant="corrected"):
        super().__init__(params, variant)
        g = self.g
        self.a = math.pi * g.r0 ** 2
        self.q1, self.q2 = g.q1, g.q2
        k = params["E_bladder_Pa"] * g.t0 * g.b / (2.0 * math.pi * g.N * g.r0 ** 2)
        self.k_el = -k if variant == "corrected" else k
        self.s0 = -math.sin(g.theta0) if variant == "corrected" else math.sin(g.theta0)
        self.c02 = math.cos(g.theta0) ** 2
        self.P_bar = params["sangian_Pbar_Pa"]

    def force_N(self, x_m, p_gauge_Pa):
        s = 1.0 - x_m / self.L0
        elastic = self.k_el * (sqrt(1.0 - s * s * self.c02) + self.s0)
        return self.a * (self.q1 * s * s - self.q2) * (p_gauge_Pa - self.P_bar + elastic)


class Trivedi(BraidModel):
    """Survey eqs. (23)-(24), neo-Hookean bladder, as a force map (pamsim's reading).

    The survey's eq. (24) gives the pressure ``P_T(l1)`` at which a free muscle
    reaches the stretch ``l1 = L/L0``.  pamsim writes the force as Gaylord's force
    at the excess pressure, ``F = (p - P_T(l1)) (3 L^2 - b^2)/(4 pi N^2)``, which is
    zero exactly where the paper's root-find puts the free muscle.  With the
    rebuilt numerator and denominator (static_models_spec.md S-14) the singular factor
    cancels: ``F = p (3 L^2 - b^2)/(4 pi N^2) - K Num(l1)/(l1^3 (1 - l1^2 c^2)^2)``,
    ``K = (E/3)(r0^2/ri^2 - 1) b^2/(4 pi N^2)``, ``c = cos(theta0)``.  Eq. (25)
    (the bladder's linear-elastic axial force) is not used.
    """

    name = "trivedi"

    def __init__(self, params, variant="default"):
        super().__init__(params, variant)
        g = self.g
        c = math.cos(g.theta0)
        self.c2, self.c4, self.c6 = c * c, c ** 4, c ** 6
        self.C2 = math.cos(2.0 * g.theta0)
        ri = g.r0 - g.t0
        self.K = params["E_bladder_Pa"] / 3.0 * (g.r0 ** 2 / ri ** 2 - 1.0) * self.b2 * self.k_gaylord

    def pressure_Pa(self, stretch):
        """Eq. (24) rebuilt: gauge pressure [Pa] at which a free muscle has axial stretch ``L/L0``."""
        l2 = stretch * stretch
        den = stretch * l2 * (1.0 - l2 * self.c2) ** 2 * (1.0 - 3.0 * l2 * self.c2)
        return abs(self.K / (self.b2 * self.k_gaylord) * self._num(l2) / den)

    def _num(self, l2):
        c2, c4, c6, C2 = self.c2, self.c4, self.c6, self.C2
        l4 = l2 * l2
        return (l4 * l4 * c4 * C2 - 2.0 * l4 * l2 * c2 * C2 + l4 * C2 + 2.0 * l2 * c2 * C2 - C2
                - 2.0 * l2 * c6 + c4)

    def force_N(self, x_m, p_gauge_Pa):
        L = self.L0 - x_m
        lam = L / self.L0
        l2 = lam * lam
        return (p_gauge_Pa * (3.0 * L * L - self.b2) * self.k_gaylord
                - self.K * self._num(l2) / (lam * l2 * (1.0 - l2 * self.c2) ** 2))


SPECS = (
    StaticModelSpec("hocking", "closed-form", f"Hocking et al., as given in {SURVEY} eq. (37) (4 pi N^2 for the printed 4 pi N)",
                    WALL + ("E_bladder_Pa",), Hocking, optional=HOCKING_OPTIONAL, variants=("plain", "tips"),
                    summary="S-24: Gaylord with polynomial axial and hoop stresses, optional dead band and tip correction"),
    StaticModelSpec("pillsbury", "closed-form", f"Pillsbury et al., as given in {SURVEY} eq. (39) (combination assumed)",
                    WALL + ("pillsbury_E1I_Pa", "pillsbury_E1S"),
                    lambda p, v: Hocking(p, v, name="pillsbury"),
                    optional={"pillsbury_E2I_Pa": 0.0, "pillsbury_E2S": 0.0}, variants=("plain", "tips"),
                    summary="S-26: Hocking with pressure-dependent moduli plus Chou's thickness term"),
    StaticModelSpec("sangian", "closed-form", f"Sangian et al., as given in {SURVEY} eq. (40) (rebuilt signs)",
                    WALL + ("E_bladder_Pa",), Sangian, optional={"sangian_Pbar_Pa": 0.0},
                    variants=("corrected", "printed"),
                    summary="S-27: normalised Gaylord at the pressure left after a dead band and the tube's elastic pressure"),
    StaticModelSpec("trivedi", "closed-form", f"Trivedi et al., as given in {SURVEY} eqs. (23)-(24) (rebuilt)",
                    WALL + ("E_bladder_Pa",), Trivedi,
                    summary="S-14: neo-Hookean inflation pressure of the free muscle, as a force map"),
)
