"""Dynamic identification (eq. 13) with synthetic truth (:mod:`synthetic_fit`): three loads pooled
separate what one trace cannot.

The fit runs on the native backend: what is tested is the pooling (shared by both backends, which
differ only in who runs the trials), and the Python backend takes 15 s for it where the C core takes
0.2 s.  The Python-backend fit is tested on one trace in ``test_fit_dynamic.py``; the two backends'
residuals are compared in ``test_fit_native.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

import pamsim

from conftest import SCENARIOS
from pamsim.identification.dynamic_fit import fit_dynamic
from synthetic_fit import FREE, friction_polynomial_error, traces, truth_vector


@pytest.fixture(scope="module")
def pooled():
    scenario = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    pairs = traces(scenario, [12.74, 22.74, 32.74])
    return pairs, fit_dynamic(scenario, [noisy for noisy, _ in pairs], free=FREE, backend="native")


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
    assert fit.backend == "native" and fit.n_simulations > 3 * (len(FREE) + 1)
