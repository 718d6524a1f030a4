"""Physical sanity of every model over its domain, for every shipped muscle it applies to.

In the contractile working range (from rest to the free contraction at each
pressure, where the muscle pulls) the force must rise with pressure and fall
with contraction; nowhere in the domain may it be NaN; outside it ``evaluate_N``
must refuse the point.  Models whose fitted constants no paper gives are checked
with assumed constants (marked below) on the survey's miniature muscle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pamsim.muscles import load_muscle, shipped_names
from pamsim.static_models import REGISTRY, StaticModelDomainError, get
from pamsim.static_models.geometry import Braid

MUSCLES = {name: load_muscle(name) for name in shipped_names()}
MPAM = MUSCLES["mpam_survey_45mm"].parameters
_g = Braid.from_parameters(MPAM)
A, Q1, Q2 = math.pi * _g.r0 ** 2, _g.q1, _g.q2

ASSUMED = {  # model: constants assumed for the test only (no paper gives them), on the 45 mm miniature muscle
    "itto": {"itto_kappa1": 0.5, "itto_kappa2_per_Pa": -1e-6, "itto_kappa3": 0.5},  # k_eps falls from 1 with pressure
    "meller": {"meller_kappa1_m2": 2.5e-6, "meller_kappa2_N": -0.1, "meller_kappa3": 0.02},
    "andrikopoulos": {"andrikopoulos_F_max_N": 1.8, "andrikopoulos_x_max_m": 0.011, "andrikopoulos_P_test_Pa": 7.58e5},
    "takosoglu": {"takosoglu_kappa1": 0.2, "takosoglu_kappa2_Pa": 5e5, "takosoglu_kappa3": 2.0, "takosoglu_kappa4": 0.0,
                  "takosoglu_kappa5_Pa": 5e5, "takosoglu_kappa6": Q1},
    # Empirical laws with Gaylord's own expansion in eps as coefficients.
    "mpam_bundle_empirical": {"bundle_kappa1_m2": A * Q1, "bundle_kappa2_N": 0.0, "bundle_kappa3_m2": -A * Q2},
    "empirical_poly46": {"emp46_k1_m2": A * (Q1 - Q2), "emp46_k2_m2": -2 * A * Q1, "emp46_k3_m2": A * Q1,
                         **{f"emp46_k{i}_N": 0.0 for i in range(4, 9)}},
    "empirical_poly47": {"emp47_k1_N": 0.0, "emp47_k2_N": 0.0, "emp47_k3_N": 0.0, "emp47_k4_m2": A * (Q1 - Q2),
                         "emp47_k5_m2": -2 * A * Q1},
    "empirical_poly48": {"emp48_k1_m2_per_Pa": 0.0, "emp48_k2_m2": -2 * A * Q1, "emp48_k3_N": 0.0,
                         "emp48_k4_m2": A * (Q1 - Q2), "emp48_k5_N": 0.0},
    "empirical_linear": {"emp49_k1": 1.0, "emp49_Fmax_N": 2.0, "emp49_eps_max": 0.28},
    "pillsbury": {"pillsbury_E1I_Pa": 0.35e6, "pillsbury_E1S": 0.1},
    "ogden": {"ogden_mu1_Pa": 0.35e6 / 3, "ogden_alpha1": 2.0},
    "mpam_two_phase": {"E_nylon_Pa": 3e9},  # nylon 6: 2-4 GPa; the survey gives none
}


THICK_WALL = ("Chou and Hannaford's constant-thickness term grows faster than Gaylord's force falls when "
              "t0/r0 (2 + 1/sin^2(theta0)) > 3 (Kothera 3x: thick wall, 28.2 deg braid): the force rises with "
              "contraction; the specification calls the model unphysical for thick walls")
PRINTED_HOOP = ("the printed hoop-term sign of Kothera's eq. (29) makes the bladder pull harder the more it contracts "
                "(the reason the corrected sign is the default)")
PHASE1_PUSH = ("two-phase model, printed: its domain ends inside phase 1 (about 65 kPa), where the free tube lengthens "
               "with pressure (Poisson) and so pushes harder at rest the higher the pressure")
KNOWN_INSANE = {  # (model, variant, muscle): why the physics check must fail
    ("mpam_two_phase", "printed", "assumed"): PHASE1_PUSH,
    **{("chou_hannaford", "default", f"kothera2009_3{c}"): THICK_WALL for c in "abc"},
    **{("kothera_force_balance", "printed", f"kothera2009_{n}{c}"): PRINTED_HOOP for n in "345" for c in "abc"},
}


def cases():
    out = []
    for model, spec in REGISTRY.items():
        if model == "force_map":
            continue  # tested on tables in test_static_models_force_map.py
        found = False
        for name, muscle in MUSCLES.items():
            if not spec.missing(muscle.parameters):
                found = True
                for variant in spec.variants:
                    why = KNOWN_INSANE.get((model, variant, name))
                    marks = pytest.mark.xfail(strict=True, reason=why) if why else ()
                    out.append(pytest.param(model, dict(muscle.parameters), variant, id=f"{model}-{variant}-{name}",
                                            marks=marks))
        if model in ASSUMED:
            found = True
            for variant in spec.variants:
                why = KNOWN_INSANE.get((model, variant, "assumed"))
                marks = pytest.mark.xfail(strict=True, reason=why) if why else ()
                out.append(pytest.param(model, {**MPAM, **ASSUMED[model]}, variant, id=f"{model}-{variant}-assumed",
                                        marks=marks))
        if model == "ogden":
            k = MUSCLES["kothera2009_5a"].parameters
            out.append(pytest.param(model, {**k, "ogden_mu1_Pa": 2 * k["C10_Pa"], "ogden_alpha1": 2.0,
                                            "ogden_mu2_Pa": -2 * k["C01_Pa"], "ogden_alpha2": -2.0},
                                    "mean_radius", id="ogden-mooney-rivlin-kothera2009_5a"))
        assert found, f"no sanity case for {model}"
    return out


@pytest.mark.parametrize("model, params, variant", cases())
def test_model_is_physically_sane_over_its_domain(model, params, variant):
    m = get(model).build(params, variant)
    d = m.domain
    p_hi = min(d.p_max_Pa, 1.0e6)
    ps = np.linspace(max(d.p_min_Pa, 0.0), p_hi, 9)
    xs = np.linspace(d.x_min_m, d.x_max_m, 61)
    F = np.asarray(m.evaluate_N(xs[None, :], ps[:, None]), dtype=float) * np.ones((len(ps), len(xs)))
    assert np.all(np.isfinite(F)), "NaN or inf inside the domain"
    scale = np.max(np.abs(F)) + 1e-12
    for i, p in enumerate(ps):
        x_free = m.free_contraction_m(float(p), 0.0)
        x_free = d.x_max_m if math.isnan(x_free) else x_free
        working = (xs >= max(d.x_min_m, 0.0)) & (xs <= x_free)
        dF = np.diff(F[i, working])
        assert np.all(dF <= 1e-9 * scale), f"force rises with contraction at {p:g} Pa"
        if i and np.any(working):
            up = F[i, working] - F[i - 1, working]
            assert np.all(up >= -1e-9 * scale), f"force falls with pressure between {ps[i - 1]:g} and {p:g} Pa"
    with pytest.raises(StaticModelDomainError):
        m.evaluate_N(d.x_max_m + 1e-6 * max(1.0, abs(d.x_max_m)) + 1e-9, p_hi)
    with pytest.raises(StaticModelDomainError):
        m.evaluate_N(0.5 * (d.x_min_m + d.x_max_m), d.p_min_Pa - 1.0)


def test_scalar_and_array_evaluations_agree():
    for model in ("gaylord", "chou_hannaford", "kothera_energy_tips", "trivedi", "hocking", "tondu_lopez", "de_volder"):
        m = MUSCLES["kothera2009_5a"].static_force(model)
        xs = np.linspace(0.0, 0.5 * m.domain.x_max_m, 5)
        arr = m.force_N(xs, 3e5)
        for x, f in zip(xs, arr):
            got = m.force_N(float(x), 3e5)
            assert isinstance(got, float) and got == pytest.approx(f, rel=1e-12, abs=1e-12)


def _outside_points(m, L0_m):
    """Contractions and pressures around and beyond every edge of the domain (and past the rest length)."""
    d = m.domain
    p_top = d.p_max_Pa if math.isfinite(d.p_max_Pa) else 1e6
    xs = (-0.2 * L0_m, -1e-4, d.x_max_m + 1e-7, 1.2 * d.x_max_m, 0.95 * L0_m, 1.5 * L0_m)
    ps = (-1e5, -1.0, 0.0, 0.5 * p_top, 2.0 * p_top, 1e8)
    return [(float(x), float(p)) for x in xs for p in ps]


@pytest.mark.parametrize("model, params, variant", [pytest.param(*c.values, id=c.id) for c in cases()])
def test_raw_scalar_force_outside_the_domain_is_real(model, params, variant):
    """``force_N`` checks nothing, but outside the domain it gives NaN (or a real number), never a complex one:
    Python's ``**`` and ``math.log`` would turn the point into a complex force or an exception."""
    m = get(model).build(params, variant)
    for x, p in _outside_points(m, params["L0_m"]):
        f = m.force_N(x, p)
        assert isinstance(f, float), f"force_N({x:g}, {p:g}) = {f!r}"
