"""A sweep's figures rendered to the bytes of their files (PNG, PDF or SVG), on an executor's workers when
one is given.

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

from ..figure_style import save

SWEEP_FIGURES = {  # slowest first, so that the workers finish together
    "time_responses": "pamsim.sweep.plots:time_responses_figure",
    "error_heatmap": "pamsim.sweep.plots:error_heatmap_figure",
    "steady_state_vs_pressure": "pamsim.sweep.plots:steady_state_figure",
    "frequency_vs_load": "pamsim.sweep.plots:frequency_figure",
}
"""``{file stem: "module:function"}`` of a sweep's figures (each function takes a ``SweepResult``); the files
are ``STEM.png``, ``.pdf`` or ``.svg``."""

UNCERTAINTY_FIGURES = {
    "uncertainty_histograms": "pamsim.sweep.uncertainty_plots:histogram_figure",
    "uncertainty_ecdf": "pamsim.sweep.uncertainty_plots:ecdf_figure",
}
"""``{file stem: "module:function"}`` of an uncertainty study's figures (each takes an ``UncertaintyResult``)."""


def maker(name: str):
    """The figure function named ``"module:function"``."""
    module, function = name.split(":")
    return getattr(importlib.import_module(module), function)


def render(maker_name: str, data, figure_format: str = "png", dpi: int | None = None) -> bytes:
    """The figure of ``maker(maker_name)(data)`` (a matplotlib Figure) as the bytes of a ``figure_format`` file
    at ``dpi`` dots per inch (default 110)."""
    buffer = io.BytesIO()
    save(maker(maker_name)(data), buffer, figure_format, dpi)
    return buffer.getvalue()


def render_all(jobs: Mapping[str, tuple[str, object]], executor: Executor | None = None, figure_format: str = "png",
               dpi: int | None = None) -> dict[str, bytes]:
    """Render ``{file name: (maker name, data)}``, in this process or on ``executor``; return ``{file name: bytes}``.

    Jobs are submitted in the order given (put the slowest first so the workers finish together).
    A figure the executor cannot give (a pool broken by a worker killed during the sweep, a cluster
    that lost its workers) is drawn in this process; a figure that fails there raises, before the
    caller writes anything.
    """
    if executor is None:
        return {name: render(maker_name, data, figure_format, dpi) for name, (maker_name, data) in jobs.items()}
    futures = {}
    for name, (maker_name, data) in jobs.items():
        try:
            futures[name] = executor.submit(render, maker_name, data, figure_format, dpi)
        except Exception:  # noqa: BLE001 -- a broken pool (a worker killed during the sweep): drawn here
            futures[name] = None
    files = {}
    for name, future in futures.items():
        if future is not None:
            try:
                files[name] = future.result()
                continue
            except Exception:  # noqa: BLE001 -- the executor failed, or the figure did: drawn here,
                pass  # which gives the figure or raises the figure's own error
        files[name] = render(*jobs[name], figure_format, dpi)
    return files
