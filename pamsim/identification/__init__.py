"""Identification of a muscle from measurements: static fits (force or equilibrium contraction) and
dynamic fits of step responses (the ACRA 2012 paper's eq. 13), with uncertainty, cross-validation and
model comparison.  See docs/identification.md.

The names below are imported on first use, so that ``pamsim.identification.choices`` (what the
command line offers) can be read without loading numpy or scipy.
"""

from __future__ import annotations

import importlib

_EXPORTS = {
    "DataError": "columns", "StaticData": "columns", "TraceData": "columns", "read_static_data": "columns",
    "read_trace": "columns", "StaticFit": "static_fit", "fit_static": "static_fit", "DynamicFit": "dynamic_fit",
    "fit_dynamic": "dynamic_fit",
}
__all__ = list(_EXPORTS)


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
