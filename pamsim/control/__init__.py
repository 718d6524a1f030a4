"""Control design with python-control: the muscle as an I/O system, operating
points, linearisations and a closed-loop position controller.

python-control is imported as ``ct``; this package never shadows it.  See
``docs/control.md``.  The names below are imported on first use, so that
``pamsim.control.choices`` (read by the CLI) does not import python-control.
"""

import importlib

_WHERE = {
    "LinearModel": "linear", "MechanicalMode": "linear", "linearize": "linear",
    "OperatingPoint": "operating_point", "held_equilibrium": "operating_point",
    "open_valve_equilibrium": "operating_point", "trajectory_point": "operating_point",
    "INPUTS": "system", "OUTPUTS": "system", "STATES": "system", "FrictionTreatment": "system",
    "MusclePlant": "system", "muscle_nlsys": "system",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str):
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value
    return value
