"""Energy models with a hyperelastic bladder: Ogden (the Festo paper's model) and neo-Hookean.

``F = F_Gaylord - F_bladder - F_braid``: ``F_bladder = -V_b dW/dL`` from the shared
strain-energy routine (:mod:`.strain_energy`), with the mean-radius stretches
(default) or the thin-wall ones; ``F_braid`` is the fibre-stretch term of the
Ogden paper (eqs. 6-13, rebuilt), zero for inextensible fibres.
"""

from __future__ import annotations

import math

import numpy as np

from .base import Domain, StaticModelSpec
from .braid_base import WALL, BladderModel
from .sources import OGDEN, SURVEY
from .strain_energy import STRETCHES, NeoHookean, Ogden, elastic_force_N

OGDEN_OPTIONAL = {"ogden_mu2_Pa": 0.0, "ogden_alpha2": 1.0, "ogden_mu3_Pa": 0.0, "ogden_alpha3": 1.0,
                  "E_braid_Pa": math.inf, "n_fibres": 1.0, "fibre_area_m2": 1.0}


class FibreStretch:
    """Ogden paper eqs. (6)-(13) rebuilt (static_models_spec.md O-2): braid force of extensible fibres.

    Radial balance gives the fibre tension, hence the stretched fibre length
    ``b = b0 / (1 - c L)`` with ``c = p b0 / (2 pi n^2 N_s E_f A_f)`` (``n`` turns,
    ``N_s`` strands); the stored energy ``W = N_s A_f b0 E_f e^2 / 2`` with strain
    ``e = c L / (1 - c L)`` gives ``F_braid = dW/dL = N_s A_f b0 E_f e c / (1 - c L)^2``.
    For small strain it is Kothera's eq. (21) term ``p^2 b0^3 L / (4 pi^2 E_f A_f N_s n^4)``.
    """

    def __init__(self, b0: float, turns: float, strands: float, E_f: float, A_f: float):
        self.k = b0 / (2.0 * math.pi * turns ** 2 * strands * E_f * A_f)
        self.stiff = strands * A_f * b0 * E_f

    def p_limit_Pa(self, L_max_m: float) -> float:
        """Pressure [Pa] at which ``c L`` reaches 1 at length ``L_max_m``: no fibre length balances it or more."""
        return 1.0 / (self.k * L_max_m)

    def force_N(self, L, p):
        """Braid force [N]; NaN where ``c L >= 1`` (the fibres cannot hold the pressure: no value)."""
        c = self.k * p
        s = 1.0 - c * L
        if isinstance(s, float):
            if not s > 0.0:
                return math.nan
        else:
            s = np.where(s > 0.0, s, np.nan)
        u = 1.0 / s
        return self.stiff * (c * L * u) * c * u * u


class HyperelasticModel(BladderModel):
    """Gaylord minus a hyperelastic bladder (and, for Ogden, minus the fibre-stretch term)."""

    def __init__(self, params, variant="mean_radius", *, name):
        self.name = name
        super().__init__(params, variant)
        if name == "ogden":
            self.energy = Ogden(tuple((params[f"ogden_mu{i}_Pa"], params[f"ogden_alpha{i}"]) for i in (1, 2, 3)))
            E_f = params["E_braid_Pa"]
            self.braid = (FibreStretch(self.g.b, self.g.N, params["n_fibres"], E_f, params["fibre_area_m2"])
                          if math.isfinite(E_f) else None)
            if self.braid is not None:
                # c L is largest at the rest length; just below the limit the force is finite (and large).
                p_top = self.braid.p_limit_Pa(self.L0) * (1.0 - 1e-9)
                d = self.domain
                self.domain = Domain(d.x_min_m, d.x_max_m, d.p_min_Pa, min(d.p_max_Pa, p_top))
        else:
            self.energy = NeoHookean(params["E_bladder_Pa"])
            self.braid = None

    def force_N(self, x_m, p_gauge_Pa):
        L = self.L0 - x_m
        F = p_gauge_Pa * (3.0 * L * L - self.b2) * self.k_gaylord - elastic_force_N(L, self.g, self.energy, self.variant)
        if self.braid is not None:
            F = F - self.braid.force_N(L, p_gauge_Pa)
        return F


SPECS = (
    StaticModelSpec("ogden", "closed-form", f"{OGDEN}, eqs. (1)-(20) and (23) without friction (rebuilt from the prose)",
                    WALL + ("ogden_mu1_Pa", "ogden_alpha1"), lambda p, v: HyperelasticModel(p, v, name="ogden"),
                    optional=OGDEN_OPTIONAL, variants=STRETCHES,
                    summary="O-1..O-3, O-6 static part: Gaylord - Ogden bladder (up to 3 terms) - fibre stretch"),
    StaticModelSpec("neo_hookean", "closed-form",
                    f"neo-Hookean energy W = (E/6)(I1 - 3) of Trivedi et al. ({SURVEY} eq. (23)) in the energy model of {OGDEN}",
                    WALL + ("E_bladder_Pa",), lambda p, v: HyperelasticModel(p, v, name="neo_hookean"),
                    variants=STRETCHES, summary="Gaylord - neo-Hookean bladder (shared strain-energy routine)"),
)
