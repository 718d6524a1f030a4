"""A native case's settings in the layout of the one-muscle FMU's variables.

The native backend reads a scenario into the same variables the one-muscle FMU has
(:data:`pamsim.fmu.variables.VARIABLES`): the reals (parameters, start, margins, solver settings)
and the ints (element choices), by name.  The engine (:mod:`pamsim.native.engine`) reads its
solver settings from them; the inputs are the FMU's, in its order.
"""

from __future__ import annotations

import numpy as np

from ..fmu.variables import INPUTS, VARIABLES  # INPUTS: the order of a case's segment_u columns

REALS = tuple(v.name for v in VARIABLES if v.kind == "real")
INTS = tuple(v.name for v in VARIABLES if v.kind == "integer")
REAL_INDEX = {name: i for i, name in enumerate(REALS)}
INT_INDEX = {name: i for i, name in enumerate(INTS)}
REAL_DEFAULTS = np.array([float(v.start) if v.start is not None else 0.0 for v in VARIABLES if v.kind == "real"])
INT_DEFAULTS = np.array([int(v.start) if v.start is not None else 0 for v in VARIABLES if v.kind == "integer"],
                        dtype=np.int32)

__all__ = ["INPUTS", "INTS", "INT_DEFAULTS", "INT_INDEX", "REALS", "REAL_DEFAULTS", "REAL_INDEX"]
