"""The three-line path: ``load_scenario``, ``simulate``, ``result.plot()``."""

from __future__ import annotations

import os

from .result import Result
from .scenario import Scenario, load_scenario
from .simulator import simulate_model


def as_scenario(scenario: "Scenario | str | os.PathLike") -> Scenario:
    """``scenario`` itself, or the scenario file it names (read and validated).

    Raises
    ------
    TypeError
        For anything else, saying what is expected.
    """
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, (str, os.PathLike)):
        return load_scenario(scenario)
    raise TypeError(f"expected a pamsim.Scenario or the path of a scenario TOML file, "
                    f"not {type(scenario).__name__}")


def simulate(scenario: "Scenario | str | os.PathLike") -> Result:
    """Run ``scenario`` (a :class:`Scenario` or a scenario file's path) with the Python (solve_ivp) backend.

    Returns its :class:`Result`.
    """
    scenario = as_scenario(scenario)
    return simulate_model(scenario.build_model(), scenario.duration_s, scenario.solver,
                          x0_m=scenario.initial_contraction_m, name=scenario.name,
                          p0_gauge_Pa=scenario.initial_pressure_gauge_Pa)
