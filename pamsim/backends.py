"""Simulation backends selectable with ``pamsim run --backend``.

Each maps a :class:`~pamsim.scenario.Scenario` to a :class:`~pamsim.result.Result`.
Backends that need optional machinery (a C compiler for the FMU) are
imported only when chosen.
"""

from __future__ import annotations

import importlib
from typing import Callable

# name -> "module:function"
BACKENDS: dict[str, str] = {
    "python": "pamsim.api:simulate_python",
    "native": "pamsim.native:simulate",
    "fmu-cs": "pamsim.fmu.runner:simulate_cs",
    "fmu-me": "pamsim.fmu.runner:simulate_me",
}


# name -> "module:function" that raises InputError for a scenario the backend cannot run, before any work
CHECKS: dict[str, str] = {
    "native": "pamsim.native:refuse_unsupported",
    "fmu-cs": "pamsim.fmu.runner:start_values",
    "fmu-me": "pamsim.fmu.runner:start_values",
}


def check_backend(name: str, scenario) -> None:
    """Raise ``InputError`` if backend ``name`` is unknown or cannot honour a setting of ``scenario``."""
    get_backend(name)
    if name in CHECKS:
        module, func = CHECKS[name].split(":")
        getattr(importlib.import_module(module), func)(scenario)


def get_backend(name: str) -> Callable:
    """The function that runs a scenario on backend ``name``; ``InputError`` for an unknown name."""
    if name not in BACKENDS:
        from .errors import InputError

        raise InputError(f"unknown backend {name!r} (choose from {', '.join(BACKENDS)})")
    module, func = BACKENDS[name].split(":")
    return getattr(importlib.import_module(module), func)
