"""Paper numbers: Kothera actuator 5a (spec sec. 7), the survey's miniature muscle, and the
identities that tie independent reconstructions together."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pamsim.muscles import load_muscle
from pamsim.static_models import StaticModelDomainError, get
from pamsim.static_models.geometry import Braid
from pamsim.static_models.hyperelastic import FibreStretch
from pamsim.static_models.strain_energy import MooneyRivlin, elastic_force_N

PSI = 6894.757293168361  # Pa per psi (exact conversion; Kothera rounds 60 psi to 415 kPa)
K5A = load_muscle("kothera2009_5a").parameters


def kothera(model, variant=None, **over):
    return get(model).build({**K5A, **over}, variant)


# Kothera 5a, spec sec. 7 ("computed values for regression tests", an independent reconstruction).
BLOCKED = {  # model: F_B [N] at 10, 30, 60 psi
    "gaylord": (11.495, 34.485, 68.970),
    "kothera_force_balance": (11.495, 34.485, 68.970),
    "kothera_force_balance_thickness": (10.259, 30.777, 61.553),
    "kothera_energy": (11.475, 34.309, 68.268),
}
FREE_STRETCH = {  # model: lambda_F = L/L0 at zero load, 10, 30, 60 psi
    "gaylord": (0.788, 0.788, 0.788),
    "kothera_force_balance": (0.968, 0.924, 0.886),
    "kothera_force_balance_thickness": (0.972, 0.927, 0.881),
    "kothera_force_balance_thickness_tips": (0.976, 0.935, 0.894),
    "kothera_mooney_rivlin": (0.958, 0.906, 0.866),
    "kothera_corrected_mooney_rivlin": (0.966, 0.916, 0.874),
    "kothera_energy": (0.966, 0.916, 0.875),
    "kothera_energy_tips": (0.970, 0.926, 0.889),
}
AT_90_PERCENT = {  # model: F [N] at L = 0.9 L0, 30 and 60 psi
    "gaylord": (17.189, 34.378),
    "kothera_force_balance": (-9.673, 7.516),
    "kothera_force_balance_thickness": (-9.821, 9.074),
    "kothera_force_balance_thickness_tips": (-14.465, 2.899),
    "kothera_energy": (-5.342, 11.373),
}


@pytest.mark.parametrize("model", BLOCKED)
def test_kothera_5a_blocked_force(model):
    for psi, expected in zip((10, 30, 60), BLOCKED[model]):
        assert kothera(model).blocked_force_N(psi * PSI) == pytest.approx(expected, rel=5e-3)


def test_kothera_5a_braid_term_at_rest():
    m = kothera("kothera_energy")
    for psi, expected in zip((10, 30, 60), (0.0195, 0.1755, 0.7020)):
        p = psi * PSI
        assert kothera("gaylord").blocked_force_N(p) - m.blocked_force_N(p) == pytest.approx(expected, rel=5e-3)


@pytest.mark.parametrize("model", FREE_STRETCH)
def test_kothera_5a_free_contraction(model):
    L0 = K5A["L0_m"]
    for psi, expected in zip((10, 30, 60), FREE_STRETCH[model]):
        lam = 1.0 - kothera(model).free_contraction_m(psi * PSI, 0.0) / L0
        assert lam == pytest.approx(expected, rel=5e-3, abs=6e-4)  # the spec prints 3 decimals


@pytest.mark.parametrize("model", AT_90_PERCENT)
def test_kothera_5a_force_at_ninety_percent_length(model):
    x = 0.1 * K5A["L0_m"]
    for psi, expected in zip((30, 60), AT_90_PERCENT[model]):
        assert kothera(model).force_N(x, psi * PSI) == pytest.approx(expected, rel=5e-3)


def test_kothera_blocked_force_decrease_is_pressure_independent():
    """Eq. (33) vs eq. (29) at L = L0: both are linear in p, so the ratio is the same at every pressure (10.8 %)."""
    for psi in (10, 30, 60):
        p = psi * PSI
        drop = 1.0 - kothera("kothera_force_balance_thickness").blocked_force_N(p) / kothera("kothera_force_balance").blocked_force_N(p)
        assert drop == pytest.approx(0.108, abs=0.001)


@pytest.mark.xfail(strict=True, reason="Kothera et al. 2009 (text after eq. 33): 'the simulated blocked force decreases "
                   "by 40 % at 10 psi to over 70 % at 60 psi' (eq. 33 vs eq. 29). At L = L0 both models are linear in "
                   "pressure, so no reading can make the decrease pressure-dependent; it is 10.8 % at every pressure "
                   "(static_models_spec.md sec. 7, not reproduced 1)")
def test_kothera_claim_blocked_force_drops_40_to_70_percent():
    drops = [1.0 - kothera("kothera_force_balance_thickness").blocked_force_N(psi * PSI)
             / kothera("kothera_force_balance").blocked_force_N(psi * PSI) for psi in (10, 60)]
    assert drops[0] == pytest.approx(0.40, abs=0.05) and drops[1] > 0.70


def test_kothera_printed_hoop_sign_contracts_beyond_the_kinematic_limit():
    """Why eq. (29)'s printed sign is a typo: actuator 3a would contract past the Gaylord limit (spec K-6)."""
    p3a = load_muscle("kothera2009_3a").parameters
    lock = 1.0 - Braid.from_parameters(p3a).x_lock_m / p3a["L0_m"]
    for variant, beyond in (("printed", True), ("corrected", False)):
        m = get("kothera_force_balance").build(p3a, variant)
        lam = 1.0 - m.free_contraction_m(60 * PSI, 0.0) / p3a["L0_m"]
        assert (lam < lock) is beyond
    assert lock == pytest.approx(0.655, abs=0.001)


