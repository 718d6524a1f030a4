"""A sweep's figures rendered to PNG bytes, on an executor's workers when one is given.

Rendering is most of the time of a fast sweep (the native backend runs the 66-case grid in well
under a second; its four figures take seconds of matplotlib layout), and the figures are
independent, so they go to the same executor as the runs.  The workers send back bytes, not files:
a worker of a remote Dask cluster does not share the output folder.
"""

from __future__ import annotations

import io
from concurrent.futures import Executor
from typing import Callable, Mapping

DPI = 110
"""Resolution of every sweep figure [dots per inch]."""


def render_png(maker: Callable, data) -> bytes:
    """``maker(data)`` (a function returning a matplotlib Figure) as PNG bytes."""
    buffer = io.BytesIO()
    maker(data).savefig(buffer, format="png", dpi=DPI)
    return buffer.getvalue()


def render_all(jobs: Mapping[str, tuple[Callable, object]], executor: Executor | None = None) -> dict[str, bytes]:
    """Render ``{name: (maker, data)}``, in this process or on ``executor``, and return ``{name: png}``.

    Jobs are submitted in the order given (put the slowest first so the workers finish together).
    A figure that fails raises here, before the caller writes anything.
    """
    if executor is None:
        return {name: render_png(maker, data) for name, (maker, data) in jobs.items()}
    futures = {name: executor.submit(render_png, maker, data) for name, (maker, data) in jobs.items()}
    return {name: future.result() for name, future in futures.items()}
