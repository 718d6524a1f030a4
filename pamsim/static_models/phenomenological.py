"""Gaylord's normalised law with fitted correction factors, and the purely empirical laws of the survey.

``F = pi r0^2 p k_f(p) (q1 (1 - k_eps(p) eps)^2 - q2)`` with ``eps = x/L0``,
``q1 = 3/tan^2(theta0)``, ``q2 = 1/sin^2(theta0)``: S-04 Tondu-Lopez, S-05/S-30
Itto, S-07 Meller, S-08/S-21 Andrikopoulos, S-29 Takosoglu (its own exponent and
``q1(p)``).  Empirical: S-28 (1.8 mm muscle bundle), S-32 eqs. (46)-(49).
Fitted constants that multiply a pressure inside ``exp`` or ``ln`` carry the
pressure unit they were fitted with as a parameter (``*_pressure_unit_Pa``).
The friction terms of these papers (S-04 eq. 7, S-06, S-21, S-25) depend on the
direction of motion and are not part of these single-valued static maps.
"""

from __future__ import annotations

import math

from .base import Domain, StaticForce, StaticModelSpec, rated_pressure_Pa
from .braid_base import GEOMETRY, BraidModel
from .real_math import exp, log, power
from .sources import SURVEY


class NormalisedGaylord(BraidModel):
    """Base: ``pi r0^2 p k_f(p) (q1 (1 - k_eps(p) eps)^2 - q2)``; subclasses give ``k_f`` and ``k_eps``."""

    def __init__(self, params, variant="default"):
        super().__init__(params, variant)
        self.a = math.pi * self.g.r0 ** 2
        self.q1, self.q2 = self.g.q1, self.g.q2
        self.setup(params)

    def setup(self, params):
        """Read the model's fitted constants."""

    def k_f(self, p):
        """Force correction factor at gauge pressure ``p`` [Pa]: 1 here; subclasses fit it."""
        return 1.0

    def k_eps(self, p):
        """Strain correction factor at gauge pressure ``p`` [Pa]: 1 here; subclasses fit it."""
        return 1.0

    def force_N(self, x_m, p_gauge_Pa):
        s = 1.0 - self.k_eps(p_gauge_Pa) * x_m / self.L0
        return self.a * p_gauge_Pa * self.k_f(p_gauge_Pa) * (self.q1 * s * s - self.q2)


class TonduLopez(NormalisedGaylord):
    """S-04 eq. (6): ``k_eps = kappa1 exp(-p/p_u) + kappa2`` (``p_u`` the fit's pressure unit)."""

    name = "tondu_lopez"

    def setup(self, params):
        self.k1, self.k2 = params["tondu_kappa1"], params["tondu_kappa2"]
        self.pu = params["tondu_pressure_unit_Pa"]

    def k_eps(self, p):
        """Strain correction at gauge pressure ``p`` [Pa]: ``kappa1 exp(-p/p_u) + kappa2``."""
        return self.k1 * exp(-p / self.pu) + self.k2


class Itto(NormalisedGaylord):
    """S-30 eq. (44): ``k_eps = kappa1 (1 + exp(kappa2 p))``; variant ``"keps_l81"``: S-05,
    ``k_eps = kappa1 exp(kappa2 p) + kappa3`` (the survey gives both forms for the same reference)."""

    name = "itto"

    def setup(self, params):
        self.k1, self.k2, self.k3 = params["itto_kappa1"], params["itto_kappa2_per_Pa"], params["itto_kappa3"]

    def k_eps(self, p):
        """Strain correction at gauge pressure ``p`` [Pa], in the form of the variant."""
        e = exp(self.k2 * p)
        return self.k1 * (1.0 + e) if self.variant == "eq44" else self.k1 * e + self.k3


class Meller(NormalisedGaylord):
    """S-07 eq. (13): calibrated on the measured blocked force ``kappa1 p + kappa2`` and the measured
    free contraction ``eps_max(p) = kappa3 ln(p/p_u)``.

    ``F = (kappa1 p + kappa2) (q1 (1 - k_eps eps)^2 - q2)/(q1 - q2)``,
    ``k_eps = (1 - 1/(sqrt(3) cos(theta0)))/eps_max(p)``.  The domain starts at
    ``2 p_u`` so that ``ln`` is positive.
    """

    name = "meller"

    def setup(self, params):
        self.k1, self.k2 = params["meller_kappa1_m2"], params["meller_kappa2_N"]
        self.k3, self.pu = params["meller_kappa3"], params["meller_pressure_unit_Pa"]
        self.lim = 1.0 - math.sqrt(self.q2 / self.q1)
        self.domain = Domain(0.0, self.domain.x_max_m, 2.0 * self.pu, self.domain.p_max_Pa)

    def eps_max(self, p):
        """Measured free contraction (fraction of L0) at gauge pressure ``p`` [Pa]."""
        return self.k3 * log(p / self.pu)

    def force_N(self, x_m, p_gauge_Pa):
        """Static force [N]: the measured blocked force times the normalised Gaylord shape."""
        s = 1.0 - self.lim / self.eps_max(p_gauge_Pa) * x_m / self.L0
        return (self.k1 * p_gauge_Pa + self.k2) * (self.q1 * s * s - self.q2) / (self.q1 - self.q2)


