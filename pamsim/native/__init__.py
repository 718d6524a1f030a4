"""The native backend: the C core of the FMU built as a shared library and called through ctypes.

    import pamsim
    result = pamsim.simulate(scenario, backend="native")
    results = pamsim.native.simulate_batch([scenario_a, scenario_b])   # one library call

:mod:`.build` compiles and caches the library, :mod:`.library` binds it, and
:mod:`.backend` turns scenarios into its inputs and its traces into
:class:`~pamsim.result.Result` s.
"""

from .backend import case_inputs, refuse_unsupported, simulate, simulate_batch

__all__ = ["case_inputs", "refuse_unsupported", "simulate", "simulate_batch"]
