"""Every row of the papers' reference file that pins a value is a test (parametrised from the shipped copy).

Rows that cannot be tested (relative errors against figures missing from the
papers' text, best-fit parameters the papers do not give) are listed in
``UNTESTABLE`` with the reason; a test checks that every row is either tested or
listed, so none is dropped silently.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pamsim.muscles import load_muscle
from pamsim.paperdata import acra2012_steady_state
from pamsim.static_models import get
from pamsim.static_models.geometry import Braid
from pamsim.static_models.reference import acra_point, is_acra_point, reference_points, table3_estimate_N

ROWS = reference_points()
PSI = 6894.757293168361
MPAM45 = load_muscle("mpam_survey_45mm").parameters
SHADOW = load_muscle("shadow_6x300_acra2012")
POLY = SHADOW.static_force()


def rows(predicate):
    """(index, row) pairs for pytest ids."""
    return [pytest.param(i, r, id=f"row{i + 2}") for i, r in enumerate(ROWS) if predicate(r)]


def _model(r):
    return r["model"]


def hung_weight_N(r):
    """The weight hung in the test of an ACRA row, found in the steady-state tables by (P_stable, x_stable)."""
    P, x = acra_point(r)
    data = acra2012_steady_state()
    hit = (np.abs(data["pressure_stable_bar"] - P / 1e5) < 5e-4) & (np.abs(data["contraction_stable_mm"] - x * 1e3) < 5e-4)
    assert hit.sum() == 1
    return float(data["weight_N"][hit][0])


# --------------------------------------------------------------------- identities (S-01, S-02, S-07, S-08)
@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("S-01")))
def test_gaylord_zero_at_the_locking_angle(i, r):
    theta = math.radians(54.7356)
    g = Braid.from_parameters(MPAM45)
    assert get("gaylord").build(MPAM45).force_N(g.L0 - g.b * math.cos(theta), 5e5) == pytest.approx(0.0, abs=1e-5)


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("S-02")))
def test_normalised_gaylord_zero_at_eps_max(i, r):
    for theta0 in (20.0, 36.0, 45.0):
        p = {**MPAM45, "theta0_deg": theta0}
        eps_max = 1.0 - 1.0 / (math.sqrt(3.0) * math.cos(math.radians(theta0)))
        m = get("gaylord_normalised").build(p)
        assert abs(m.force_N(eps_max * p["L0_m"], 7e5)) < 1e-12 * m.blocked_force_N(7e5)


MELLER = {"meller_kappa1_m2": 2.5e-6, "meller_kappa2_N": -0.1, "meller_kappa3": 0.02}  # assumed test values
ANDRIKOPOULOS = {"andrikopoulos_F_max_N": 1.8, "andrikopoulos_x_max_m": 0.011, "andrikopoulos_P_test_Pa": 7.58e5}


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("S-07")))
def test_meller_calibration_identities(i, r):
    m = get("meller").build({**MPAM45, **MELLER})
    for P in (3e5, 7.58e5):
        if r["contraction_or_length"] == "eps=0":
            assert m.force_N(0.0, P) == pytest.approx(MELLER["meller_kappa1_m2"] * P + MELLER["meller_kappa2_N"], rel=1e-12)
        else:
            assert abs(m.force_N(m.eps_max(P) * MPAM45["L0_m"], P)) < 1e-12


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("S-08 Andrikopoulos eq.(14)")))
def test_andrikopoulos_calibration_identities(i, r):
    m = get("andrikopoulos").build({**MPAM45, **ANDRIKOPOULOS})
    P = ANDRIKOPOULOS["andrikopoulos_P_test_Pa"]
    if r["contraction_or_length"] == "eps=0":
        assert m.force_N(0.0, P) == pytest.approx(ANDRIKOPOULOS["andrikopoulos_F_max_N"], rel=1e-12)
    else:
        assert abs(m.force_N(ANDRIKOPOULOS["andrikopoulos_x_max_m"], P)) < 1e-12


# --------------------------------------------------------------------- ACRA 2012 polynomial
@pytest.mark.parametrize("i, r", rows(lambda r: is_acra_point(r) and r["force_N_expected"]))
def test_acra_polynomial_holds_the_hung_weight(i, r):
    """Training points: exact (0.015 N); others: the paper's 7 %, or the error it reports for the three it flags."""
    P, x = acra_point(r)
    W = float(r["force_N_expected"])
    F = POLY.force_N(x, P)
    if "TRAINING POINT" in r["tolerance_or_reported_error"]:
        assert F == pytest.approx(W, abs=0.015)
        return
    flagged = {(2.417, 12.74): 0.13, (1.632, 22.74): 0.13, (2.425, 22.74): 0.08}  # paper: "13 %, 13 % and 8 %"
    assert abs(F - W) / W <= flagged.get((P / 1e5, W), 0.07)