class Andrikopoulos(NormalisedGaylord):
    """S-08 eq. (14) with S-21's thermal strain: ``k_f = F_max/(pi r0^2 P_test (q1 - q2))``,
    ``k_eps = (L0/x_max)(1 - sqrt(q2/q1))``, strain ``eps + alpha_l dT``."""

    name = "andrikopoulos"

    def setup(self, params):
        self.kf = params["andrikopoulos_F_max_N"] / (self.a * params["andrikopoulos_P_test_Pa"] * (self.q1 - self.q2))
        self.ke = self.L0 / params["andrikopoulos_x_max_m"] * (1.0 - math.sqrt(self.q2 / self.q1))
        self.e_th = params["alpha_l_per_K"] * params["delta_T_K"]

    def force_N(self, x_m, p_gauge_Pa):
        """Static force [N] with the thermal strain added to the contraction strain."""
        s = 1.0 - self.ke * (x_m / self.L0 + self.e_th)
        return self.a * p_gauge_Pa * self.kf * (self.q1 * s * s - self.q2)


class Takosoglu(NormalisedGaylord):
    """S-29 eq. (43): ``F = A p (q1(p) (1 - eps)^n(p) - q2)``, ``n = kappa1 exp(-p/kappa2) + kappa3``,
    ``q1 = kappa4 exp(-p/kappa5) + kappa6``; ``A = pi r0^2`` (``"corrected"``) or the printed ``4 pi r0^2``."""

    name = "takosoglu"

    def setup(self, params):
        self.k = [params[f"takosoglu_kappa{i}"] for i in (1, 3, 4, 6)]
        self.k2, self.k5 = params["takosoglu_kappa2_Pa"], params["takosoglu_kappa5_Pa"]
        if self.variant == "printed":
            self.a *= 4.0

    def force_N(self, x_m, p_gauge_Pa):
        """Static force [N] with the pressure-dependent exponent and ``q1``."""
        k1, k3, k4, k6 = self.k
        n = k1 * exp(-p_gauge_Pa / self.k2) + k3
        q1 = k4 * exp(-p_gauge_Pa / self.k5) + k6
        return self.a * p_gauge_Pa * (q1 * power(1.0 - x_m / self.L0, n) - self.q2)


def _bundle(e, p, c):
    return c["kappa2"] + p * (c["kappa1"] * (1.0 - e) ** 2 + c["kappa3"])


def _poly46(e, p, c):
    return (c["k1"] + (c["k2"] + c["k3"] * e) * e) * p + c["k4"] + (c["k5"] + (c["k6"] + (c["k7"] + c["k8"] * e) * e) * e) * e


def _poly47(e, p, c):
    return c["k1"] + (c["k2"] + c["k3"] * e) * e + (c["k4"] + c["k5"] * e) * p


def _poly48(e, p, c):
    return ((c["k1"] * p + c["k2"]) * p + c["k3"]) * e + c["k4"] * p + c["k5"]


def _linear49(e, p, c):
    return c["k1"] * c["Fmax"] * (1.0 - e / c["eps"]) + 0.0 * p  # 0 p: broadcasts like the others


LAWS = {"mpam_bundle_empirical": _bundle, "empirical_poly46": _poly46, "empirical_poly47": _poly47,
        "empirical_poly48": _poly48, "empirical_linear": _linear49}
"""name -> ``law(eps, p, coefficients)``: survey eqs. (41), (46), (47), (48) without its rate term, (49)."""


class Empirical(StaticForce):
    """Survey eqs. (41)/(46)-(49): polynomials in ``eps = x/L0`` and ``p`` with fitted coefficients.

    Only ``L0_m`` is needed; the domain is ``0 <= eps <= 0.99`` (``eps <= eps_max`` for eq. 49).
    Coefficients are named ``<law>_<symbol>_<unit>``; the law sees them by symbol.
    """

    def __init__(self, params, variant="default", *, name, coefficients):
        self.name = name
        self.law = LAWS[name]
        self.L0 = params["L0_m"]
        self.c = {k.split("_")[1]: params[k] for k in coefficients}
        x_max = params["emp49_eps_max"] * self.L0 if name == "empirical_linear" else 0.99 * self.L0
        self.domain = Domain(0.0, x_max, 0.0, rated_pressure_Pa(params))

    def force_N(self, x_m, p_gauge_Pa):
        return self.law(x_m / self.L0, p_gauge_Pa, self.c)


