"""The muscle files' parameter names, units and bounds: kept importable here, defined in
:mod:`pamsim.parameter_schema` (the dynamics' parameter sets use them too)."""

from ..parameter_schema import FILE_INPUTS, INF, KNOWN, LOCK_DEG, SUFFIX_UNITS, Known, unit_of

__all__ = ["FILE_INPUTS", "INF", "KNOWN", "LOCK_DEG", "SUFFIX_UNITS", "Known", "unit_of"]