@pytest.mark.parametrize("i, r", rows(lambda r: is_acra_point(r) and "BEYOND FORCE CAPABILITY" in r["tolerance_or_reported_error"]))
def test_acra_polynomial_cannot_hold_the_weight_beyond_its_capability(i, r):
    P, x = acra_point(r)
    assert POLY.force_N(x, P) < hung_weight_N(r)


TABLE3_MATCHES = {(2.04, 24.45), (3.634, 59.67), (2.815, 10.542), (3.227, 11.1)}  # spec sec. 7: 2 of 25 (+ 2 shaded)


def _table3(r):
    return is_acra_point(r) and table3_estimate_N(r) is not None


@pytest.mark.parametrize("i, r", [
    pytest.param(i, r, id=f"row{i + 2}", marks=() if (float(r["pressure_value"]), round(acra_point(r)[1] * 1e3, 3)) in TABLE3_MATCHES
                 else pytest.mark.xfail(strict=True, reason="ACRA 2012 Table 3 does not follow from eq. (11) with the printed "
                                        "coefficients, which do reproduce the training set exactly (spec sec. 7, A14)"))
    for i, r in enumerate(ROWS) if _table3(r)])
def test_acra_table3_estimate(i, r):
    P, x = acra_point(r)
    assert POLY.force_N(x, P) == pytest.approx(table3_estimate_N(r), abs=0.1)


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("A-2") and "plateau" in r["tolerance_or_reported_error"]))
@pytest.mark.xfail(strict=True, reason="the paper's 'around 46 N to 47 N' plateau at 2.8 bar comes from its Table 3, which eq. (11) "
                   "does not reproduce: eq. (11) gives 47.7, 48.0 and 49.6 N at the three points (spec sec. 7)")
def test_acra_force_plateau_at_2_8_bar(i, r):
    F = [POLY.force_N(x * 1e-3, P * 1e5) for P, x in ((2.815, 10.542), (2.703, 6.703), (2.705, 4.69))]
    assert all(46.0 <= f <= 47.0 for f in F)


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("A-4")))
def test_chou_hannaford_constant_friction_value(i, r):
    assert SHADOW.parameters["coulomb_constant_N"] == float(r["force_N_expected"])


# --------------------------------------------------------------------- the survey's miniature muscle
def _stiffness_N_per_mm(model, over, P=7.58e5, load=0.05):
    m = get(model).build({**MPAM45, **over})
    return m.stiffness_N_per_m(m.free_contraction_m(P, load), P) / 1e3


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("EXPERIMENT") and "45mm" in r["muscle"]))
def test_measured_13_mm_is_reproduced_by_kotheras_eq33_with_tips(i, r):
    m = get("kothera_force_balance_thickness_tips").build({**MPAM45, "E_bladder_Pa": 0.345e6})
    assert 1e3 * m.free_contraction_m(7.58e5, float(r["force_N_expected"])) == pytest.approx(13.0, abs=0.2)


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("EXPERIMENT") and "l0=40mm" in r["muscle"]))
@pytest.mark.xfail(strict=True, reason="the measured muscle is about 10x stiffer than the phenomenological models "
                   "(survey sec. 4): Kothera's eq. (33) moves 0.96 mm between 0.05 N and 0.147 N, the muscle < 0.3 mm")
def test_load_change_moves_the_40mm_muscle_less_than_0_3_mm(i, r):
    m = load_muscle("mpam_survey_40mm").static_force("kothera_force_balance_thickness", overrides={"E_bladder_Pa": 0.345e6})
    assert 1e3 * (m.free_contraction_m(8.27e5, 0.05) - m.free_contraction_m(8.27e5, 0.147)) < 0.3


STIFFNESS = {  # spec sec. 7 (independent reconstruction), N/mm at the 758 kPa datum
    "chou_hannaford": ({}, 0.066), "kothera_force_balance_thickness": ({"E_bladder_Pa": 0.345e6}, 0.082),
    "sangian": ({}, 0.119), "hocking": ({"E_bladder_Pa": 0.352e6}, 0.147)}


@pytest.mark.parametrize("i, r", rows(lambda r: "stiffness" in r["contraction_or_length"] and (
    _model(r).startswith("other phenomenological") or _model(r).startswith("S-24"))))
def test_phenomenological_models_are_several_times_too_soft(i, r):
    """Survey: 'very large error in the stiffness value (in the order of 10)'; measured 0.63 N/mm."""
    names = ["hocking"] if _model(r).startswith("S-24") else ["chou_hannaford", "kothera_force_balance_thickness", "sangian"]
    for name in names:
        over, spec_value = STIFFNESS[name]
        k = _stiffness_N_per_mm(name, over)
        assert k == pytest.approx(spec_value, abs=0.001)
        assert 4.0 <= 0.63 / k <= 15.0


