"""One table scheme: the spline SciPy evaluates in Python is the B-spline CasADi writes as C.

The same knots and coefficients, evaluated by two implementations (FITPACK on floats, CasADi's
``Function.bspline`` on symbols), agree to rounding in value and in slope, on a uniform grid and on the
graded grid that refinement makes toward a bladder model's domain end; outside the grid both hold the
edge value.
"""

from __future__ import annotations

import numpy as np
import pytest

casadi = pytest.importorskip("casadi")

from pamsim.elements.force_table import tabulate  # noqa: E402
from pamsim.elements.stops import EndStops  # noqa: E402
from pamsim.muscles import load_muscle  # noqa: E402
from pamsim.parameters import dynamics_parameters  # noqa: E402
from pamsim.static_models import REGISTRY  # noqa: E402
from pamsim.static_models.spline import SplineSurface  # noqa: E402


def _kothera_energy_table():
    """kothera_energy on actuator 5a up to the end of its domain, where its push diverges."""
    p = dynamics_parameters(load_muscle("kothera2009_5a").parameters)
    m = REGISTRY["kothera_energy"].build(p)
    return m, tabulate(m, (0.0, m.domain.x_max_m), (0.0, p["rated_pressure_gauge_Pa"]))


def _both(surface: SplineSurface, x: np.ndarray, p: np.ndarray):
    """The surface and its x-slope at the points, by SciPy and by the CasADi form."""
    a, b = casadi.MX.sym("x"), casadi.MX.sym("p")
    F = surface(a, b)
    fn = casadi.Function("F", [a, b], [F, casadi.jacobian(F, a)])
    sym_value, sym_slope = (np.array(v).ravel() for v in fn(x[None, :], p[None, :]))
    inside = (x > surface.x_lo) & (x < surface.x_hi)
    held_x, held_p = np.clip(x, surface.x_lo, surface.x_hi), np.clip(p, surface.p_lo, surface.p_hi)
    slope = np.where(inside, surface._spline.ev(held_x, held_p, dx=1), 0.0)
    return (surface(x, p), slope), (sym_value, sym_slope)


@pytest.mark.parametrize("graded", [False, True])
def test_casadi_evaluates_the_spline_scipy_does(graded):
    if graded:
        _, table = _kothera_energy_table()
        surface, x, p = table._surface, table.x_grid_m, table.p_grid_Pa
        assert np.diff(x).min() < 1e-3 * np.diff(x).max()  # graded toward the end
    else:
        x, p = np.linspace(0.0, 0.05, 17), np.linspace(0.0, 6e5, 9)
        X, P = np.meshgrid(x, p, indexing="ij")
        surface = SplineSurface(x, p, np.sin(40.0 * X) * P / 1e4 + np.exp(-P / 3e5))
    rng = np.random.default_rng(7)
    # Points inside (half of them near the grid's end, where a graded grid is dense) and outside.
    span = x[-1] - x[0]
    xs = np.concatenate([rng.uniform(x[0], x[-1], 300), x[-1] - span * 10.0 ** rng.uniform(-9, -1, 300),
                         rng.uniform(x[0] - 0.1 * span, x[-1] + 0.1 * span, 100)])
    ps = np.concatenate([rng.uniform(p[0], p[-1], 600), rng.uniform(p[0] - 1e5, p[-1] + 1e5, 100)])
    (value, slope), (sym_value, sym_slope) = _both(surface, xs, ps)
    scale = np.abs(value).max()
    assert np.max(np.abs(sym_value - value)) <= 1e-12 * scale
    np.testing.assert_allclose(sym_slope, slope, rtol=1e-9, atol=1e-12 * np.abs(slope).max())


def test_refinement_follows_the_diverging_push_and_keeps_the_uniform_grid_elsewhere():
    """kothera_energy's push grows as the inverse square root of the distance to its domain's end: the
    uniform 65-point grid's spline rings back from the last node (a pull of over 1e6 N where the model
    pushes); refined, the table is within 0.025 % of the blocked force, or of the force where larger, at
    points the refinement never looked at.  A model without such an end keeps the uniform grid."""
    m, table = _kothera_energy_table()
    p_rated = table.p_grid_Pa[-1]
    uniform = tabulate(m, (0.0, m.domain.x_max_m), (0.0, p_rated), refine_tol=None)
    x = uniform.x_grid_m
    assert np.max(uniform.force_N(0.5 * (x[1:] + x[:-1]), p_rated)) > 1e6
    x, p = table.x_grid_m, table.p_grid_Pa
    X, P = np.meshgrid(np.concatenate([x[:-1] + f * np.diff(x) for f in (0.25, 0.75)]), 0.5 * (p[1:] + p[:-1]),
                       indexing="ij")
    exact = m.force_N(X, P)
    blocked = float(m.force_N(0.0, p_rated))
    assert np.all(np.abs(table.force_N(X, P) - exact) <= 2.5e-4 * np.maximum(blocked, np.abs(exact)))
    params = dynamics_parameters(load_muscle("mpam_survey_45mm").parameters)
    ch = REGISTRY["chou_hannaford"].build(params)
    x_hi = EndStops.from_parameters(params).x_high_m
    assert tabulate(ch, (0.0, x_hi), (0.0, params["rated_pressure_gauge_Pa"])).x_grid_m.shape == (65,)
