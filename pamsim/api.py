"""The three-line path: ``load_scenario``, ``simulate``, ``result.plot()``."""

from __future__ import annotations

from .result import Result
from .scenario import Scenario
from .simulator import simulate_model


def simulate(scenario: Scenario, backend: str = "python") -> Result:
    """Run ``scenario`` and return its :class:`Result`.

    Parameters
    ----------
    scenario : Scenario
        The scenario to run.
    backend : str
        ``"python"`` (solve_ivp, the default), ``"native"`` (the C core as a shared library), or an
        FMU importer (``"fmu-cs"``, ``"fmu-me"``); see :data:`pamsim.backends.BACKENDS`.  A setting a
        backend cannot honour raises :class:`~pamsim.errors.InputError` naming it.
    """
    from .backends import get_backend

    return get_backend(backend)(scenario)


def simulate_python(scenario: Scenario) -> Result:
    """Backend ``python``: integrate ``scenario`` with ``scipy.integrate.solve_ivp``."""
    return simulate_model(scenario.build_model(), scenario.duration_s, scenario.solver,
                          x0_m=scenario.initial_contraction_m, name=scenario.name,
                          p0_gauge_Pa=scenario.initial_pressure_gauge_Pa)
