"""Parameter sweeps: many cases of one base scenario, compared with measured steady states.

``pamsim.sweep`` is both this package and a function::

    import pamsim
    spec = pamsim.sweep.load_sweep("scenarios/acra2012_grid.toml")
    result = pamsim.sweep(spec, executor)      # same as pamsim.sweep.run_sweep(spec, executor)
    result.write("out/")

The package is callable so that the short form and the submodules
(:mod:`.spec` reads and validates sweep files, :mod:`.run` runs them,
:mod:`.report` and :mod:`.plots` write the outputs) live under one name,
and ``import pamsim.sweep`` never finds a function in place of the package.
"""

from __future__ import annotations

import sys
import types

from .run import FIGURES, SETTLED_FRACTION, SweepResult, run_sweep, run_task, settled_time_s
from .spec import FrequencyStudy, SweepCase, SweepError, SweepSpec, load_sweep, sweep_from_dict

__all__ = ["FIGURES", "SETTLED_FRACTION", "FrequencyStudy", "SweepCase", "SweepError", "SweepResult", "SweepSpec",
           "load_sweep", "run_sweep", "run_task", "settled_time_s", "sweep_from_dict"]


class _CallableModule(types.ModuleType):
    def __call__(self, *args, **kwargs):
        return run_sweep(*args, **kwargs)

    __call__.__doc__ = run_sweep.__doc__


sys.modules[__name__].__class__ = _CallableModule
