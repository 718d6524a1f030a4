"""The three-line path: ``load_scenario``, ``simulate``, ``result.plot()``."""

from __future__ import annotations

from .result import Result
from .scenario import Scenario
from .simulator import simulate_model


def simulate(scenario: Scenario) -> Result:
    """Run ``scenario`` with the Python (solve_ivp) backend and return its :class:`Result`."""
    return simulate_model(scenario.build_model(), scenario.duration_s, scenario.solver,
                          x0_m=scenario.initial_contraction_m, name=scenario.name,
                          p0_gauge_Pa=scenario.initial_pressure_gauge_Pa)
