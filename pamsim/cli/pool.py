"""The worker processes of a command (``--workers N``), stopped at once if the command is interrupted."""

from __future__ import annotations

import contextlib
import signal
from concurrent.futures import ProcessPoolExecutor


@contextlib.contextmanager
def process_pool(workers: int):
    """A ``ProcessPoolExecutor`` of ``workers`` processes that, if the block raises (an interrupt, SIGTERM, a
    lost run), stops its workers at once instead of waiting for their chunks: left running, they outlived
    the command and kept its stdout open."""
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_die_on_sigterm)
    try:
        yield pool
    except BaseException:
        _kill_workers(pool)
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def _die_on_sigterm() -> None:
    """A worker forked from the command inherits its SIGTERM handler, which raises an interrupt wherever the
    worker is (in the middle of reading its next chunk, say) instead of ending it."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _kill_workers(pool: ProcessPoolExecutor) -> None:
    """Kill ``pool``'s workers where they are; the chunks that have not started are dropped by the shutdown.

    A worker killed while it sends its results leaves half a message in the results pipe, and the pool's
    manager thread waits for the rest for ever (the shutdown, and the interpreter's exit, with it). The
    command never writes to that pipe, so it closes its own end for writing at once (in a ``finally``: a
    second interrupt here must not leave it open): once the killed workers' ends are closed too, that
    wait becomes an end of file, which the pool takes for a broken pool.
    """
    # CPython's pool keeps {pid: process} and its results queue as private attributes.
    try:
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            process.kill()
    finally:
        results = getattr(pool, "_result_queue", None)
        if results is not None:
            results._writer.close()
