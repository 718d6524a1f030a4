"""Python's cyclic garbage collector in the process that runs a sweep on an executor, or a native batch.

That process holds the imported modules, the sweep's tasks and, with ``--dask-local``, the Dask
scheduler, nannies and client: over a hundred thousand objects the collector tracks.  Each full
collection rescans all of them, and the collector made several such passes per sweep, each taking
tens of milliseconds of a CPU that the workers and, with Dask, the scheduler need.
The two context managers below keep those passes short without leaving the collector off for long.
"""

from __future__ import annotations

import contextlib
import gc
from typing import Iterator


@contextlib.contextmanager
def paused_gc() -> Iterator[None]:
    """The cyclic collector off inside the block (for a short burst of allocation, such as importing
    Dask and starting a cluster); back on at exit if it was on, and the block's objects are
    collected as usual from then on."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


@contextlib.contextmanager
def frozen_gc() -> Iterator[None]:
    """Every object that exists on entry kept out of the collector's passes inside the block
    (:func:`gc.freeze`); put back on exit.  The objects made inside the block are collected as usual.

    Does nothing if something in this process froze objects already: their owner decides when they
    go back (:func:`gc.unfreeze` would release them too).
    """
    if gc.get_freeze_count():
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()
