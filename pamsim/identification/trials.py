"""The simulations of a dynamic fit's trial points on the Python backend, and what the native
backend's (:mod:`.native_fit`) shares with them: the scenario a trace is simulated with and the
fit's integrator tolerance.

A trial is a function ``trials(thetas, executor)`` that gives every trace's contraction at its
sample times for every row of ``thetas``; :func:`pamsim.identification.dynamic_fit.make_trials`
chooses the backend's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Mapping, Sequence

import numpy as np

from ..elements.pressure_source import PrescribedPressure
from ..scenario import Scenario
from ..simulator import simulate_model
from .pressure_input import PiecewiseLinearInput

FIT_RTOL = 1e-8
"""Integrator tolerance of the fit's simulations: the trajectory noise it leaves (about 1e-10 m)
is far below what a step of FD_RELATIVE_STEP changes."""


@dataclass(frozen=True)
class SimulationTask:
    """One simulation of one trace with some coefficients (pickles to a worker process)."""

    scenario: Scenario
    overrides: Mapping[str, float]
    weight_N: float
    duration_s: float
    pressure_t_s: np.ndarray | None
    pressure_Pa: np.ndarray | None
    sample_t_s: np.ndarray


def run_simulation(task: SimulationTask) -> np.ndarray:
    """Contraction [m] at the trace's sample times (relative to its first sample); NaN if it fails.

    A failed simulation (solver failure) returns NaNs rather than raising, so one bad trial point
    of the optimiser does not end the fit; the residuals turn it into a large cost.
    """
    try:
        sc = trace_scenario(task.scenario, task.overrides, task.weight_N, task.duration_s)
        model = sc.build_model()
        p0 = sc.initial_pressure_gauge_Pa
        if task.pressure_t_s is not None:
            model = replace(model, source=PrescribedPressure(PiecewiseLinearInput(task.pressure_t_s, task.pressure_Pa)))
            p0 = None
        res = simulate_model(model, sc.duration_s, sc.solver, x0_m=sc.initial_contraction_m, p0_gauge_Pa=p0,
                             added=sc.added_components)
        return np.interp(task.sample_t_s, res.t_s, res.x_m)
    except Exception:  # noqa: BLE001 -- a trial point that cannot be simulated is a bad point, not an error
        return np.full(task.sample_t_s.shape, np.nan)


def trace_scenario(scenario: Scenario, overrides: Mapping[str, float], weight_N: float, duration_s: float,
                   rtol: float = FIT_RTOL) -> Scenario:
    """The scenario one trace is simulated with: ``overrides`` of its parameters, the trace's load
    [N] and duration [s], the fit's integrator tolerance."""
    return scenario.with_changes({"parameters": dict(overrides), "load": {"weight_N": weight_N},
                                  "simulation": {"duration_s": duration_s}, "solver": {"rtol": rtol}})


def _map(executor, tasks: Sequence[SimulationTask]) -> list[np.ndarray]:
    if executor is None:
        return [run_simulation(t) for t in tasks]
    return list(executor.map(run_simulation, tasks))


class PythonTrials:
    """The fit's simulations on the Python backend: ``trials(thetas, executor)`` gives every trace's
    contraction at its sample times for every row of ``thetas``, theta-major; one task per simulation.
    ``problem`` is a :class:`~pamsim.identification.dynamic_fit.DynamicProblem` (its ``tasks(theta)``)."""

    def __init__(self, problem):
        self.problem = problem

    def __call__(self, thetas: np.ndarray, executor=None) -> list[np.ndarray]:
        return _map(executor, [task for t in np.atleast_2d(thetas) for task in self.problem.tasks(t)])