def test_kothera_length_independence_without_tips():
    """Kothera's observations: F_B and lambda_F do not depend on L0 (5a, 5b, 5c) without tip correction."""
    ref = None
    for name in ("kothera2009_5a", "kothera2009_5b", "kothera2009_5c"):
        m = load_muscle(name).static_force("kothera_force_balance_thickness")
        L0 = load_muscle(name).parameters["L0_m"]
        got = (m.blocked_force_N(40 * PSI), m.free_contraction_m(40 * PSI) / L0)
        ref = ref or got
        assert got == pytest.approx(ref, rel=1e-9)


# ----------------------------------------------------------------------- identities
def test_chou_hannaford_is_kothera_eq33_with_zero_modulus_and_constant_thickness():
    p = load_muscle("mpam_survey_45mm").parameters
    chou = get("chou_hannaford").build(p)
    k7 = get("kothera_force_balance_thickness").build({**p, "E_bladder_Pa": 0.0}, "constant_thickness")
    x = np.linspace(0.0, chou.domain.x_max_m, 50)
    P = np.array([1e4, 3e5, 7.58e5])[:, None]
    a, b = chou.force_N(x, P), k7.force_N(x, P)
    assert np.all(np.abs(a - b) <= 1e-9 * np.abs(a).max())
    for model in (chou, k7):  # coincide at rest with eq. (33) proper as well
        assert model.blocked_force_N(5e5) == pytest.approx(
            get("kothera_force_balance_thickness").build({**p, "E_bladder_Pa": 0.0}).blocked_force_N(5e5), rel=1e-12)


def test_ogden_with_exponents_two_and_minus_two_is_mooney_rivlin():
    C10, C01 = K5A["C10_Pa"], K5A["C01_Pa"]
    terms = {"ogden_mu1_Pa": 2 * C10, "ogden_alpha1": 2.0, "ogden_mu2_Pa": -2 * C01, "ogden_alpha2": -2.0,
             "E_braid_Pa": math.inf}  # inextensible fibres: K-3 has no braid term
    ogden = get("ogden").build({**K5A, **terms})
    mr = kothera("kothera_corrected_mooney_rivlin")
    x = np.linspace(0.0, 0.9 * mr.domain.x_max_m, 40)
    for p in (0.0, 10 * PSI, 60 * PSI):
        assert np.allclose(ogden.force_N(x, p), mr.force_N(x, p), rtol=1e-10, atol=1e-9)
    thin = get("ogden").build({**K5A, **terms}, "thin")
    assert np.allclose(thin.force_N(x, 3e5), kothera("kothera_mooney_rivlin").force_N(x, 3e5), rtol=1e-10, atol=1e-9)


