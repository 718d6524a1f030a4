"""The survey's two-phase miniature-muscle model (S-34) as the registry model ``mpam_two_phase``.

No shipped muscle gives the nylon modulus, so the model is exercised on the survey's
45 mm muscle with an assumed ``E_nylon_Pa`` (nylon 6: 2-4 GPa).  The checks use code
of their own: the Lame solution written with Young's modulus, the phase-2 equations
written out again from the specification, and the survey's measured 13 mm.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from pamsim.errors import InputError
from pamsim.muscles import load_muscle, shipped_names
from pamsim.static_models import Domain, StaticModelDomainError, get

E_NYLON_ASSUMED_PA = 3e9  # assumed: nylon 6 lies at 2-4 GPa; the survey gives no value
MPAM = load_muscle("mpam_survey_45mm")
P = MPAM.parameters
RO, RI, L0, TH0 = P["r0_m"], P["ri0_m"], P["L0_m"], math.radians(P["theta0_deg"])
GAP, E, NU = P["sleeve_gap_m"], P["E_bladder_Pa"], P["nu_bladder"]
D = RO ** 2 - RI ** 2
MEASURED_MM = 13.0  # survey, Fig. 18 caption: contraction at 758 kPa with the 0.05 N datum load


def _model(variant="corrected", e_nylon=E_NYLON_ASSUMED_PA):
    return MPAM.static_force("mpam_two_phase", variant, overrides={"E_nylon_Pa": e_nylon})


CORRECTED = _model()
PRINTED = _model("printed")


# ------------------------------------------------------------------------------------ refusal
def test_refused_for_every_shipped_muscle_naming_the_nylon_modulus():
    spec = get("mpam_two_phase")
    assert spec.kind == "implicit" and "E_nylon_Pa" in spec.parameters
    for name in shipped_names():
        params = load_muscle(name).parameters
        assert "E_nylon_Pa" in spec.missing(params), name
    with pytest.raises(InputError, match="E_nylon_Pa"):
        MPAM.static_force("mpam_two_phase")


# ------------------------------------------------------------------------------------ phase 1
def _lame_load_N(x_m, p_Pa, area_m2):
    """Thick tube, internal pressure p, axial strain -x/L0 (generalised plane strain), by hand:
    sigma_r + sigma_theta = 2 p ri^2 / D everywhere, eps_z = (sigma_z - nu (sigma_r + sigma_theta)) / E;
    the load is sigma_z A_sil less the pressure on the end caps, referred to ``area_m2``."""
    sigma_z = E * (-x_m / L0) + NU * 2.0 * p_Pa * RI ** 2 / D
    return (sigma_z - p_Pa * RI ** 2 / D) * area_m2


@pytest.mark.parametrize("x_mm, p_kPa", [(0.0, 20.0), (1.0, 30.0), (3.0, 50.0), (8.0, 0.0)])
def test_phase1_force_is_the_lame_load_that_holds_the_contraction(x_mm, p_kPa):
    x, p = x_mm * 1e-3, p_kPa * 1e3
    assert not CORRECTED.in_contact(x, p)
    assert CORRECTED.force_N(x, p) == pytest.approx(_lame_load_N(x, p, math.pi * D), rel=1e-9, abs=1e-12)
    assert PRINTED.force_N(x, p) == pytest.approx(_lame_load_N(x, p, math.pi * RI ** 2), rel=1e-9, abs=1e-12)
    if p > 0.0 and x == 0.0:  # the tube lengthens under pressure: held at rest, it pushes
        assert CORRECTED.force_N(x, p) < 0.0


# ------------------------------------------------------------------------------------ phase 2
def _phase2_residuals(m, x, p, s, printed):
    """Every phase-2 equation of the specification, written out again, relative to its largest term."""
    L1, L2 = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    k = 1.0 / (L2 * (3 * L1 + 2 * L2))
    sign = 1.0 if printed else -1.0
    rb, m_str, rn, phi = RO + GAP, P["n_fibres"], P["fibre_radius_m"], P["end_cone_length_m"]
    c3 = -x / L0
    out = []
    c1 = (L1 + 2 * L2) * k / 2 * ((p * RI ** 2 + sign * s.P_o_Pa * RO ** 2) / D - s.P_s_Pa * L1 / (L1 + 2 * L2))
    out.append((s.c1 - c1) / max(abs(c1), 1e-300))
    c2 = RI ** 2 * RO ** 2 * (p - s.P_o_Pa) / (2 * L2 * D)
    out.append((s.c2 - c2) / max(abs(c2), 1e-300))
    terms = (-p * RI ** 2 / D, s.P_o_Pa * RO ** 2 / D, s.P_s_Pa * (L1 + L2) / L1)
    out.append((s.c3 - L1 * k * sum(terms)) / (L1 * k * max(abs(t) for t in terms)))  # c3 = 0 at rest: relative to its terms
    out.append(s.c3 - c3)
    stretch = 1.0 + s.F_nyl_N / (m_str * math.pi * rn ** 2 * E_NYLON_ASSUMED_PA * math.cos(s.theta))
    u_r = s.c1 * RO + s.c2 / RO
    sleeve = stretch * math.sin(s.theta) / math.sin(TH0) - 1.0
    out.append((u_r / RO - sleeve) / abs(sleeve) if printed else (u_r - GAP - rb * sleeve) / u_r)
    out.append((1 + c3) / (stretch * math.cos(s.theta) / math.cos(TH0)) - 1.0)
    tmin = 0.5 * math.asin(rn * m_str / (math.pi * RO))
    r = u_r if printed else RO + u_r
    S = ((math.sin(tmin) * math.cos(tmin)) ** 2 / (math.sin(s.theta) * math.cos(s.theta)) ** 2
         * 2 * math.pi * r * (L0 - 2 * phi) * (1 + c3) + 2 * math.pi * (rb + r) * phi * (1 + c3))
    g = math.sin(s.theta) ** 2 / math.cos(s.theta) if printed else math.tan(s.theta)
    F_r = s.F_nyl_N * (L0 / rb) * g * math.tan(TH0)
    out.append(s.P_o_Pa / (F_r / S) - 1.0)
    force = s.P_s_Pa * math.pi * D + s.F_nyl_N - math.pi * RI ** 2 * p
    out.append((s.force_N - force) / max(abs(force), s.P_s_Pa * math.pi * D))
    return out


@pytest.mark.parametrize("variant", ["corrected", "printed"])
def test_every_returned_phase2_solution_satisfies_every_equation(variant):
    m = CORRECTED if variant == "corrected" else PRINTED
    checked = 0
    for p in (1e5, 2e5, 4e5, 7.58e5):
        for x in np.linspace(0.0, m.domain.x_max_m, 7):
            if not m.in_contact(x, p):
                continue
            s = m.phase2_state(x, p)
            F = m.force_N(x, p)
            if s is None or s.P_o_Pa < 0.0:  # no solution, or only a tensile-contact one: no force
                assert math.isnan(F)
            else:
                assert F == s.force_N
            if s is not None:  # the solver's solutions, physical or not, solve the system
                assert max(abs(r) for r in _phase2_residuals(m, x, p, s, variant == "printed")) < 1e-9
                checked += 1
    assert checked >= 12


def test_corrected_phase2_is_physical_over_the_whole_domain():
    """Compressive contact (P_o >= 0) wherever the tube touches the sleeve, up to the muscle's rating."""
    assert CORRECTED.domain.p_max_Pa == P["rated_pressure_gauge_Pa"]
    for p in np.linspace(1e5, CORRECTED.domain.p_max_Pa, 5):
        for x in np.linspace(0.0, CORRECTED.domain.x_max_m, 9):
            if CORRECTED.in_contact(x, p):
                assert CORRECTED.phase2_state(x, p).P_o_Pa >= 0.0