def _empirical(name, coefficients):
    def build(params, variant):
        return Empirical(params, variant, name=name, coefficients=coefficients)
    return build


EMP46 = ("emp46_k1_m2", "emp46_k2_m2", "emp46_k3_m2", "emp46_k4_N", "emp46_k5_N", "emp46_k6_N", "emp46_k7_N", "emp46_k8_N")
EMP47 = ("emp47_k1_N", "emp47_k2_N", "emp47_k3_N", "emp47_k4_m2", "emp47_k5_m2")
EMP48 = ("emp48_k1_m2_per_Pa", "emp48_k2_m2", "emp48_k3_N", "emp48_k4_m2", "emp48_k5_N")
EMP49 = ("emp49_k1", "emp49_Fmax_N", "emp49_eps_max")
BUNDLE = ("bundle_kappa1_m2", "bundle_kappa2_N", "bundle_kappa3_m2")
TAKOSOGLU = ("takosoglu_kappa1", "takosoglu_kappa2_Pa", "takosoglu_kappa3", "takosoglu_kappa4",
             "takosoglu_kappa5_Pa", "takosoglu_kappa6")

SPECS = (
    StaticModelSpec("tondu_lopez", "closed-form", f"Tondu and Lopez (2000), as given in {SURVEY} eq. (6)",
                    GEOMETRY, TonduLopez,
                    optional={"tondu_kappa1": 0.0, "tondu_kappa2": 1.0, "tondu_pressure_unit_Pa": 1e5},
                    summary="S-04 static part: normalised Gaylord with a pressure-dependent end-effect factor k_eps"),
    StaticModelSpec("itto", "closed-form", f"Itto and Kogiso, as given in {SURVEY} eq. (44) and eq. (6) with the k_eps of the text",
                    GEOMETRY + ("itto_kappa1", "itto_kappa2_per_Pa"), Itto, optional={"itto_kappa3": 0.0},
                    variants=("eq44", "keps_l81"), summary="S-30 / S-05: normalised Gaylord, exponential k_eps"),
    StaticModelSpec("meller", "closed-form", f"Meller et al., as given in {SURVEY} eq. (13)",
                    GEOMETRY + ("meller_kappa1_m2", "meller_kappa2_N", "meller_kappa3"), Meller,
                    optional={"meller_pressure_unit_Pa": 1.0},
                    summary="S-07: normalised Gaylord calibrated on measured blocked force and free contraction"),
    StaticModelSpec("andrikopoulos", "closed-form", f"Andrikopoulos et al., as given in {SURVEY} eqs. (14) and (33) (static part)",
                    GEOMETRY + ("andrikopoulos_F_max_N", "andrikopoulos_x_max_m", "andrikopoulos_P_test_Pa"), Andrikopoulos,
                    optional={"alpha_l_per_K": 0.0, "delta_T_K": 0.0},
                    summary="S-08/S-21: normalised Gaylord with constant factors from one calibration test, thermal strain"),
    StaticModelSpec("takosoglu", "closed-form", f"Takosoglu et al., as given in {SURVEY} eq. (43)",
                    GEOMETRY + TAKOSOGLU, Takosoglu, variants=("corrected", "printed"),
                    summary="S-29: Gaylord with pressure-dependent q1 and exponent"),
    StaticModelSpec("mpam_bundle_empirical", "closed-form", f"{SURVEY} eq. (41) (force form), 1.8 mm muscle bundle",
                    ("L0_m",) + BUNDLE, _empirical("mpam_bundle_empirical", BUNDLE),
                    summary="S-28: F = kappa2 + p (kappa1 (1 - eps)^2 + kappa3)"),
    StaticModelSpec("empirical_poly46", "closed-form", f"{SURVEY} eq. (46)", ("L0_m",) + EMP46,
                    _empirical("empirical_poly46", EMP46), summary="S-32: quadratic in eps times p plus quartic in eps"),
    StaticModelSpec("empirical_poly47", "closed-form", f"{SURVEY} eq. (47)", ("L0_m",) + EMP47,
                    _empirical("empirical_poly47", EMP47), summary="S-32: bilinear-quadratic in eps and p"),
    StaticModelSpec("empirical_poly48", "closed-form", f"{SURVEY} eq. (48) without its rate term", ("L0_m",) + EMP48,
                    _empirical("empirical_poly48", EMP48), summary="S-32: quadratic in p times eps plus linear in p"),
    StaticModelSpec("empirical_linear", "closed-form", f"{SURVEY} eq. (49)", ("L0_m",) + EMP49,
                    _empirical("empirical_linear", EMP49), summary="S-32: F = k1 F_max (1 - eps/eps_max), pressure-independent"),
)
