"""Sweeps on a Dask cluster: an executor for a running scheduler or a local cluster of processes.

``pamsim sweep SPEC --dask ADDRESS`` and ``--dask-local N`` use :func:`dask_executor`.
From Python any ``distributed.Client`` works the same way::

    from distributed import Client
    with Client("tcp://scheduler:8786") as client:
        result = pamsim.sweep(spec, client.get_executor(pure=False), chunk_size=50)

Dask is the optional extra ``pamsim[dask]``; without it :func:`dask_executor`
raises :class:`DaskUnavailable` (exit code 2 on the command line).  A worker
that dies mid-sweep is handled by the scheduler: its tasks run again on another
worker, and after ``distributed.scheduler.allowed-failures`` deaths the chunk's
cases become failed rows (``KilledWorker``) while the sweep completes.
"""

from __future__ import annotations

import contextlib
import logging
from concurrent.futures import Executor
from typing import Iterator

from ..errors import InputError

EXTRA = "pamsim[dask]"
CONNECT_TIMEOUT_S = 10.0
"""How long to wait for a scheduler before reporting the address as unreachable."""


class DaskUnavailable(InputError):
    """Dask (``distributed``) is not installed: the message names the extra to install."""


class DaskConnectionError(InputError):
    """The scheduler address cannot be reached."""


def _distributed():
    try:
        import distributed
    except ImportError as exc:
        raise DaskUnavailable(f"--dask needs the optional extra {EXTRA}: pip install '{EXTRA}' "
                              f"({exc})") from None
    return distributed


@contextlib.contextmanager
def _keep_malloc_defaults() -> Iterator[None]:
    """Start local workers without the ``MALLOC_TRIM_THRESHOLD_`` Dask sets for them.

    Dask sets it to hand freed memory back to the system sooner.  Setting it also turns off glibc's
    adaptive threshold for serving large allocations from the heap, so every run's traces (about
    0.6 MB per 8 s run at 1 kHz) come from fresh pages: with the native backend's runs of about a
    millisecond that made each run a quarter slower.  A pamsim choice for the clusters it starts;
    a cluster of your own keeps its configuration.
    """
    import dask

    key = "distributed.nanny.pre-spawn-environ"
    environ = dict(dask.config.get(key, default={}) or {})
    environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    with dask.config.set({key: environ}):
        yield


@contextlib.contextmanager
def dask_executor(address: str | None = None, local_workers: int | None = None) -> Iterator[tuple[Executor, str]]:
    """Yield ``(executor, description)`` for a Dask scheduler, closed on exit.

    Parameters
    ----------
    address : str, optional
        Address of a running scheduler, e.g. ``tcp://10.0.0.5:8786``.  Its workers
        need the same pamsim installed.
    local_workers : int, optional
        Instead of ``address``: start a ``LocalCluster`` of this many single-threaded
        worker processes (the simulations hold the GIL, so threads would not help).
    """
    if (address is None) == (local_workers is None):
        raise InputError("give exactly one of a scheduler address (--dask) and a local worker count (--dask-local)")
    distributed = _distributed()
    with contextlib.ExitStack() as stack:
        if address is not None:
            try:
                client = stack.enter_context(distributed.Client(address, timeout=CONNECT_TIMEOUT_S))
            except (OSError, TimeoutError, ValueError) as exc:
                raise DaskConnectionError(f"--dask {address}: cannot reach the scheduler: {exc}") from None
            where = f"Dask scheduler {address}"
        else:
            stack.enter_context(_keep_malloc_defaults())
            cluster = stack.enter_context(distributed.LocalCluster(
                n_workers=local_workers, threads_per_worker=1, processes=True, dashboard_address=None,
                # Workers log a lost heartbeat as an error while the cluster shuts down; not the user's concern.
                silence_logs=logging.CRITICAL))
            client = stack.enter_context(distributed.Client(cluster))
            where = f"Dask LocalCluster of {local_workers} worker process(es)"
        yield client.get_executor(pure=False), where
