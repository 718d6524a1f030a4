"""Where a native batch keeps its results' columns and what it does with the garbage collector: the modes
and the pressure column in the run's own buffer, each case's apart and equal to the case run alone, and the
collector paused for the batch, as it was afterwards."""

from __future__ import annotations

import gc
from pathlib import Path

import numpy as np

import pamsim
from pamsim.native import backend, simulate_batch
from pamsim.paperdata import acra2012_steady_state
from pamsim.scenario import load_scenario

FIG4 = Path(__file__).resolve().parents[1] / "scenarios" / "acra2012_fig4.toml"


def _cases(n: int):
    base = load_scenario(FIG4)
    return [base.with_changes({"load": {"weight_N": float(r["weight_N"])},
                               "pressure": {"supply_gauge_bar": float(r["pressure_stable_bar"])}})
            for r in acra2012_steady_state()[:n]]


def test_batch_columns_equal_each_case_run_alone_and_are_its_own():
    cases = _cases(4)
    results = simulate_batch(cases)
    for case, r in zip(cases, results):
        alone = pamsim.simulate(case.with_changes({}), backend="native")  # a new object: a batch of one, at offset 0
        assert r.mode.dtype == alone.mode.dtype == np.dtype(int)
        assert np.array_equal(r.mode, alone.mode) and np.array_equal(r.p_gauge_Pa, alone.p_gauge_Pa)
    assert len({round(float(r.p_gauge_Pa[-1])) for r in results}) > 1  # the cases differ: no column shared
    for a in results:
        for b in results:
            if a is not b:
                assert not np.shares_memory(a.p_gauge_Pa, b.p_gauge_Pa)
                assert not np.shares_memory(a.mode, b.mode)


def test_the_collector_does_not_run_during_a_batch_and_is_on_after(monkeypatch):
    cases = _cases(20)
    inside, passes = [], []
    batch = backend._simulate_batch

    def watched(*args):
        inside.append(True)
        try:
            return batch(*args)
        finally:
            inside.clear()

    def count(phase, info):
        if phase == "start" and inside:
            passes.append(info["generation"])

    monkeypatch.setattr(backend, "_simulate_batch", watched)
    gc.collect()
    assert gc.isenabled()
    old = gc.get_threshold()
    gc.set_threshold(10)  # a pass every few allocations while the collector is on
    gc.callbacks.append(count)
    try:
        simulate_batch(cases)
    finally:
        gc.callbacks.remove(count)
        gc.set_threshold(*old)
    assert passes == []
    assert gc.isenabled()
