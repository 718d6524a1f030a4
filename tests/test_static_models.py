"""The static-model library: registry contract, identities and hand calculations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pamsim.errors import InputError
from pamsim.parameters import get_parameter_set
from pamsim.static_models import KINDS, REGISTRY, StaticModelDomainError, get, names
from pamsim.static_models.gaylord import gaylord_angle_N, gaylord_contraction_N
from pamsim.static_models.geometry import Braid

LOCK_DEG = math.degrees(math.acos(1 / math.sqrt(3)))
MPAM_45 = {"L0_m": 0.045, "r0_m": 0.55e-3, "theta0_deg": 36.0, "wall_thickness_m": 0.30e-3}  # survey Fig. 18 caption


def test_registry_contract():
    assert names() == list(REGISTRY)
    for name, spec in REGISTRY.items():
        assert spec.name == name and spec.kind in KINDS and spec.source and spec.variants
        assert name == name.lower() and " " not in name


def test_unknown_model_error_suggests_the_closest_name():
    with pytest.raises(InputError, match=r"static model = 'gaylor': unknown model \(did you mean 'gaylord'\?\)"):
        get("gaylor")


def test_missing_parameters_are_named():
    spec = get("chou_hannaford")
    assert spec.missing({"L0_m": 1}) == ["r0_m", "theta0_deg", "wall_thickness_m"]
    with pytest.raises(InputError, match="needs parameter.*wall_thickness_m"):
        spec.build({k: v for k, v in MPAM_45.items() if k != "wall_thickness_m"})


def test_polynomial_is_the_library_entry_and_matches_a_hand_value():
    from pamsim.elements.static_force import STATIC_FORCE_MODELS
    P = get_parameter_set("shadow_6x300_acra2012")
    model = get("acra2012_polynomial").build(P)
    assert STATIC_FORCE_MODELS["acra2012_polynomial"](P).force_N(0.03, 3.6e5) == model.force_N(0.03, 3.6e5)
    x, Pb = 0.03, 3.6  # eq. (11) by hand, P in bar and x in metres
    hand = (-476.95 * x * x - 188.39 * x + 23.90) * Pb + 2562.4 * x * x - 245.48 * x - 11.56
    assert model.force_N(x, Pb * 1e5) == pytest.approx(hand, rel=1e-12)
    assert model.domain.x_max_m == P["fit_x_max_m"] and model.domain.p_max_Pa == P["fit_p_max_Pa"]


def test_gaylord_vanishes_at_the_locking_angle():
    g = Braid.from_parameters(MPAM_45)
    theta = math.radians(LOCK_DEG)
    assert abs(gaylord_angle_N(theta, 7e5, g.b, g.N)) < 1e-12
    L_lock = g.b * math.cos(theta)
    model = get("gaylord").build(MPAM_45)
    assert abs(model.force_N(g.L0 - L_lock, 7e5)) < 1e-12
    assert model.domain.x_max_m == pytest.approx(g.L0 - L_lock, rel=1e-12)
    assert LOCK_DEG == pytest.approx(54 + 44 / 60, abs=0.01)  # survey: 54 deg 44'


def test_gaylord_forms_in_length_angle_contraction_and_normalised_agree():
    g = Braid.from_parameters(MPAM_45)
    x = np.linspace(0.0, g.x_lock_m, 7)
    p = np.array([1e5, 4e5, 7.58e5])[:, None]
    ref = get("gaylord").build(MPAM_45).force_N(x, p)
    theta = np.arccos((g.L0 - x) / g.b)
    scale = np.max(np.abs(ref))
    for other in (gaylord_contraction_N(x, p, g.L0, g.b, g.N), gaylord_angle_N(theta, p, g.b, g.N),
                  get("gaylord_normalised").build(MPAM_45).force_N(x, p)):
        assert np.max(np.abs(other - ref)) < 1e-12 * scale
    # Blocked force pi r0^2 p (q1 - q2) and the survey's derived 2.01 N at 758 kPa (spec sec. 5.2).
    blocked = math.pi * g.r0 ** 2 * 7.58e5 * (g.q1 - g.q2)
    assert get("gaylord").build(MPAM_45).blocked_force_N(7.58e5) == pytest.approx(blocked, rel=1e-12)
    assert blocked == pytest.approx(2.01, abs=0.005)


def test_evaluate_checks_the_domain_and_force_n_does_not():
    model = get("gaylord").build({**MPAM_45, "rated_pressure_gauge_Pa": 8e5})
    with pytest.raises(StaticModelDomainError, match=r"'gaylord': x_m = 0.02 lies outside \[0, 0.012886\] m"):
        model.evaluate_N(0.02, 5e5)
    with pytest.raises(StaticModelDomainError, match=r"p_gauge_Pa = 900000 lies outside \[0, 800000\] Pa"):
        model.evaluate_N(np.array([0.0, 0.001]), np.array([5e5, 9e5]))
    assert model.evaluate_N(0.001, 5e5) == model.force_N(0.001, 5e5)
    assert model.force_N(0.02, 5e5) < 0.0  # raw value outside the domain: negative, no check


def test_free_contraction_solves_the_equilibrium():
    model = get("gaylord").build(MPAM_45)
    x = model.free_contraction_m(7.58e5, 0.05)
    assert model.force_N(x, 7.58e5) == pytest.approx(0.05, abs=1e-9)
    g = Braid.from_parameters(MPAM_45)  # closed-form inverse (spec S-01): L = sqrt((4 pi N^2 F / P + b^2) / 3)
    L = math.sqrt((4 * math.pi * g.N ** 2 * 0.05 / 7.58e5 + g.b ** 2) / 3)
    assert x == pytest.approx(g.L0 - L, rel=1e-9)
    assert model.free_contraction_m(1e3, 5.0) == 0.0  # cannot lift it


def _gaylord_expansion():
    """Gaylord's normalised law as a polynomial in eps: A p ((q1 - q2) - 2 q1 eps + q1 eps^2)."""
    g = Braid.from_parameters(MPAM_45)
    A = math.pi * g.r0 ** 2
    return A * (g.q1 - g.q2), -2 * A * g.q1, A * g.q1, g


