"""Sweeps on a Dask cluster: an executor for a running scheduler or a local cluster of processes.

``pamsim sweep SPEC --dask ADDRESS`` and ``--dask-local N`` use :func:`dask_executor`.
From Python any ``distributed.Client`` works the same way::

    from distributed import Client
    with Client("tcp://scheduler:8786") as client:
        result = pamsim.sweep(spec, client.get_executor(pure=False), chunk_size=50)

Dask is the optional extra ``pamsim[dask]``; without it :func:`dask_executor`
raises :class:`DaskUnavailable` (exit code 2 on the command line).  A worker
that dies mid-sweep is handled by the scheduler: its tasks run again on another
worker; after ``distributed.scheduler.allowed-failures`` deaths the chunk fails
(``KilledWorker``), which stops the sweep unless it allows an incomplete result.
:func:`executor_watch` stops a sweep whose scheduler or last worker is gone.
"""

from __future__ import annotations

import contextlib
import importlib.util
import logging
import os
import time
from concurrent.futures import Executor
from typing import Callable, Iterator

from ..errors import InputError
from ..gc_control import paused_gc

EXTRA = "pamsim[dask]"
CONNECT_TIMEOUT_S = 10.0
"""How long to wait for a scheduler before reporting the address as unreachable."""

CLOSE_TIMEOUT_S = 2.0
"""How long closing the client of a scheduler may take [s]."""

HANDSHAKE_TIMEOUT_S = 3.0
"""How long a server that accepted the connection may take to send Dask's handshake [s]: a scheduler sends
it at once, unasked."""

MAX_HANDSHAKE_BYTES = 1 << 20
"""A first message longer than this is not a scheduler's handshake (which is a few hundred bytes)."""


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


LOCAL_CLUSTER_CONFIG = {
    # Workers forked from a single-threaded server that has imported Dask, numpy and pamsim once,
    # instead of spawned fresh interpreters that each import them again (a worker's import of
    # distributed and pamsim takes about 0.8 s of CPU; with 2 cores that is the run's time).
    "distributed.worker.multiprocessing-method": "forkserver",
    # The statistical profiler samples each task thread every 10 ms for the dashboard, which the
    # clusters pamsim starts do not serve.
    "distributed.worker.profile.enabled": False,
    # Resource and memory polling every 2 s and 1 s instead of 0.5 s and 0.1 s: the polling shares
    # the CPUs with the runs, and a runaway worker is still stopped within a second.
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
    # Every Dask server (the scheduler, each nanny, each worker) times its event loop every 20 ms, to
    # warn when it stalls for seconds; each tick wakes a thread that takes the GIL from the runs (in a
    # worker) or from the scheduler (in the sweep's process).  Once a second still catches a stall.
    "distributed.admin.tick.interval": "1s",
    # The workers start while the sweep prepares its tasks (local_client): should none start, the
    # tasks fail after this long (failed rows, the sweep completes) instead of waiting for ever.
    "distributed.scheduler.no-workers-timeout": "30s",
    # The scheduler always starts an HTTP server (its default port is the dashboard's 8787, with a warning
    # when another program holds it); a cluster that lives for one sweep serves no pages (LOCAL_SCHEDULER).
    "distributed.scheduler.http.routes": [],
}
"""Dask settings of the ``LocalCluster`` that ``--dask-local`` starts (a pamsim choice; a cluster
of your own keeps its configuration).  With runs of about a millisecond (the native backend),
Dask's own work shows; ``benchmarks/bench_dask.py`` measures the cluster against a process pool
(figures in ``docs/scaling.md``)."""

LOCAL_SCHEDULER = {"dashboard": False, "dashboard_address": "127.0.0.1:0"}
"""The local cluster's scheduler: no dashboard, and its HTTP server (which Dask always starts) on a free
port of this machine only, so it never takes port 8787 or warns that another program holds it."""

WORKER_START_TIMEOUT_S = 30.0
"""How long a local worker may take to start and reach the scheduler before it gives up [s]."""

