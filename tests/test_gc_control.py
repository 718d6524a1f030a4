"""The garbage-collector scopes of a sweep's process (pamsim.gc_control): what they change
while they are open, and that they give the collector back as it was."""

from __future__ import annotations

import contextlib
import gc
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

import pamsim
from pamsim.sweep import sweep_from_dict
from pamsim.gc_control import frozen_gc, paused_gc

FIG4 = str(Path(__file__).resolve().parents[1] / "scenarios" / "acra2012_fig4.toml")
SWEEP = {"base_scenario": FIG4, "axes": {"pressure_bar": [2.8, 3.6], "weight_N": [12.74, 32.74]}}


@pytest.fixture(autouse=True)
def _collector_as_found():
    """Each test starts with the collector on and nothing frozen, and leaves it so."""
    assert gc.isenabled() and gc.get_freeze_count() == 0
    yield
    gc.enable()
    gc.unfreeze()


@pytest.mark.parametrize("raises", [False, True])
def test_paused_gc_turns_the_collector_off_and_back_on(raises):
    with pytest.raises(RuntimeError) if raises else contextlib.nullcontext():
        with paused_gc():
            assert not gc.isenabled()
            if raises:
                raise RuntimeError("inside")
    assert gc.isenabled()


def test_paused_gc_leaves_a_collector_that_was_off_off():
    gc.disable()
    with paused_gc():
        assert not gc.isenabled()
    assert not gc.isenabled()


def _tracked(obj) -> bool:
    """Whether the collector scans ``obj`` (frozen objects are not among gc.get_objects())."""
    return any(o is obj for o in gc.get_objects())


@pytest.mark.parametrize("raises", [False, True])
def test_frozen_gc_freezes_what_exists_and_releases_it(raises):
    kept = []  # a tracked object that exists on entry
    with pytest.raises(RuntimeError) if raises else contextlib.nullcontext():
        with frozen_gc():
            assert not _tracked(kept) and gc.get_freeze_count() > 0
            made_inside = []
            assert _tracked(made_inside)  # objects made inside are collected as usual
            if raises:
                raise RuntimeError("inside")
    assert _tracked(kept) and gc.get_freeze_count() == 0


def test_frozen_gc_leaves_an_earlier_freeze_to_its_owner():
    early = []
    gc.freeze()
    later = []
    with frozen_gc():
        assert _tracked(later)  # nothing more frozen
    assert not _tracked(early) and _tracked(later)  # and nothing released


class _RecordingPool(ThreadPoolExecutor):
    """A thread pool that records the collector's freeze count at each submit."""

    def __init__(self):
        super().__init__(max_workers=2)
        self.freeze_counts = []

    def submit(self, fn, /, *args, **kwargs):
        self.freeze_counts.append(gc.get_freeze_count())
        return super().submit(fn, *args, **kwargs)


def test_a_sweep_on_an_executor_keeps_its_objects_frozen_only_while_it_runs():
    spec = sweep_from_dict(SWEEP)
    with _RecordingPool() as pool:
        result = pamsim.sweep(spec, pool, chunk_size=2)
    assert result.failures == []
    # Every chunk was sent with the sweep's objects (its tasks among them) frozen ...
    assert pool.freeze_counts and min(pool.freeze_counts) > 1000
    # ... and the collector has them all back.
    assert gc.get_freeze_count() == 0 and gc.isenabled()

