"""Identification of a muscle from measurements: static fits (force or equilibrium contraction) and
dynamic fits of step responses (the ACRA 2012 paper's eq. 13), with uncertainty, cross-validation and
model comparison.  See docs/identification.md.
"""

from .columns import DataError, StaticData, TraceData, read_static_data, read_trace
from .dynamic_fit import DynamicFit, fit_dynamic
from .static_fit import StaticFit, fit_static

__all__ = ["DataError", "StaticData", "TraceData", "read_static_data", "read_trace", "StaticFit", "fit_static",
           "DynamicFit", "fit_dynamic"]
