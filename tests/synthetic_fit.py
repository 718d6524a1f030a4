"""Synthetic truth for the dynamic-fit tests (``test_fit_dynamic*.py``): traces made by pamsim with
coefficients other than the paper's, the pressure recorded, seeded noise of 0.05 mm on the contraction.

The traces last 2.5 s (valve opening at 1 s; the load sticks for good by 1.9 s) to keep the suite
quick; benchmarks/bench_fit.py runs the full 8 s case.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from pamsim.identification.dynamic_fit import fit_dynamic
from pamsim.identification.synthetic import synthetic_trace

TRUTH = {"D1_N_s_per_m": -0.5, "D2_N_s2_per_m2": 1.2, "N2_N_per_bar_m2": 200.0, "N1_N_per_bar_m": -80.0,
         "N0_N_per_bar": 6.0}
FREE = tuple(TRUTH)
NOISE_M = 0.05e-3
DURATION_S = 2.5


def traces(scenario, loads):
    """(noisy, clean) synthetic traces, one per load [N], seeded by their position."""
    return [synthetic_trace(scenario, TRUTH, w, NOISE_M, seed=i, duration_s=DURATION_S) for i, w in enumerate(loads)]


def fit_in_pool(scenario, pairs):
    """Fit every coefficient of FREE to the noisy traces, simulations on two worker processes."""
    with ProcessPoolExecutor(2) as pool:
        return fit_dynamic(scenario, [noisy for noisy, _ in pairs], free=FREE, executor=pool)


def truth_vector():
    return np.array([TRUTH[n] for n in FREE])


def friction_polynomial_error(theta, clean_traces):
    """RMS relative error of N2 x^2 + N1 x + N0 over the contractions the traces pass through."""
    x = np.concatenate([tr.x_m[tr.x_m > 1e-3] for tr in clean_traces])
    true = TRUTH["N2_N_per_bar_m2"] * x ** 2 + TRUTH["N1_N_per_bar_m"] * x + TRUTH["N0_N_per_bar"]
    fit = theta[2] * x ** 2 + theta[3] * x + theta[4]
    return float(np.sqrt(np.mean(((fit - true) / true) ** 2)))


def check_three_loads_pooled(pooled):
    """Three loads pooled separate what one trace cannot: ``pooled`` is ``(pairs, fit)`` of the three
    loads 12.74, 22.74 and 32.74 N with every coefficient of FREE free."""
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