FORKSERVER_PRELOAD = ("pamsim.sweep.worker_preload",)
"""What the fork server imports once, before it forks the workers: Dask, numpy and pamsim's runner,
with their objects frozen out of the workers' garbage collection (:mod:`.worker_preload`)."""

FORKSERVER_ENVIRON = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
"""Environment the fork server starts with: one thread for numpy's linear algebra in each worker,
as Dask's own ``pre-spawn-environ`` gives a worker it spawns.  The libraries read these when they
load, which is in the server (the preload), before Dask could set them in a worker."""


@contextlib.contextmanager
def _restored_environ(keys) -> Iterator[None]:
    """The variables ``keys`` of ``os.environ`` put back on exit as they were on entry (removed if
    they were not set); the others are left alone."""
    saved = {k: os.environ.get(k) for k in keys}
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def start_worker_server() -> None:
    """Start the fork server that local workers are forked from, if Dask is installed.

    The server imports :data:`FORKSERVER_PRELOAD` (Dask, numpy, pamsim) in its own process, so the
    earlier it starts, the more of that overlaps this process's own work: ``pamsim sweep
    --dask-local`` starts it before reading the sweep file.  :func:`local_client` starts it too
    (before this process imports Dask); a server already running is reused as it is, and lives until
    this process exits.  Without Dask this does nothing (:func:`local_client` then says what to install).
    """
    if importlib.util.find_spec("distributed") is None:
        return
    import multiprocessing
    import multiprocessing.forkserver

    multiprocessing.get_context("forkserver").set_forkserver_preload(list(FORKSERVER_PRELOAD))
    # The workers are forked from the server, so they keep the environment of its start: the thread
    # limits, and no MALLOC_TRIM_THRESHOLD_ (which a Dask cluster started earlier in this process
    # leaves in its environment).
    with _restored_environ([*FORKSERVER_ENVIRON, "MALLOC_TRIM_THRESHOLD_"]):
        os.environ.update(FORKSERVER_ENVIRON)
        os.environ.pop("MALLOC_TRIM_THRESHOLD_", None)
        multiprocessing.forkserver.ensure_running()


@contextlib.contextmanager
def _local_cluster_settings() -> Iterator[None]:
    """:data:`LOCAL_CLUSTER_CONFIG`, the fork server's preload, and the workers' environment
    without ``MALLOC_TRIM_THRESHOLD_``, for the lifetime of a local cluster (a restarted worker is
    started the same way).

    Dask sets ``MALLOC_TRIM_THRESHOLD_`` to hand freed memory back to the system sooner.  Setting
    it also turns off glibc's adaptive threshold for serving large allocations from the heap, so
    every run's traces (about 0.6 MB per 8 s run at 1 kHz) come from fresh pages: with the native
    backend's runs of about a millisecond that made each run a quarter slower.
    """
    import dask
    from distributed.utils import get_mp_context

    key = "distributed.nanny.pre-spawn-environ"
    environ = dict(dask.config.get(key, default={}) or {})
    environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    # Dask's nanny writes the workers' pre-spawn variables (and PYTHONHASHSEED) into this process's
    # environment and leaves them there; they are put back when the cluster closes.
    with dask.config.set({**LOCAL_CLUSTER_CONFIG, key: environ}), _restored_environ([*environ, "PYTHONHASHSEED"]):
        # Dask names its own preload the first time it makes the context; pamsim's is named again, for
        # a server restarted after this one (the running one has its preload already).
        get_mp_context().set_forkserver_preload(list(FORKSERVER_PRELOAD))
        yield


