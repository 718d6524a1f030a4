"""pamsim: dynamic simulation of McKibben pneumatic artificial muscles.

    import pamsim
    result = pamsim.simulate("scenarios/acra2012_fig4.toml")
    result.plot("fig4.png")

The names below are imported on first use: ``import pamsim`` (and so every
``pamsim`` command, ``--help`` included) does not pay for scipy's integrators,
matplotlib or python-control until they are needed.  ``pamsim.sweep`` is a
callable package: ``pamsim.sweep(spec, executor)`` runs a sweep.
"""

import importlib

__version__ = "0.1.0"

_WHERE = {
    "simulate": "api", "run": "api",
    "Mode": "model", "MuscleModel": "model",
    "PARAMETER_SETS": "parameters", "ParameterSet": "parameters", "get_parameter_set": "parameters",
    "Result": "result",
    "Scenario": "scenario", "ScenarioError": "scenario", "load_scenario": "scenario",
    "SolverFailure": "simulator", "SolverOptions": "simulator", "simulate_model": "simulator",
}

__all__ = ["simulate", "run", "load_scenario", "Scenario", "ScenarioError", "Result", "Mode", "MuscleModel",
           "PARAMETER_SETS", "ParameterSet", "get_parameter_set", "SolverFailure", "SolverOptions",
           "simulate_model"]


def __getattr__(name: str):
    if name == "sweep":
        return importlib.import_module(".sweep", __name__)  # importing it binds pamsim.sweep for good
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE) | {"sweep"})
