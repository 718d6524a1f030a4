"""Gaylord's ideal model and the closed-form models that keep its braid kinematics unchanged.

S-01/K-1/O-1/A-1 Gaylord, S-02 normalised Gaylord, S-03 Chou-Hannaford with wall
thickness, S-22 Zang (preliminary FEA form), S-23 de Volder (dead band and length
correction).  Contraction ``x = L0 - L`` [m], gauge pressure ``p`` [Pa], force [N].
"""

from __future__ import annotations

import math
import numpy as np

from .base import StaticModelSpec
from .braid_base import GEOMETRY, WALL, BraidModel
from .real_math import sqrt
from .sources import ACRA2012, KOTHERA2009, SURVEY


def gaylord_angle_N(theta_rad, p_gauge_Pa, b_m: float, N_turns: float):
    """Survey eq. (3): ``b^2/(4 pi N^2) p (3 cos^2(theta) - 1)`` with ``theta`` from the axis [rad]."""
    return b_m ** 2 / (4.0 * math.pi * N_turns ** 2) * p_gauge_Pa * (3.0 * np.cos(theta_rad) ** 2 - 1.0)


def gaylord_contraction_N(x_m, p_gauge_Pa, L0_m: float, b_m: float, N_turns: float):
    """ACRA 2012 eq. (2) as rebuilt: ``p (3 x^2 - 6 L0 x + 3 L0^2 - b^2) / (4 pi N^2)``, ``x = L0 - L``."""
    return p_gauge_Pa * (3.0 * x_m ** 2 - 6.0 * L0_m * x_m + (3.0 * L0_m ** 2 - b_m ** 2)) / (4.0 * math.pi * N_turns ** 2)


class Gaylord(BraidModel):
    """Kothera eq. (2): ``F = p (3 L^2 - b^2) / (4 pi N^2)``; domain up to the kinematic limit."""

    name = "gaylord"

    def force_N(self, x_m, p_gauge_Pa):
        L = self.L0 - x_m
        return p_gauge_Pa * (3.0 * L * L - self.b2) * self.k_gaylord


class GaylordNormalised(BraidModel):
    """Survey eq. (4): ``pi r0^2 p (q1 (1 - eps)^2 - q2)``, ``eps = x / L0``."""

    name = "gaylord_normalised"

    def __init__(self, params, variant="default"):
        super().__init__(params, variant)
        self.a = math.pi * self.g.r0 ** 2
        self.q1, self.q2 = self.g.q1, self.g.q2

    def force_N(self, x_m, p_gauge_Pa):
        s = 1.0 - x_m / self.L0
        return self.a * p_gauge_Pa * (self.q1 * s * s - self.q2)


class ChouHannaford(BraidModel):
    """Survey eq. (5): Gaylord plus ``pi p ((b t0/(N pi)) (2 sin(theta) - 1/sin(theta)) - t0^2)``.

    The wall thickness stays ``t0``.  The model predicts contraction beyond
    Gaylord's limit, so its domain runs to where the (incompressible) bladder
    would fill the braid.
    """

    name = "chou_hannaford"

    def __init__(self, params, variant="default"):
        super().__init__(params, variant)
        t0 = self.g.t0
        self.c1 = self.g.b * t0 / self.g.N  # pi * (b t0 / (N pi))
        self.c0 = math.pi * t0 * t0

    def x_max_m(self, params):
        return self.g.x_fill_m()

    def force_N(self, x_m, p_gauge_Pa):
        L = self.L0 - x_m
        s = sqrt(1.0 - L * L / self.b2)
        return p_gauge_Pa * ((3.0 * L * L - self.b2) * self.k_gaylord + self.c1 * (2.0 * s - 1.0 / s) - self.c0)


class Zang(BraidModel):
    """Survey eq. (34), preliminary FEA model: ``F = 2 pi r0^2 p (1 - eps)^2 / tan^2(theta0)``.

    Implemented as printed; it is not Gaylord's law (no ``q2`` term, factor 2 not 3).
    Domain: contraction up to the Gaylord limit, like the other braid models.
    """

    name = "zang"

    def __init__(self, params, variant="default"):
        super().__init__(params, variant)
        self.a = 2.0 * math.pi * self.g.r0 ** 2 / math.tan(self.g.theta0) ** 2

    def force_N(self, x_m, p_gauge_Pa):
        s = 1.0 - x_m / self.L0
        return self.a * p_gauge_Pa * s * s


class DeVolder(BraidModel):
    """Survey eq. (35) rebuilt: ``max(F_min, (p - P_corr) b^2/(4 pi N^2) (3 (L - l_corr)^2/b^2 - 1)) + max(0, k_b (L - l_b0))``.

    The printed ``3 (l - l_corr)^2 / b`` is dimensionally wrong; ``/b^2`` reduces to
    Gaylord for ``P_corr = l_corr = 0``.  With the optional defaults
    (no dead band, no length correction, no clip, no bladder spring) it is Gaylord.
    """

    name = "de_volder"

    def __init__(self, params, variant="default"):
        super().__init__(params, variant)
        self.P_corr = params["devolder_P_corr_Pa"]
        self.l_corr = params["devolder_l_corr_m"]
        self.F_min = params["devolder_F_min_N"]
        self.k_b = params["devolder_k_b_N_per_m"]
        self.l_b0 = params["devolder_l_b0_m"]

    def force_N(self, x_m, p_gauge_Pa):
        L = self.L0 - x_m
        Lc = L - self.l_corr
        f = (p_gauge_Pa - self.P_corr) * (3.0 * Lc * Lc - self.b2) * self.k_gaylord
        spring = self.k_b * (L - self.l_b0)
        if isinstance(f, float) and isinstance(spring, float):
            return max(self.F_min, f) + max(0.0, spring)
        return np.maximum(self.F_min, f) + np.maximum(0.0, spring)


SPECS = (
    StaticModelSpec("gaylord", "closed-form",
                    f"Gaylord's ideal model: {SURVEY} eq. (3); {KOTHERA2009} eq. (2); {ACRA2012} eq. (2)",
                    GEOMETRY, Gaylord, summary="ideal virtual-work model, inextensible braid, no bladder"),
    StaticModelSpec("gaylord_normalised", "closed-form", f"{SURVEY} eq. (4) (Tondu-Lopez basic form)",
                    GEOMETRY, GaylordNormalised, summary="Gaylord in normalised form; identical to gaylord"),
    StaticModelSpec("chou_hannaford", "closed-form", f"Chou and Hannaford (1996) as given in {SURVEY} eq. (5)",
                    WALL, ChouHannaford, summary="Gaylord plus a constant-thickness bladder wall term"),
    StaticModelSpec("zang", "closed-form", f"Zang, preliminary FEA model, as given in {SURVEY} eq. (34)",
                    GEOMETRY, Zang, summary="preliminary model, printed form (not Gaylord's law)"),
    StaticModelSpec("de_volder", "closed-form", f"de Volder, as given in {SURVEY} eq. (35) (rebuilt: /b^2)",
                    GEOMETRY, DeVolder,
                    optional={"devolder_P_corr_Pa": 0.0, "devolder_l_corr_m": 0.0, "devolder_F_min_N": -math.inf,
                              "devolder_k_b_N_per_m": 0.0, "devolder_l_b0_m": 0.0},
                    summary="Gaylord with a dead-band pressure, a length correction, a force floor and a bladder spring"),
)
