"""What the fork server of ``--dask-local``'s workers imports once, before it forks them
(:data:`.dask_cluster.FORKSERVER_PRELOAD`); only that server imports this module.

It imports Dask, numpy and the sweep's runner with Python's cyclic garbage collector paused, then
moves every object they made into the collector's permanent generation (:func:`gc.freeze`), as
Python's documentation of ``gc.freeze`` advises before forking without exec.  A worker forked from
the server then never rescans those objects (most of the objects a worker holds) in its full
collections, which otherwise cost it tens of milliseconds each, and the memory pages holding them
stay shared between the workers.  The worker's own objects are collected as usual.
"""

import gc

gc.disable()
try:
    import distributed  # noqa: F401 -- imported for the workers, which need it
    import numpy  # noqa: F401
    import pamsim.native  # noqa: F401
    import pamsim.sweep.run  # noqa: F401
finally:
    gc.freeze()
    gc.enable()
