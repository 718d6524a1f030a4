"""A sweep's figures rendered to PNG bytes, on an executor's workers when one is given.

Rendering is most of the time of a fast sweep (the native backend runs the 66-case grid in well
under a second; its four figures take seconds of matplotlib layout), and the figures are
independent, so they go to the same executor as the runs.  The workers send back bytes, not files:
a worker of a remote Dask cluster does not share the output folder.

The figure functions are named here (``"module:function"``) rather than imported: only the process
that renders a figure imports matplotlib, and on a process pool that is not the sweep's own
process, which would otherwise spend half a second importing it while the workers wait.
"""

from __future__ import annotations

import importlib
import io
from concurrent.futures import Executor
from typing import Mapping

DPI = 110
"""Resolution of every sweep figure [dots per inch]."""

SWEEP_FIGURES = {  # slowest first, so that the workers finish together
    "time_responses.png": "pamsim.sweep.plots:time_responses_figure",
    "error_heatmap.png": "pamsim.sweep.plots:error_heatmap_figure",
    "steady_state_vs_pressure.png": "pamsim.sweep.plots:steady_state_figure",
    "frequency_vs_load.png": "pamsim.sweep.plots:frequency_figure",
}
"""``{file name: "module:function"}`` of a sweep's figures (each function takes a ``SweepResult``)."""

UNCERTAINTY_FIGURES = {
    "uncertainty_histograms.png": "pamsim.sweep.uncertainty_plots:histogram_figure",
    "uncertainty_ecdf.png": "pamsim.sweep.uncertainty_plots:ecdf_figure",
}
"""``{file name: "module:function"}`` of an uncertainty study's figures (each takes an ``UncertaintyResult``)."""


def maker(name: str):
    """The figure function named ``"module:function"``."""
    module, function = name.split(":")
    return getattr(importlib.import_module(module), function)


def render_png(maker_name: str, data) -> bytes:
    """The figure of ``maker(maker_name)(data)`` (a matplotlib Figure) as PNG bytes."""
    buffer = io.BytesIO()
    maker(maker_name)(data).savefig(buffer, format="png", dpi=DPI)
    return buffer.getvalue()


def render_all(jobs: Mapping[str, tuple[str, object]], executor: Executor | None = None) -> dict[str, bytes]:
    """Render ``{file name: (maker name, data)}``, in this process or on ``executor``; return ``{file name: png}``.

    Jobs are submitted in the order given (put the slowest first so the workers finish together).
    A figure the executor cannot give (a pool broken by a worker killed during the sweep, a cluster
    that lost its workers) is drawn in this process; a figure that fails there raises, before the
    caller writes anything.
    """
    if executor is None:
        return {name: render_png(maker_name, data) for name, (maker_name, data) in jobs.items()}
    futures = {}
    for name, (maker_name, data) in jobs.items():
        try:
            futures[name] = executor.submit(render_png, maker_name, data)
        except Exception:  # noqa: BLE001 -- a broken pool (a worker killed during the sweep): drawn here
            futures[name] = None
    pngs = {}
    for name, future in futures.items():
        if future is not None:
            try:
                pngs[name] = future.result()
                continue
            except Exception:  # noqa: BLE001 -- the executor failed, or the figure did: drawn here,
                pass  # which gives the figure or raises the figure's own error
        pngs[name] = render_png(*jobs[name])
    return pngs
