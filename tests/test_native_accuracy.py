"""The native backend's accuracy against a converged run: where it locates an event on a grazing orbit, and
the tolerance it integrates at by default."""

from __future__ import annotations

import numpy as np
import pytest

import pamsim
from pamsim.scenario import ScenarioError
from pamsim.simulator import NATIVE_RTOL_FACTOR

from conftest import SCENARIOS


def free_swing(duration_s: float):
    """Figure 4's rig without friction or damping under a prescribed 3.6 bar step at 1 s: the load rises to
    its upper stop (restitution 0: it stays there), falls back, and without losses every later swing
    turns back exactly at the stop, touching it with zero speed."""
    return pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes({
        "model": {"friction": "none", "damping": "none"},
        "pressure": {"source": "prescribed", "prescribed": {"kind": "step", "time_s": 1.0, "final_gauge_bar": 3.6}},
        "simulation": {"duration_s": duration_s}})


@pytest.fixture(scope="module")
def converged_swing():
    """The first 1.6 s (three events: the impact, the turn at the bottom, the grazing turn at the top)
    by the python backend's DOP853 at rtol 1e-12."""
    return pamsim.simulate(free_swing(1.6).with_changes({"solver": {"rtol": 1e-12, "method": "DOP853"}}))


@pytest.fixture(scope="module")
def converged_run():
    """The whole 8 s (37 events) by the python backend's DOP853 at rtol 1e-12."""
    return pamsim.simulate(free_swing(8.0).with_changes({"solver": {"rtol": 1e-12, "method": "DOP853"}}))


def test_a_turn_that_grazes_the_stop_is_located_where_the_converged_run_puts_it(converged_swing):
    # An integration error of d above the stop moves an impact found inside the step by sqrt(2 d / g):
    # at rtol 1e-8 the apex came out 30 nm above the stop and the turn 78 us early.  Located where the
    # indicators change sign, as in solve_ivp, the turn is where the dense output puts it.
    ref = converged_swing.transitions
    run = pamsim.simulate(free_swing(1.6).with_changes({"solver": {"rtol": 1e-8, "native_rtol_factor": 1.0}}),
                          backend="native")
    assert len(run.transitions) == len(ref) == 3
    assert abs(run.transitions[2].t_s - ref[2].t_s) < 1e-6
    assert abs(run.transitions[2].x_m - ref[2].x_m) < 1e-8  # at the stop (the stop's margin is 1e-9 m)


def test_by_default_the_free_swing_ends_as_close_to_the_converged_run_as_the_python_default(converged_run):
    # 37 events in 8 s, each turn at the stop a chance to amplify an error.  At the same rtol the
    # native backend's Dormand-Prince 5(4) ended 0.31 mm from the converged run, LSODA 1.5e-3 mm.
    base, ref = free_swing(8.0), converged_run
    python = pamsim.simulate(base)
    native = pamsim.simulate(base, backend="native")
    assert len(native.transitions) == len(python.transitions) == len(ref.transitions) == 37
    assert np.max(np.abs(native.x_m - ref.x_m)) <= np.max(np.abs(python.x_m - ref.x_m))


def test_the_native_tolerance_is_the_scenario_rtol_times_the_factor(tmp_path):
    base = free_swing(1.2)
    assert base.solver.native_rtol_factor == NATIVE_RTOL_FACTOR == 0.01
    default = pamsim.simulate(base, backend="native")
    explicit = pamsim.simulate(base.with_changes({"solver": {"rtol": 1e-8, "native_rtol_factor": 1.0}}),
                               backend="native")
    assert default.stats["rtol"] == explicit.stats["rtol"] == pytest.approx(1e-8)
    assert np.array_equal(default.x_m, explicit.x_m)
    # no finer than the finest rtol a scenario may give
    assert pamsim.simulate(base.with_changes({"solver": {"rtol": 1e-12}}), backend="native").stats["rtol"] == 1e-13
    # the python backend ignores it
    python = pamsim.simulate(base.with_changes({"solver": {"native_rtol_factor": 1.0}}))
    assert np.array_equal(python.x_m, pamsim.simulate(base).x_m)


@pytest.mark.parametrize("value, words", [(0.0, "(0, 1]"), (2.0, "(0, 1]"), (-1.0, "(0, 1]"),
                                          ("small", "number")])
def test_a_bad_native_rtol_factor_is_refused_naming_the_key(value, words):
    with pytest.raises(ScenarioError) as info:
        free_swing(1.0).with_changes({"solver": {"native_rtol_factor": value}})
    message = str(info.value)
    assert "solver.native_rtol_factor" in message and str(value) in message and words in message


def test_the_one_muscle_fmu_locates_the_grazing_turns_too(converged_run):
    # The hand-written core (the one-muscle FMU, at its own cs_relative_tolerance of 1e-8) located events
    # as the engine did: its free swing ended 0.58 mm from the converged run, now 7e-4 mm.
    base, ref = free_swing(8.0), converged_run
    fmu = pamsim.simulate(base, backend="fmu-cs")
    assert np.max(np.abs(fmu.x_m - ref.x_m)) < 1e-5