def test_neo_hookean_is_mooney_rivlin_with_c10_e_over_six():
    E = 0.35e6
    p = load_muscle("mpam_survey_45mm").parameters
    nh = get("neo_hookean").build({**p, "E_bladder_Pa": E})
    g = Braid.from_parameters(p)
    L = g.L0 - np.linspace(0.0, 0.012, 20)
    mr = elastic_force_N(L, g, MooneyRivlin(E / 6.0, 0.0))
    assert np.allclose(nh.force_N(g.L0 - L, 5e5), get("gaylord").build(p).force_N(g.L0 - L, 5e5) - mr, rtol=1e-12)


def test_mooney_rivlin_thin_matches_kotheras_printed_eq5_brace():
    """Kothera eq. (5)'s brace is dW/dlambda for the eq. (7) stretches; the force is -(V_b/L0) brace."""
    g = Braid.from_parameters(K5A)
    C10, C01 = K5A["C10_Pa"], K5A["C01_Pa"]
    a = (g.L0 / (2 * math.pi * g.r0 * g.N)) ** 2
    lam = np.linspace(0.80, 1.0, 21)
    brace = (C10 * (2 * lam * (1 - a) - 2 * lam * (1 + a - 2 * a * lam ** 2) / (lam ** 2 + a * lam ** 2 * (1 - lam ** 2)) ** 2)
             + C01 * (2 * lam * (1 + a - 2 * a * lam ** 2) - 2 / lam ** 3 + 2 * a * lam / (1 + a * (1 - lam ** 2)) ** 2))
    printed = -(g.Vb / g.L0) * brace
    ours = elastic_force_N(lam * g.L0, g, MooneyRivlin(C10, C01), "thin")
    assert np.allclose(ours, printed, rtol=1e-9, atol=1e-9)
    assert np.all(ours[:-1] > 0.0) and abs(ours[-1]) < 1e-9  # resists contraction, zero at rest


def test_fibre_stretch_reduces_to_kotheras_braid_term_for_small_strain():
    g = Braid.from_parameters(K5A)
    n, A, E = K5A["n_fibres"], K5A["fibre_area_m2"], K5A["E_braid_Pa"]
    fs = FibreStretch(g.b, g.N, n, E, A)
    for p in (10.0, 100.0):  # fibre strain ~1e-6: the first-order term is all that is left
        L = 0.95 * g.L0
        kothera21 = p ** 2 * g.b ** 3 * L / (4 * math.pi ** 2 * E * A * n * g.N ** 4)
        assert fs.force_N(L, p) == pytest.approx(kothera21, rel=1e-4)


def test_fibre_stretch_has_no_value_where_no_fibre_length_balances_the_pressure():
    """``b = b0/(1 - c L)``, ``c = p k``: at ``c L >= 1`` the fibres cannot hold the pressure; the model has
    no value there (NaN, outside the domain) instead of a force from a negative fibre length."""
    E_soft = 1e7  # soft fibres bring the limit below the muscle's rating
    params = {**K5A, "ogden_mu1_Pa": 2 * K5A["C10_Pa"], "ogden_alpha1": 2.0, "E_braid_Pa": E_soft}
    m = get("ogden").build(params)
    g = Braid.from_parameters(K5A)
    fs = FibreStretch(g.b, g.N, K5A["n_fibres"], E_soft, K5A["fibre_area_m2"])
    p_limit = 1.0 / (fs.k * g.L0)  # c L = 1 first at the rest length
    assert p_limit < K5A["rated_pressure_gauge_Pa"]
    assert p_limit * (1 - 1e-6) < m.domain.p_max_Pa < p_limit
    assert math.isfinite(m.evaluate_N(0.0, m.domain.p_max_Pa))
    for p in (p_limit, 1.5 * p_limit, 10 * p_limit):
        assert math.isnan(fs.force_N(g.L0, p)) and math.isnan(m.force_N(0.0, p))
        assert np.all(np.isnan(m.force_N(np.array([0.0, 1e-3]), p))) or p == p_limit  # c L < 1 at 1 mm there
        with pytest.raises(StaticModelDomainError):
            m.evaluate_N(0.0, p)
    assert math.isfinite(m.force_N(0.5 * m.domain.x_max_m, 0.9 * p_limit))