@pytest.mark.parametrize("x_mm", [0.0, 4.0, 10.0])
def test_force_is_continuous_at_the_inflection_pressure(x_mm):
    x = x_mm * 1e-3
    lo, hi = 0.0, 2e6  # bisection on the contact condition: the inflection pressure at this contraction
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if CORRECTED.in_contact(x, mid) else (mid, hi)
    f1, f2 = CORRECTED.force_N(x, lo), CORRECTED.force_N(x, hi * (1 + 1e-9))
    assert f2 == pytest.approx(f1, abs=1e-6 * abs(f1) + 1e-9)
    assert CORRECTED.phase2_state(x, hi * (1 + 1e-9)).P_o_Pa == pytest.approx(0.0, abs=1e-3 * hi)


def test_stiffer_nylon_tends_to_the_inextensible_braid():
    x, p = 5e-3, 7.58e5
    strains = [_model(e_nylon=e).phase2_state(x, p).strand_strain for e in (1e9, 1e10, 1e11)]
    assert strains[0] > strains[1] > strains[2] > 0.0
    assert strains[1] / strains[2] == pytest.approx(10.0, rel=0.05)  # strain ~ 1/E_nylon


# ------------------------------------------------------------------------------------ domain and errors
def test_printed_domain_ends_where_phase2_has_no_compressive_contact():
    d = PRINTED.domain
    xs = np.linspace(d.x_min_m, d.x_max_m, 9)
    assert 0.0 < d.p_max_Pa < 1e5
    assert np.all(np.isfinite(PRINTED.force_N(xs, d.p_max_Pa)))
    assert not np.all(np.isfinite(PRINTED.force_N(xs, d.p_max_Pa * 1.01)))
    with pytest.raises(StaticModelDomainError, match="p_gauge_Pa"):
        PRINTED.evaluate_N(0.0, 7.58e5)


