"""What the fork server of ``--dask-local``'s workers imports once, before it forks them
(:data:`.dask_cluster.FORKSERVER_PRELOAD`).  Only that server should import this module: importing
it freezes every object of the importing process out of the garbage collector for good.

It imports Dask, numpy and the sweep's runner, then moves every object of the server into the
collector's permanent generation (:func:`gc.freeze`).  A worker forked from the server then never
rescans those objects (most of the objects a worker holds) in its full collections, which otherwise
cost it tens of milliseconds each; the worker's own objects are collected as usual.  The imports
below run with the collector paused; the package ``pamsim.sweep`` (and numpy with it) is imported
before this module's body runs, so its objects are frozen but were imported with the collector on.
"""

import contextlib
import gc
import importlib

from ..gc_control import paused_gc

MODULES = ("distributed", "numpy", "pamsim.sweep.run", "pamsim.native")
"""The modules a worker needs, each imported on its own: one that fails does not stop the others
(as the fork server treats the modules it is asked to preload)."""

with paused_gc():
    for name in MODULES:
        with contextlib.suppress(ImportError):
            importlib.import_module(name)
    gc.freeze()
