"""Simulation backends selectable with ``pamsim run --backend``, and :func:`simulate`, which runs a
scenario on one of them.

Each maps a :class:`~pamsim.scenario.Scenario` to a :class:`~pamsim.result.Result`.
Backends that need optional machinery (a C compiler for the FMU) are
imported only when chosen.  Sweeps, fits and the control tools run their
scenarios through :func:`simulate` here, below :mod:`pamsim.api`, which
re-exports it.
"""

from __future__ import annotations

import importlib
import os
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:
    from .model import MuscleModel
    from .result import Result
    from .scenario import Scenario

# name -> "module:function"
BACKENDS: dict[str, str] = {
    "python": "pamsim.simulator:simulate_python",
    "native": "pamsim.native:simulate",
    "fmu-cs": "pamsim.fmu.runner:simulate_cs",
    "fmu-me": "pamsim.fmu.runner:simulate_me",
}


# name -> "module:function" that runs a scenario with a model in its place (a controller's), as its
# assembly: the one-muscle FMU has no controller, so the FMU backends run the FMU generated from it.
MODEL_BACKENDS: dict[str, str] = {
    "native": "pamsim.native:simulate",
    "fmu-cs": "pamsim.fmu.assembly_runner:simulate_cs",
    "fmu-me": "pamsim.fmu.assembly_runner:simulate_me",
}


DESCRIPTIONS: dict[str, str] = {
    "python": "scipy's solve_ivp (default)",
    "native": "the C core as a shared library, built on first use (needs a C compiler)",
    "fmu-cs": "the exported FMU, co-simulation, through FMPy",
    "fmu-me": "the exported FMU, model exchange, through FMPy",
}
"""name -> one line for ``pamsim run --help``."""


# name -> "module:function" that raises InputError for a scenario the backend cannot run, before any work
CHECKS: dict[str, str] = {
    "native": "pamsim.native:refuse_unsupported",
    "fmu-cs": "pamsim.fmu.runner:check_scenario",
    "fmu-me": "pamsim.fmu.runner:check_scenario",
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


def as_scenario(scenario: "Scenario | str | os.PathLike") -> "Scenario":
    """``scenario`` itself, or the scenario file it names (read and validated).

    Raises
    ------
    TypeError
        For anything else, saying what is expected.
    """
    # Imported here: the command line reads BACKENDS for its options and must not pay for numpy then.
    from .scenario import Scenario, load_scenario

    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, (str, os.PathLike)):
        return load_scenario(scenario)
    raise TypeError(f"expected a pamsim.Scenario or the path of a scenario TOML file, "
                    f"not {type(scenario).__name__}")


def simulate(scenario: "Scenario | str | os.PathLike", backend: str = "python",
             progress: "Callable[[float], None] | None" = None, model: "MuscleModel | None" = None) -> "Result":
    """Run ``scenario`` (a :class:`Scenario` or a scenario file's path) and return its :class:`Result`.

    Parameters
    ----------
    scenario : Scenario, str or PathLike
        The scenario, or the path of its file.
    backend : str
        ``"python"`` (solve_ivp, the default), ``"native"`` (the C core as a shared library), or an
        FMU importer (``"fmu-cs"``, ``"fmu-me"``); see :data:`pamsim.backends.BACKENDS`.  A setting a
        backend cannot honour raises :class:`~pamsim.errors.InputError` naming it.
    progress : callable, optional
        Called with the simulated time reached (python backend; the others do not report it).
    model : MuscleModel, optional
        The scenario's model with its pressure source replaced (a controller's,
        :func:`pamsim.control.closed_loop.closed_loop_model`), run on every backend as its assembly of
        components; None runs the scenario's own model.
    """
    scenario = as_scenario(scenario)
    if "motion" in scenario.spec:
        from .errors import InputError

        raise InputError(f"{scenario.origin}: [motion]: a muscle driven by its length is not the hanging-load rig; "
                         "run it with `pamsim run` or pamsim.muscle_alone.simulate_length_drive")
    if backend == "python":
        from .simulator import simulate_python

        return simulate_python(scenario, progress, model)
    if model is None and backend in ("fmu-cs", "fmu-me") and scenario.beyond_one_muscle_fmu:
        model = scenario.build_model()
    if model is None:
        return get_backend(backend)(scenario)
    get_backend(backend)  # an unknown name refused as such
    module, func = MODEL_BACKENDS[backend].split(":")
    return getattr(importlib.import_module(module), func)(scenario, model)
