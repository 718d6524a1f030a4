"""Kothera et al. (2009) models K-2 ... K-8: energy models and force-balance models.

Energy models: ``F = F_Gaylord - F_bladder - F_braid`` with ``F_bladder = -V_b dW/dL``
(Mooney-Rivlin, :mod:`.strain_energy`) and the braid term of eq. (21)
``F_Br = p^2 B^3 L / (4 pi^2 E_b A_b n N^4)``.  Force-balance models: eq. (29)
(linear-elastic bladder, constant thickness) and eq. (33) (variable thickness).
The ``_tips`` models evaluate at ``L' = L - 2 (R - R0)`` (eq. 24).
"""

from __future__ import annotations

import math
from functools import partial

from .base import StaticModelSpec
from .braid_base import WALL, BladderModel
from .sources import KOTHERA2009, SURVEY
from .strain_energy import MooneyRivlin, elastic_force_N

BRAID = ("n_fibres", "fibre_area_m2", "E_braid_Pa")
MOONEY_RIVLIN = ("C10_Pa", "C01_Pa")


class KotheraEnergy(BladderModel):
    """Gaylord minus a Mooney-Rivlin bladder term (K-2 thin stretches, K-3 mean-radius), optionally
    minus the braid-stretch term (K-4) and with tip correction (K-5)."""

    def __init__(self, params, variant="default", *, name, stretch, braid, tips):
        self.name, self.stretch = name, stretch
        self.tip_factor = 2.0 if tips else 0.0
        self.implicit_tips = variant == "implicit_radius"
        super().__init__(params, variant)
        self.energy = MooneyRivlin(params["C10_Pa"], params["C01_Pa"])
        g = self.g
        self.k_braid = (g.b ** 3 / (4.0 * math.pi ** 2 * params["E_braid_Pa"] * params["fibre_area_m2"]
                                    * params["n_fibres"] * g.N ** 4)) if braid else 0.0

    def force_N(self, x_m, p_gauge_Pa):
        L = self.effective_length_m(x_m)
        F = p_gauge_Pa * (3.0 * L * L - self.b2) * self.k_gaylord - elastic_force_N(L, self.g, self.energy, self.stretch)
        if self.k_braid:
            F = F - self.k_braid * p_gauge_Pa * p_gauge_Pa * L
        return F


class KotheraForceBalance(BladderModel):
    """Eq. (29), linear-elastic bladder of constant thickness ``t0`` (Tsagarakis-Caldwell form):

    ``F = p (3 L^2 - B^2)/(4 pi N^2) - E t0 L^2/(2 pi N^2) (1/R0 - 1/R) + E V_b (1/L0 - 1/L)``.

    Variant ``"printed"`` uses the paper's hoop term ``(1/R - 1/R0)``, which
    contradicts eqs. (26)-(28) and predicts contraction beyond the kinematic limit.
    """

    name = "kothera_force_balance"

    def __init__(self, params, variant="corrected"):
        super().__init__(params, variant)
        E = params["E_bladder_Pa"]
        sign = 1.0 if variant == "corrected" else -1.0
        self.k_hoop = sign * E * self.g.t0 / (2.0 * math.pi * self.g.N ** 2)
        self.EVb = E * self.g.Vb

    def force_N(self, x_m, p_gauge_Pa):
        L = self.L0 - x_m
        R = self.g.radius_m(L)
        return (p_gauge_Pa * (3.0 * L * L - self.b2) * self.k_gaylord
                - self.k_hoop * L * L * (1.0 / self.g.r0 - 1.0 / R) + self.EVb * (1.0 / self.L0 - 1.0 / L))