def _reductions():
    a0, a1, a2, g = _gaylord_expansion()
    blocked_ptest = math.pi * g.r0 ** 2 * 4e5 * (g.q1 - g.q2)
    W = {**MPAM_45, "E_bladder_Pa": 0.0}
    return {  # model: (parameters with the extra constants that make it its parent, variant, parent)
        "tondu_lopez": (MPAM_45, None, "gaylord"),
        "de_volder": (MPAM_45, None, "gaylord"),
        "itto": ({**MPAM_45, "itto_kappa1": 0.5, "itto_kappa2_per_Pa": 0.0}, "eq44", "gaylord"),
        "andrikopoulos": ({**MPAM_45, "andrikopoulos_F_max_N": blocked_ptest, "andrikopoulos_P_test_Pa": 4e5,
                           "andrikopoulos_x_max_m": g.x_lock_m}, None, "gaylord"),
        "takosoglu": ({**MPAM_45, "takosoglu_kappa1": 0.0, "takosoglu_kappa2_Pa": 1.0, "takosoglu_kappa3": 2.0,
                       "takosoglu_kappa4": 0.0, "takosoglu_kappa5_Pa": 1.0, "takosoglu_kappa6": g.q1}, None, "gaylord"),
        "mpam_bundle_empirical": ({**MPAM_45, "bundle_kappa1_m2": a2, "bundle_kappa2_N": 0.0,
                                   "bundle_kappa3_m2": a0 - a2}, None, "gaylord"),
        "empirical_poly46": ({**MPAM_45, "emp46_k1_m2": a0, "emp46_k2_m2": a1, "emp46_k3_m2": a2,
                              **{f"emp46_k{i}_N": 0.0 for i in range(4, 9)}}, None, "gaylord"),
        "sangian": (W, None, "gaylord"),
        "hocking": (W, None, "gaylord"),
        "neo_hookean": (W, None, "gaylord"),
        "kothera_force_balance": (W, None, "gaylord"),
        "pillsbury": ({**MPAM_45, "pillsbury_E1I_Pa": 0.0, "pillsbury_E1S": 0.0}, None, "chou_hannaford"),
    }