def test_trivedi_force_vanishes_at_the_papers_inflation_pressure():
    m = get("trivedi").build({**load_muscle("mpam_survey_45mm").parameters, "E_bladder_Pa": 0.35e6})
    L0 = 0.045
    for lam in (0.95, 0.85, 0.79, 0.75):
        P = m.pressure_Pa(lam)
        assert m.force_N(L0 * (1 - lam), P) == pytest.approx(0.0, abs=1e-9 * P * L0 ** 2)
    assert m.pressure_Pa(1.0) == 0.0


# ---------------------------------------------------- the survey's miniature muscle
MPAM = load_muscle("mpam_survey_45mm").parameters
P_MPAM, LOAD, MEASURED_MM = 758e3, 0.05, 13.0
MINIATURE = {  # name: (model, variant, overrides, load N, spec sec. 7 contraction mm, survey-reported error %)
    "gaylord": ("gaylord", None, {}, LOAD, 12.50, None),
    "chou": ("chou_hannaford", None, {}, LOAD, 16.98, 40),
    "kothera": ("kothera_force_balance_thickness", None, {"E_bladder_Pa": 0.345e6}, LOAD, 13.30, 7),
    "kothera_tips": ("kothera_force_balance_thickness_tips", None, {"E_bladder_Pa": 0.345e6}, LOAD, 12.87, None),
    "hocking": ("hocking", None, {"E_bladder_Pa": 0.352e6}, LOAD, 11.19, 8),
    "sangian": ("sangian", None, {}, LOAD, 12.46, 35),
    # The spec's Trivedi value solves eq. (24) for the free muscle: no load.
    "trivedi": ("trivedi", None, {}, 0.0, 9.52, 29),
}


def _contraction_mm(key):
    model, variant, over, load, _, _ = MINIATURE[key]
    return 1e3 * get(model).build({**MPAM, **over}, variant).free_contraction_m(P_MPAM, load)


@pytest.mark.parametrize("key", MINIATURE)
def test_miniature_muscle_free_contraction(key):
    assert _contraction_mm(key) == pytest.approx(MINIATURE[key][4], rel=0.01)


def test_miniature_muscle_gaylord_limit_and_blocked_force():
    g = Braid.from_parameters(MPAM)
    assert 1e3 * g.b == pytest.approx(55.62, abs=0.01) and g.N == pytest.approx(9.461, abs=0.001)
    assert 1e3 * g.x_lock_m == pytest.approx(12.89, abs=0.01)


def test_miniature_muscle_error_ranking_of_chou_kothera_trivedi_matches_the_survey():
    """Survey: Kothera 7 % < Trivedi 29 % < Chou 40 % (40 mm muscle); against the measured 13 mm on 45 mm."""
    err = {k: abs(_contraction_mm(k) - MEASURED_MM) for k in ("kothera", "trivedi", "chou")}
    assert err["kothera"] < err["trivedi"] < err["chou"]
    assert _contraction_mm("chou") > MEASURED_MM > _contraction_mm("trivedi")  # Chou over-, Trivedi under-predicts


@pytest.mark.xfail(strict=True, reason="The survey ranks Kothera 7 % < Hocking 8 % < Trivedi 29 % < Sangian 35 % < Chou 40 % "
                   "with each model's best-fit parameters, which it does not give. With the parameters it does give "
                   "(Hocking: linear term only; Sangian: no dead band) Sangian is the second best (-4 %) and Hocking "
                   "the third (-14 %) (static_models_spec.md sec. 7)")
def test_miniature_muscle_full_error_ranking_as_the_survey_reports():
    ranked = [k for k in MINIATURE if MINIATURE[k][5] is not None]
    by_survey = sorted(ranked, key=lambda k: MINIATURE[k][5])
    by_us = sorted(ranked, key=lambda k: abs(_contraction_mm(k) - MEASURED_MM))
    assert by_us == by_survey