# --------------------------------------------------------------------- Kothera
K = {n: load_muscle(f"kothera2009_5{n}") for n in "abc"}


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("K-7") and "decreases" in r["tolerance_or_reported_error"]))
@pytest.mark.xfail(strict=True, reason="eq. (33) vs eq. (29) at L = L0 are both linear in pressure: the blocked force drops "
                   "by 10.8 % at every pressure, not 40 % at 10 psi and > 70 % at 60 psi (spec sec. 7, A1)")
def test_kothera_eq33_blocked_force_decrease(i, r):
    psi = float(r["pressure_value"])
    m33, m29 = (K["a"].static_force(n) for n in ("kothera_force_balance_thickness", "kothera_force_balance"))
    drop = 1.0 - m33.blocked_force_N(psi * PSI) / m29.blocked_force_N(psi * PSI)
    assert drop == pytest.approx(0.40, abs=0.05) if psi == 10 else drop > 0.70


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("K-5")))
def test_kothera_tip_correction_leaves_blocked_force_unchanged(i, r):
    for plain, tips in (("kothera_energy", "kothera_energy_tips"),
                        ("kothera_force_balance_thickness", "kothera_force_balance_thickness_tips")):
        for psi in (10, 60):
            assert K["a"].static_force(tips).blocked_force_N(psi * PSI) == pytest.approx(
                K["a"].static_force(plain).blocked_force_N(psi * PSI), rel=1e-12)


@pytest.mark.parametrize("i, r", rows(lambda r: _model(r).startswith("K-1")))
def test_kothera_length_independence(i, r):
    """F_B and lambda_F do not depend on L0 (5a/5b/5c); with tips lambda_F varies a little."""
    for model, tol in (("kothera_energy", 1e-9), ("kothera_force_balance_thickness", 1e-9),
                       ("kothera_energy_tips", None), ("kothera_force_balance_thickness_tips", None)):
        for psi in (10, 60):
            ms = [K[n].static_force(model) for n in "abc"]
            if "blocked" in r["contraction_or_length"]:
                fb = [m.blocked_force_N(psi * PSI) for m in ms]
                assert max(fb) - min(fb) <= 1e-9 * fb[0]
                continue
            lam = [1 - m.free_contraction_m(psi * PSI) / K[n].parameters["L0_m"] for m, n in zip(ms, "abc")]
            spread = max(lam) - min(lam)
            assert spread <= 1e-9 if tol else 1e-4 < spread < 0.02


# --------------------------------------------------------------------- coverage
UNTESTABLE = {
    "S-34": "two-phase model: errors against the survey's Figs. 13-19, whose data are not in the text",
    "S-03": "survey error against Fig. 13/14 curves (not in the text) with best-fit parameters (not given)",
    "S-18": "Liu's model is not implementable (garbled, needs a shooting method); Fig. 13/14 data missing",
    "S-11": "survey error against Fig. 13/14 curves (not in the text) with best-fit parameters (not given)",
    "S-08/S-21": "Andrikopoulos' best-fit calibration values and the Fig. 13/14 curves are not given",
    "S-14": "survey error against Fig. 13/14 curves (not in the text) with best-fit parameters (not given)",
    "S-24": "survey error against Fig. 13/14 curves (not in the text) with best-fit parameters (not given)",
    "S-27": "survey error against Fig. 13/14 curves (not in the text) with best-fit parameters (not given)",
    "K-2": "relative error against data of Kothera's ref. [31] (not given)",
    "K-3": "error reduction against Kothera's Fig. 18 data (not in the text)",
    "K-4": "error reduction against Kothera's measured free contraction (not in the text)",
    "K-7": "agreement with Kothera's measured blocked force (not in the text)",
    "K-8": "agreement with Kothera's measured free contraction (not in the text)",
    "O-6": "hysteresis width needs the friction terms and the Ogden paper's constants and pressures (not given)",
}
TESTS = (
    lambda r: _model(r).startswith(("S-01", "S-02", "S-07", "S-08 Andrikopoulos eq.(14)", "A-4", "K-5", "K-1", "EXPERIMENT")),
    is_acra_point, lambda r: _model(r).startswith("A-2") and "plateau" in r["tolerance_or_reported_error"],
    lambda r: "stiffness" in r["contraction_or_length"] and (_model(r).startswith("other phenomenological")
                                                           or (_model(r).startswith("S-24") and "10x" in r["tolerance_or_reported_error"])),
    lambda r: _model(r).startswith("K-7") and "decreases" in r["tolerance_or_reported_error"],
)


def test_every_reference_row_is_tested_or_listed_as_untestable():
    assert len(ROWS) == 138
    for i, r in enumerate(ROWS):
        tested = any(t(r) for t in TESTS)
        placeholder = r["tolerance_or_reported_error"] == "no numeric reference given in the papers"
        listed = _model(r).split(" ")[0] in UNTESTABLE
        assert tested or placeholder or listed, f"row {i + 2} ({r['model']}) is neither tested nor listed"