def test_evaluate_names_the_point_without_a_compressive_contact_solution():
    m = _model("printed")
    assert math.isnan(m.force_N(0.0, 2e5))
    m.domain = Domain(0.0, m.domain.x_max_m, 0.0, 1e6)  # widened, to reach the point the scan keeps out
    with pytest.raises(StaticModelDomainError, match=r"x_m = 0, p_gauge_Pa = 200000: no compressive-contact solution"):
        m.evaluate_N(0.0, 2e5)


def test_scalar_and_array_evaluations_agree():
    xs = np.array([0.0, 3e-3, 9e-3])
    arr = CORRECTED.force_N(xs, 5e5)
    assert arr.shape == (3,)
    for x, f in zip(xs, arr):
        got = CORRECTED.force_N(float(x), 5e5)
        assert isinstance(got, float) and got == f


# ------------------------------------------------------------------------------------ the survey's claims
@pytest.mark.parametrize("e_nylon", [1e9, 3e9, 5e9])
def test_free_contraction_at_758_kPa_within_7_percent_of_the_measured_13_mm(e_nylon):
    x = _model(e_nylon=e_nylon).free_contraction_m(7.58e5, 0.05)
    assert abs(1e3 * x / MEASURED_MM - 1.0) < 0.07


@pytest.mark.xfail(strict=True, reason="the survey's printed equations (eq. 60's +P_o, eq. 70 without the gap, "
                   "eq. 80) have no compressive-contact solution at 758 kPa, so they cannot give its <7 % error")
def test_printed_form_reproduces_the_13_mm_at_758_kPa():
    m = _model("printed")
    m.domain = Domain(0.0, m.domain.x_max_m, 0.0, 1e6)
    x = m.free_contraction_m(7.58e5, 0.05)
    assert abs(1e3 * x / MEASURED_MM - 1.0) < 0.07


@pytest.mark.xfail(strict=True, reason="the survey's model stiffness 0.94 N/mm at 758 kPa (measured 0.63 N/mm) is "
                   "not reproduced: the rebuilt model gives about 0.03 N/mm (the thin tube and the braid's "
                   "radial pull are soft near the free contraction)")
def test_stiffness_at_758_kPa_is_the_surveys_0_94_N_per_mm():
    x = CORRECTED.free_contraction_m(7.58e5, 0.05)
    assert CORRECTED.stiffness_N_per_m(x, 7.58e5) == pytest.approx(0.94e3, rel=0.1)


# ------------------------------------------------------------------------------------ command line
def test_cli_refuses_without_the_nylon_modulus_and_computes_with_it(cli):
    point = ("force", "--model", "mpam_two_phase", "--muscle", "mpam_survey_45mm", "--pressure-bar", "7.58",
             "--contraction-mm", "5")
    r = cli(*point)
    assert r.returncode == 2 and "E_nylon_Pa" in r.stderr and "Traceback" not in r.stderr
    r = cli(*point, "--set", f"E_nylon_Pa={E_NYLON_ASSUMED_PA:g}", "--json")
    assert r.returncode == 0
    assert json.loads(r.stdout)["force_N"] == pytest.approx(CORRECTED.force_N(5e-3, 7.58e5), rel=1e-12)
    r = cli(*point, "--set", f"E_nylon_Pa={E_NYLON_ASSUMED_PA:g}", "--variant", "printed")
    assert r.returncode == 2 and "--pressure-bar 7.58" in r.stderr and "Traceback" not in r.stderr