class KotheraForceBalanceThickness(BladderModel):
    """Eq. (33) (the survey's Kothera^(1), eq. 17), thickness from constant bladder volume:

    ``F = p (3 L^2 - B^2)/(4 pi N^2) + p (V_b/L - t L^2/(2 pi R N^2)) + E V_b (1/L0 - 1/L)
    + E L/(2 pi R N^2) (t L - t0 L0)``.

    Variant ``"constant_thickness"`` holds ``t = t0`` and uses the current wall
    volume ``2 pi L t0 (R - t0/2)`` for ``V_b`` in the pressure term; with ``E = 0`` it
    is Chou and Hannaford's model exactly.
    """

    def __init__(self, params, variant="variable_thickness", *, name, tips):
        self.name = name
        self.tip_factor = 2.0 if tips else 0.0
        super().__init__(params, variant)
        self.E = params["E_bladder_Pa"]
        self.k_rn = 1.0 / (2.0 * math.pi * self.g.N ** 2)
        self.constant = variant == "constant_thickness"

    def force_N(self, x_m, p_gauge_Pa):
        g = self.g
        L = self.effective_length_m(x_m)
        R = g.radius_m(L)
        if self.constant:
            t = g.t0
            vb_per_L = math.pi * t * (2.0 * R - t)
        else:
            t = g.thickness_m(L, R)
            vb_per_L = g.Vb / L
        kr = self.k_rn / R
        return (p_gauge_Pa * ((3.0 * L * L - self.b2) * self.k_gaylord + vb_per_L - t * L * L * kr)
                + self.E * (g.Vb * (1.0 / self.L0 - 1.0 / L) + L * kr * (t * L - g.t0 * self.L0)))


def _energy(name, stretch, braid, tips):
    return partial(KotheraEnergy, name=name, stretch=stretch, braid=braid, tips=tips)


def _thickness(name, tips):
    return partial(KotheraForceBalanceThickness, name=name, tips=tips)


SPECS = (
    StaticModelSpec("kothera_mooney_rivlin", "closed-form", f"{KOTHERA2009} eqs. (3)-(7) (Klute-Hannaford; 1/L0 and sign rebuilt)",
                    WALL + MOONEY_RIVLIN, _energy("kothera_mooney_rivlin", "thin", False, False),
                    summary="K-2: Gaylord minus a Mooney-Rivlin bladder, thin-wall stretches"),
    StaticModelSpec("kothera_corrected_mooney_rivlin", "closed-form",
                    f"{KOTHERA2009} eqs. (8)-(16) (= Delson, {SURVEY} eqs. (18)-(21))",
                    WALL + MOONEY_RIVLIN, _energy("kothera_corrected_mooney_rivlin", "mean_radius", False, False),
                    summary="K-3: Gaylord minus a Mooney-Rivlin bladder, mean-radius stretches, variable thickness"),
    StaticModelSpec("kothera_energy", "closed-form", f"{KOTHERA2009} eqs. (17)-(23) (= {SURVEY} eq. (22), braid term as Kothera eq. (21))",
                    WALL + MOONEY_RIVLIN + BRAID, _energy("kothera_energy", "mean_radius", True, False),
                    summary="K-4: Gaylord - corrected Mooney-Rivlin - braid stretch"),
    StaticModelSpec("kothera_energy_tips", "closed-form", f"{KOTHERA2009} eqs. (23)-(25)",
                    WALL + MOONEY_RIVLIN + BRAID, _energy("kothera_energy_tips", "mean_radius", True, True),
                    variants=("explicit_radius", "implicit_radius"),
                    summary="K-5: K-4 evaluated at the tip-corrected length (tip radius R(L), or R(L') implicitly)"),
    StaticModelSpec("kothera_force_balance", "closed-form",
                    f"{KOTHERA2009} eqs. (26)-(29), hoop-term sign corrected (= Ferraresi, {SURVEY} eq. (16), repaired)",
                    WALL + ("E_bladder_Pa",), KotheraForceBalance, variants=("corrected", "printed"),
                    summary="K-6: linear-elastic force balance, constant thickness"),
    StaticModelSpec("kothera_force_balance_thickness", "closed-form", f"{KOTHERA2009} eqs. (30)-(33) (= {SURVEY} eq. (17))",
                    WALL + ("E_bladder_Pa",), _thickness("kothera_force_balance_thickness", False),
                    variants=("variable_thickness", "constant_thickness"),
                    summary="K-7: linear-elastic force balance with variable wall thickness"),
    StaticModelSpec("kothera_force_balance_thickness_tips", "closed-form", f"{KOTHERA2009} eq. (33) with eq. (24)",
                    WALL + ("E_bladder_Pa",), _thickness("kothera_force_balance_thickness_tips", True),
                    variants=("variable_thickness", "constant_thickness"),
                    summary="K-8: K-7 evaluated at the tip-corrected length"),
)