@contextlib.contextmanager
def local_client(workers: int) -> Iterator:
    """Yield a ``distributed.Client`` of a new ``LocalCluster`` of ``workers`` single-threaded worker
    processes, started with pamsim's settings (:func:`_local_cluster_settings`); closed on exit.

    Raises :class:`DaskUnavailable` without the extra.
    """
    start_worker_server()  # first, so that its imports overlap this process's import of Dask
    with contextlib.ExitStack() as stack:
        # Importing Dask and starting the cluster make objects in a burst that would set off several
        # full passes of the garbage collector (gc_control); it runs again once they are made.
        with paused_gc():
            distributed = _distributed()
            stack.enter_context(_local_cluster_settings())
            cluster = stack.enter_context(distributed.LocalCluster(
                n_workers=0, threads_per_worker=1, processes=True, dashboard_address=None,
                scheduler_kwargs=LOCAL_SCHEDULER,
                # A worker whose start hangs gives up after this long, so closing the cluster cannot hang.
                death_timeout=WORKER_START_TIMEOUT_S,
                # Workers log a lost heartbeat as an error while the cluster shuts down; not the user's concern.
                silence_logs=logging.CRITICAL))
            client = stack.enter_context(distributed.Client(cluster))
            # The workers start while the caller prepares its tasks, instead of before: the scheduler
            # holds the tasks until they arrive.  A worker that cannot start fails its tasks after
            # distributed.scheduler.no-workers-timeout (LOCAL_CLUSTER_CONFIG).
            cluster.scale(workers)
        yield client


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
        worker processes (the simulations hold the GIL, so threads would not help), with
        :func:`local_client`.
    """
    if (address is None) == (local_workers is None):
        raise InputError("give exactly one of a scheduler address (--dask) and a local worker count (--dask-local)")
    if local_workers is not None:
        with local_client(local_workers) as client:
            yield client.get_executor(pure=False), f"Dask LocalCluster of {local_workers} worker process(es)"
        return
    distributed = _distributed()
    check_scheduler(address)
    try:
        client = distributed.Client(address, timeout=CONNECT_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError, MemoryError) as exc:
        raise DaskConnectionError(f"--dask {address}: cannot reach the scheduler: {exc}") from None
    with _quiet_dask_logs():
        try:
            yield client.get_executor(pure=False), f"Dask scheduler {address}"
        finally:
            # A client whose scheduler is gone would go on trying to reach it while it closes.
            with contextlib.suppress(Exception):
                client.close(timeout=CLOSE_TIMEOUT_S)


@contextlib.contextmanager
def _quiet_dask_logs() -> Iterator[None]:
    """Dask's own log records below CRITICAL kept off stderr inside the block: a lost scheduler is one line
    from the sweep (:func:`executor_watch`), where Dask's client logs each reconnection attempt and a
    traceback when it is closed in the middle of one."""
    # Dask's logging configuration gives some of its loggers a level of their own ("distributed.client").
    names = ["distributed", *(n for n in logging.root.manager.loggerDict if n.startswith("distributed."))]
    levels = {name: logging.getLogger(name).level for name in names}
    for name in names:
        logging.getLogger(name).setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for name, level in levels.items():
            logging.getLogger(name).setLevel(level)


def check_scheduler(address: str) -> None:
    """Raise :class:`DaskConnectionError` unless a Dask scheduler answers at ``address`` (``tcp://`` or no
    scheme; other schemes are left to Dask's client).

    Dask's client retries a refused connection until its timeout, waits without a limit for a server that
    accepts the connection but never speaks (an HTTP server), and reads the reply of one that speaks first
    as the length of a message (an allocation of exabytes).  A scheduler sends its handshake as soon as it
    accepts a connection: eight bytes giving the length of a small message.  So a plain socket tells, in
    at most :data:`HANDSHAKE_TIMEOUT_S`, whether one is there.
    """
    import socket

    from distributed.comm import parse_address, parse_host_port

    def fail(why: str):
        raise DaskConnectionError(f"--dask {address}: {why}")

    try:
        scheme, location = parse_address(address)
        host, port = parse_host_port(location)
    except (ValueError, TypeError) as exc:
        fail(f"not a scheduler address ({exc}); write tcp://HOST:PORT")
    if scheme != "tcp":
        return
    try:
        sock = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S)
    except ConnectionRefusedError:
        fail("connection refused: no scheduler listens there")
    except OSError as exc:  # a timeout, an unknown host, no route
        fail(f"cannot reach the scheduler: {exc.strerror or exc or 'no answer'}")
    with sock:
        sock.settimeout(HANDSHAKE_TIMEOUT_S)
        try:
            first = sock.recv(8, socket.MSG_WAITALL)
        except OSError:  # the timeout, or a reset
            first = b""
    if len(first) < 8:
        fail(f"not a Dask scheduler: it sent no handshake within {HANDSHAKE_TIMEOUT_S:g} s")
    if int.from_bytes(first, "little") > MAX_HANDSHAKE_BYTES:
        fail(f"not a Dask scheduler: it answered {first!r}")


SCHEDULER_LOST_S = 5.0
"""How long a sweep waits for its client to get back its connection to the scheduler before it stops [s]
(Dask's client would try for ``distributed.comm.timeouts.connect``, then cancel every task)."""

LAST_WORKER_LOST_S = 10.0
"""How long a sweep waits, once its cluster has had a worker, for one to come back after the last has
gone before it stops [s] (a local cluster's nanny restarts a dead worker within seconds; a scheduler of
your own waits for ever)."""

NO_WORKER_S = 30.0
"""How long a sweep waits for the first worker of a cluster [s] (a local cluster's start, or a scheduler
whose workers have not connected yet)."""


def executor_watch(executor: Executor) -> Callable[[], str | None] | None:
    """A check of the cluster behind a Dask executor (``Client.get_executor()``), or None for any other.

    Calling it returns None while the cluster can run the sweep's tasks, and a message once the client has
    lost its scheduler for :data:`SCHEDULER_LOST_S` or the scheduler has had no worker for
    :data:`LAST_WORKER_LOST_S` (:data:`NO_WORKER_S` before the first arrived): the sweep then stops
    instead of waiting for ever.  It reads what the client last heard from the scheduler (updated every
    2 s), so a call costs nothing.
    """
    client = _dask_client(executor)
    return None if client is None else _ClusterWatch(client)


def _dask_client(executor: Executor):
    """The ``distributed.Client`` behind a Dask executor, or None for any other executor."""
    client = getattr(executor, "_client", None)
    return client if client is not None and type(executor).__module__.startswith("distributed") else None


def executor_workers(executor: Executor) -> int | None:
    """Workers (threads) that run ``executor``'s tasks: a process or thread pool's, or the threads of a Dask
    cluster's workers as the scheduler last reported them (0 before any has connected); None for any other
    executor."""
    client = _dask_client(executor)
    if client is not None:
        return int((getattr(client, "_scheduler_identity", None) or {}).get("total_threads") or 0)
    workers = getattr(executor, "_max_workers", None)
    return workers if isinstance(workers, int) else None


class _ClusterWatch:
    """:func:`executor_watch` of one client: when each trouble began, and whether a worker was ever seen."""

    def __init__(self, client):
        self.client = client
        self.since: dict[str, float] = {"workers": time.monotonic()}
        self.had_worker = False

    def _lasted(self, trouble: str, now: float, present: bool) -> float:
        """How long ``trouble`` has been present [s] (0 when it is not)."""
        if not present:
            self.since.pop(trouble, None)
            return 0.0
        return now - self.since.setdefault(trouble, now)

    def __call__(self) -> str | None:
        now = time.monotonic()
        address = getattr(self.client.scheduler, "address", None) or "the scheduler"
        if self._lasted("scheduler", now, self.client.status != "running") > SCHEDULER_LOST_S:
            return f"lost the Dask scheduler {address} (client {self.client.status} for {SCHEDULER_LOST_S:g} s)"
        workers = (getattr(self.client, "_scheduler_identity", None) or {}).get("n_workers")
        if workers is None:
            return None
        self.had_worker = self.had_worker or workers > 0
        limit = LAST_WORKER_LOST_S if self.had_worker else NO_WORKER_S
        if self._lasted("workers", now, workers == 0) > limit:
            what = "lost its last worker" if self.had_worker else "has had no worker"
            return f"the Dask scheduler {address} {what} for {limit:g} s"
        return None