# ---------------------------------------------------- the survey's two-phase model, phase 1
def test_two_phase_inflection_pressure_with_the_load_left_to_the_braid():
    """Spec S-34: with the load neglected in phase 1, Pbar = 64.9 kPa and u_r = delta at contact."""
    from pamsim.static_models.two_phase import TwoPhaseTube
    tube = TwoPhaseTube.from_parameters(load_muscle("mpam_survey_40mm").parameters)
    P = tube.inflection_pressure_Pa()
    assert P == pytest.approx(64.9e3, rel=0.005)
    u_r, u_z = tube.phase1_displacements_m(P)
    assert u_r == pytest.approx(0.04e-3, rel=0.01) and u_z > 0.0  # phase 1 lengthens the muscle


def test_two_phase_printed_load_term_has_no_inflection_pressure():
    """Spec sec. 7 (not reproduced 3): the survey's P_sil = F/(pi r_i^2) stretches the tube ~73 % under 0.05 N."""
    from pamsim.errors import InputError
    from pamsim.static_models.two_phase import TwoPhaseTube
    tube = TwoPhaseTube.from_parameters(load_muscle("mpam_survey_40mm").parameters)
    strain = tube.phase1_displacements_m(0.0, 0.05, "printed")[1] / tube.l0
    assert strain == pytest.approx(0.73, abs=0.01)
    with pytest.raises(InputError, match="kinematic limit"):
        tube.inflection_pressure_Pa(0.05, "printed")
    with pytest.raises(InputError, match="touches the sleeve at zero pressure"):
        tube.inflection_pressure_Pa(0.05, "annulus")


@pytest.mark.parametrize("c1_sign", [-1.0, 1.0])
def test_two_phase_phase2_has_no_compressive_contact_solution(c1_sign):
    """The specification's phase-2 reduction at a given pressure (contraction free, eq. 74's split): every
    solution has a tensile contact pressure, and there is none at the survey's test pressure (why
    mpam_two_phase solves at imposed contraction instead; see test_static_models_two_phase.py)."""
    from pamsim.static_models.two_phase import TwoPhaseTube
    p = load_muscle("mpam_survey_45mm").parameters
    tube = TwoPhaseTube.from_parameters(p)
    args = (p["n_fibres"], p["fibre_radius_m"], 3e9, p["end_cone_length_m"], c1_sign)  # E_nylon 3 GPa: assumed
    found = 0
    for P in (7e4, 1e5, 2e5, 4e5, 7.58e5):
        sols = tube.phase2_solutions(P, *args)
        found += len(sols)
        assert all(s["P_o_Pa"] < 0.0 and s["F_e_N"] < 0.0 for s in sols)
    assert tube.phase2_solutions(7.58e5, *args) == [] and found > 0


def test_report_prints_every_table_the_docs_quote(capsys):
    from pamsim.static_models import REGISTRY
    from pamsim.muscles.report import main
    main([])
    out = capsys.readouterr().out
    assert all(f"| `{name}` |" in out for name in REGISTRY)
    assert "| lambda_F G+cMR+B+T | 0.970 / 0.926 / 0.889 | 0.970 / 0.926 / 0.889 |" in out
    assert out.count("| not reproduced |") == 4 and "4 of 56 within 0.1 N" in out
    main(["--muscles"])
    assert "| `kothera2009_5a` |" in capsys.readouterr().out


def test_kothera_tip_radius_explicit_and_implicit():
    """Spec K-5: lambda_F of 5a at 60 psi is 0.8893 with R(L) and 0.8910 with R(L') solved implicitly."""
    for variant, expected in (("explicit_radius", 0.8893), ("implicit_radius", 0.8910)):
        m = kothera("kothera_energy_tips", variant)
        assert 1.0 - m.free_contraction_m(60 * PSI) / K5A["L0_m"] == pytest.approx(expected, abs=1e-4)
        L = K5A["L0_m"] - 0.01
        Lc = m.tip_length_m(L)
        R_at = m.g.radius_m(Lc if variant == "implicit_radius" else L)
        assert Lc == pytest.approx(L - 2 * (R_at - K5A["r0_m"]), rel=1e-12)
