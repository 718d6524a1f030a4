"""Dynamic identification (eq. 13) on the Python backend with synthetic truth (:mod:`synthetic_fit`):
one trace, two traces pooled, the fit's options, the pressure input.  The three-load pooled fit and
the per-trace table run on the native backend, in ``test_fit_native.py``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import pamsim
from pamsim.elements.pressure_source import PrescribedPressure
from pamsim.identification.columns import TraceData
from pamsim.identification.dynamic_fit import _Objective, fit_dynamic, make_problem, run_simulation
from pamsim.identification.pressure_input import knots, thinned_input
from pamsim.signals import Trace
from pamsim.simulator import simulate_model
from pamsim.errors import InputError
from pamsim.identification.plots import plot_dynamic_fit

from conftest import SCENARIOS
from synthetic_fit import FREE, NOISE_M, fit_in_pool, friction_polynomial_error, traces, truth_vector


@pytest.fixture(scope="module")
def scenario():
    return pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")


@pytest.fixture(scope="module")
def single(scenario):
    pairs = traces(scenario, [22.74])
    return pairs, fit_in_pool(scenario, pairs)


def test_single_trace_recovers_the_noise_free_trajectory(single):
    pairs, fit = single
    (noisy, clean), = pairs
    assert fit.theta.tolist() != fit.start.tolist()
    assert np.sqrt(np.mean((fit.simulated_m[0] - clean.x_m) ** 2)) < 0.1e-3
    # What is left against the noisy trace is the noise itself.
    assert fit.rms_contraction_mm[0] == pytest.approx(NOISE_M * 1e3, rel=0.1)
    # The start (the paper's coefficients) was far from the truth.
    assert np.sqrt(np.mean((fit.start_simulated_m[0] - clean.x_m) ** 2)) > 0.3e-3


def test_single_trace_identifiable_coefficients_within_10_percent(single):
    _, fit = single
    ident = fit.uncertainty.identifiable(fit.theta)
    assert "N0_N_per_bar" in ident
    truth = dict(zip(FREE, truth_vector()))
    for name in ident:
        assert fit.parameters[name] == pytest.approx(truth[name], rel=0.10), name


def test_single_trace_says_which_coefficients_it_cannot_separate(single):
    pairs, fit = single
    u = fit.uncertainty
    pairs_found = {(a, b) for a, b, r in u.inseparable_pairs() if abs(r) > 0.95}
    assert ("D1_N_s_per_m", "D2_N_s2_per_m2") in pairs_found
    # The combination the data determine agrees with the truth within its standard error (x3).
    group = ("D1_N_s_per_m", "D2_N_s2_per_m2")
    w, se = u.best_combination(group)
    idx = [FREE.index(n) for n in group]
    assert abs(w @ (fit.theta[idx] - truth_vector()[idx])) < 3 * se
    # N2 is tied to N1 (or, near the 0.95 limit, poorly determined: standard error above 5 %), so it
    # is not claimed identifiable; the friction level it forms with N1 and N0 is.
    assert "N2_N_per_bar_m2" not in u.identifiable(fit.theta)
    assert friction_polynomial_error(fit.theta, [pairs[0][1]]) < 0.10


@pytest.mark.xfail(strict=True, reason="one 3.6 bar trace barely excites the damping (a few hundredths of a "
                                       "newton): its best-determined D1/D2 combination comes back 30 % off")
def test_single_trace_damping_combination_within_10_percent(single):
    _, fit = single
    group = ("D1_N_s_per_m", "D2_N_s2_per_m2")
    w, _ = fit.uncertainty.best_combination(group)
    true = w @ truth_vector()[:2]
    assert w @ fit.theta[:2] == pytest.approx(true, rel=0.10)


def test_parallel_and_in_process_simulations_agree(single):
    _, fit = single
    task = fit.problem.tasks(fit.theta)[0]
    np.testing.assert_array_equal(run_simulation(task), fit.simulated_m[0])


def test_fd_step_is_far_above_the_simulation_noise(scenario, single):
    # A short trace: the Jacobian columns at steps 1e-3 and 3e-3 agree, so neither is dominated by
    # integration or event-timing noise; at 1e-9 they do not.
    (noisy, _), = single[0]
    short = TraceData(noisy.t_s[:1801], noisy.x_m[:1801], noisy.p_gauge_Pa[:1801], 22.74)
    prob = make_problem(scenario, [short], free=FREE)
    theta = np.array([scenario.parameters[n] for n in FREE])
    objective = _Objective(prob, None, 1e-3)  # one objective: the unperturbed simulation is shared
    J = {}
    for h in (1e-3, 3e-3, 1e-9):
        objective.fd_step = h
        J[h] = objective.jacobian(theta)
    rel = lambda a, b: np.linalg.norm(a - b) / np.linalg.norm(b)  # noqa: E731
    assert rel(J[1e-3], J[3e-3]) < 0.05
    assert rel(J[1e-9], J[1e-3]) > 0.05


def test_thinned_pressure_stays_within_tolerance_and_monotonic_between_breakpoints(scenario):
    res = pamsim.simulate(scenario)
    sig = thinned_input(res.t_s, res.p_gauge_Pa, 10.0)
    assert len(sig.t_s) < len(res.t_s) / 10
    assert np.max(np.abs(sig(res.t_s) - res.p_gauge_Pa)) <= 10.0 + 1e-9
    edges = [0.0, *sig.breakpoints, res.t_s[-1]]
    for a, b in zip(edges[:-1], edges[1:]):
        seg = np.diff(sig.values[(sig.t_s >= a) & (sig.t_s <= b)])
        assert np.all(seg >= 0) or np.all(seg <= 0)
    # The same motion as with the full 1 kHz trace, within a few micrometres.
    model = scenario.build_model()
    full = simulate_model(replace(model, source=PrescribedPressure(Trace(res.t_s, res.p_gauge_Pa))), 8.0,
                          scenario.solver)
    thin = simulate_model(replace(model, source=PrescribedPressure(sig)), 8.0, scenario.solver)
    assert np.max(np.abs(full.x_m - thin.x_m)) < 10e-6
    assert list(knots(np.arange(5.0), np.array([0.0, 1, 2, 3, 4]), 1e-9)) == [0, 4]  # a line needs two knots


def test_bad_choices_are_input_errors(scenario, single):
    pairs, _ = single
    tr = pairs[0][0]
    with pytest.raises(InputError, match="--free"):
        fit_dynamic(scenario, [tr], free=["N9"])
    with pytest.raises(InputError, match="--window"):
        fit_dynamic(scenario, [tr], window_s=(10.0, 11.0))
    with pytest.raises(InputError, match="--load-N"):
        fit_dynamic(scenario, [tr], loads_N=[1.0, 2.0])


@pytest.fixture(scope="module")
def short_pair(scenario):
    """Two 2 s traces with N0 = 6.0 only changed (12.74 and 22.74 N)."""
    from pamsim.identification.synthetic import synthetic_trace

    return [synthetic_trace(scenario, {"N0_N_per_bar": 6.0}, w, NOISE_M, seed=10 + i, duration_s=2.0)
            for i, w in enumerate((12.74, 22.74))]


def test_global_search_then_local_fit(scenario, short_pair):
    noisy, _ = short_pair[1]
    fit = fit_dynamic(scenario, [noisy], free=["N0_N_per_bar"], global_search=True, global_iterations=2, seed=1)
    assert fit.parameters["N0_N_per_bar"] == pytest.approx(6.0, rel=0.02)
    # popsize 6 x 1 coefficient, initial population and 2 generations: at least 18 evaluations, 1 trace each
    assert fit.n_simulations >= 18


def test_two_traces_pooled(scenario, short_pair):
    """Two loads pooled on the Python backend (the per-trace table is tested on the native backend in
    test_fit_native.py: the same code, a third of the time).  The pooled cost has a local minimum at
    N0 = 6.15 N/bar (RMS 0.46 mm, the 12.74 N trace sticking elsewhere), where a single local fit from the
    paper's 6.87 stops once N0 is bounded below by 0: one extra start (test_fit_dynamic_robust.py)."""
    fit = fit_dynamic(scenario, [n for n, _ in short_pair], free=["N0_N_per_bar"], n_starts=1)
    assert fit.backend == "python" and len(fit.simulated_m) == 2
    assert fit.parameters["N0_N_per_bar"] == pytest.approx(6.0, rel=0.02)
    for rms in fit.rms_contraction_mm:
        assert rms == pytest.approx(NOISE_M * 1e3, rel=0.2)
    # the figure names each trace by its file, as the reports do, not by the folder it was read from
    traces = [replace(n, origin=f"/some/folder/step_{i}.csv") for i, (n, _) in enumerate(short_pair)]
    fig = plot_dynamic_fit(replace(fit, problem=replace(fit.problem, traces=tuple(traces))))
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert [t.split(" (")[0] for t in titles] == ["step_0.csv", "step_1.csv"]


def test_without_recorded_pressure_the_scenario_valve_drives_the_fit(scenario, short_pair):
    noisy, clean = short_pair[1]
    no_p = TraceData(noisy.t_s, noisy.x_m, None, None, "no pressure")
    fit = fit_dynamic(scenario, [no_p], free=["N0_N_per_bar"], loads_N=[22.74])
    assert fit.problem.inputs == (None,)
    assert fit.parameters["N0_N_per_bar"] == pytest.approx(6.0, rel=0.02)
    assert np.sqrt(np.mean((fit.simulated_m[0] - clean.x_m) ** 2)) < 0.02e-3