@pytest.mark.parametrize("model", list(_reductions()))
def test_each_model_reduces_to_its_parent_when_its_extra_constants_vanish(model):
    params, variant, parent = _reductions()[model]
    m, ref = get(model).build(params, variant), get(parent).build(MPAM_45)
    x = np.linspace(0.0, 0.99 * min(m.domain.x_max_m, ref.domain.x_max_m), 30)
    p = np.array([1e5, 4e5, 7.58e5])[:, None]
    assert np.allclose(m.force_N(x, p), ref.force_N(x, p), rtol=1e-9, atol=1e-12 * ref.blocked_force_N(7.58e5))


def test_linear_empirical_laws_are_gaylords_first_order_expansion():
    a0, a1, a2, g = _gaylord_expansion()
    eps = np.linspace(0.0, 0.2, 9)
    p = 5e5
    first_order = p * (a0 + a1 * eps)
    m47 = get("empirical_poly47").build({**MPAM_45, "emp47_k1_N": 0.0, "emp47_k2_N": 0.0, "emp47_k3_N": 0.0,
                                         "emp47_k4_m2": a0, "emp47_k5_m2": a1})
    m48 = get("empirical_poly48").build({**MPAM_45, "emp48_k1_m2_per_Pa": 0.0, "emp48_k2_m2": a1, "emp48_k3_N": 0.0,
                                         "emp48_k4_m2": a0, "emp48_k5_N": 0.0})
    m49 = get("empirical_linear").build({**MPAM_45, "emp49_k1": 0.5, "emp49_Fmax_N": 4.0, "emp49_eps_max": 0.25})
    for m in (m47, m48):
        assert np.allclose(m.force_N(eps * g.L0, p), first_order, rtol=1e-12)
    assert m49.force_N(0.0, 1e5) == pytest.approx(2.0) and m49.force_N(0.25 * g.L0, 7e5) == pytest.approx(0.0, abs=1e-12)


def test_zang_by_hand():
    g = Braid.from_parameters(MPAM_45)
    x, p = 0.004, 6e5
    hand = 2 * math.pi * g.r0 ** 2 * p * (1 - x / g.L0) ** 2 / math.tan(g.theta0) ** 2
    assert get("zang").build(MPAM_45).force_N(x, p) == pytest.approx(hand, rel=1e-12)
    assert get("takosoglu").build({**MPAM_45, "takosoglu_kappa1": 0.0, "takosoglu_kappa2_Pa": 1.0, "takosoglu_kappa3": 2.0,
                                   "takosoglu_kappa4": 0.0, "takosoglu_kappa5_Pa": 1.0, "takosoglu_kappa6": g.q1},
                                  "printed").force_N(x, p) == pytest.approx(4 * get("gaylord").build(MPAM_45).force_N(x, p))


def test_stiffness_is_minus_the_derivative_of_the_force():
    g = Braid.from_parameters(MPAM_45)
    m = get("gaylord").build(MPAM_45)
    x, p = 0.005, 7.58e5
    L = g.L0 - x
    assert m.stiffness_N_per_m(x, p) == pytest.approx(6 * L * p / (4 * math.pi * g.N ** 2), rel=1e-7)  # dF/dL by hand
    xs = np.array([0.001, 0.004])
    assert np.allclose(m.stiffness_N_per_m(xs, p), 6 * (g.L0 - xs) * p / (4 * math.pi * g.N ** 2), rtol=1e-7)
