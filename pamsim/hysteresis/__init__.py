"""Rate-independent hysteresis operators driven by a sampled input, and their identification from loops
(docs/hysteresis.md): Maxwell-slip (:mod:`.maxwell_slip`), generalized Prandtl-Ishlinskii with its analytic
inverse (:mod:`.prandtl_ishlinskii`) and Bouc-Wen (:mod:`.bouc_wen`); :func:`fit_hysteresis` fits them.

The names below are imported on first use, so that the command line can read :data:`MODELS` without
loading numpy or scipy.
"""

from __future__ import annotations

import importlib

MODELS = ("maxwell_slip", "pi", "bouc_wen")
"""The models ``pamsim fit hysteresis --model`` offers."""

_EXPORTS = {
    "MaxwellSlip": "maxwell_slip", "PrandtlIshlinskii": "prandtl_ishlinskii", "BoucWen": "bouc_wen",
    "fit_hysteresis": "fit", "HysteresisFit": "fit", "LoopData": "loop_data", "read_loop": "loop_data",
}
__all__ = ["MODELS", *_EXPORTS]


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
