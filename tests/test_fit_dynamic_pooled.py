"""Dynamic identification (eq. 13) with synthetic truth (:mod:`synthetic_fit`): three loads pooled
separate what one trace cannot.  In its own file (the suite's longest fixture) so that it and the
single-trace tests of ``test_fit_dynamic.py`` run on different test workers.
"""

from __future__ import annotations

import numpy as np
import pytest

import pamsim

from conftest import SCENARIOS
from synthetic_fit import FREE, fit_in_pool, friction_polynomial_error, traces, truth_vector


@pytest.fixture(scope="module")
def pooled():
    scenario = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    pairs = traces(scenario, [12.74, 22.74, 32.74])
    return pairs, fit_in_pool(scenario, pairs)


def test_three_loads_pooled(pooled):
    pairs, fit = pooled
    for sim, (_, clean) in zip(fit.simulated_m, pairs):
        assert np.sqrt(np.mean((sim - clean.x_m) ** 2)) < 0.1e-3
    truth = dict(zip(FREE, truth_vector()))
    ident = fit.uncertainty.identifiable(fit.theta)
    assert {"D1_N_s_per_m", "D2_N_s2_per_m2"} <= set(ident)  # three loads separate the damping terms
    for name in ident:
        assert fit.parameters[name] == pytest.approx(truth[name], rel=0.10), name
    for group in fit.uncertainty.groups():
        w, se = fit.uncertainty.best_combination(group)
        idx = [FREE.index(n) for n in group]
        assert w @ fit.theta[idx] == pytest.approx(w @ truth_vector()[idx], rel=0.10)
    assert friction_polynomial_error(fit.theta, [c for _, c in pairs]) < 0.02
    assert fit.n_simulations > 3 * (len(FREE) + 1)
