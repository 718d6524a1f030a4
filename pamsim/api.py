"""The three-line path: ``load_scenario``, ``simulate``, ``result.plot()``."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

from .errors import InputError
from .result import Result
from .scenario import Scenario, load_scenario
from .simulator import simulate_model

if TYPE_CHECKING:
    from .control.closed_loop import ClosedLoopRun


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


def simulate(scenario: "Scenario | str | os.PathLike", progress: "Callable[[float], None] | None" = None) -> Result:
    """Run ``scenario`` (a :class:`Scenario` or a scenario file's path) with the Python (solve_ivp) backend.

    Returns its :class:`Result`.  ``progress`` is called with the simulated
    time reached (see :func:`~pamsim.simulator.simulate_model`).
    """
    scenario = as_scenario(scenario)
    return simulate_model(scenario.build_model(), scenario.duration_s, scenario.solver,
                          x0_m=scenario.initial_contraction_m, name=scenario.name,
                          p0_gauge_Pa=scenario.initial_pressure_gauge_Pa, progress=progress)


@dataclass
class ScenarioRun:
    """One run of a scenario as ``pamsim run`` does it: open loop, or with its ``[controller]``.

    ``closed_loop`` is the :class:`~pamsim.control.closed_loop.ClosedLoopRun`
    of a scenario with a controller, else None.
    """

    result: Result
    backend: str
    closed_loop: "ClosedLoopRun | None" = None

    def summary(self) -> dict:
        """The result's summary, with the backend and, in closed loop, the controller's figures."""
        s = {**self.result.summary(), "backend": self.backend}
        if self.closed_loop is not None:
            s["controller"] = self.closed_loop.summary()
        return s

    @property
    def failures(self) -> list[str]:
        """The controller specification items the run misses (empty in open loop)."""
        return [] if self.closed_loop is None else self.closed_loop.failures()

    def figure(self):
        """The run's figure: contraction, pressure and forces, or the closed-loop response."""
        if self.closed_loop is None:
            from .plotting import result_figure

            return result_figure(self.result, backend=self.backend)
        from .control.plots import closed_loop_figure

        return closed_loop_figure(self.closed_loop)


def run(scenario: "Scenario | str | os.PathLike", backend: str = "python",
        progress: "Callable[[float], None] | None" = None) -> ScenarioRun:
    """Run ``scenario`` on ``backend`` (a name of :data:`pamsim.backends.BACKENDS`).

    A scenario with a ``[controller]`` table runs with its controller
    (python backend only: the FMU has no controller, and running it open
    loop would silently give a different system).  ``progress`` receives the
    simulated time reached (python backend; the FMU backends do not report it).
    """
    from .backends import BACKENDS, get_backend

    scenario = as_scenario(scenario)
    if backend not in BACKENDS:
        raise InputError(f"unknown backend {backend!r} (choose from {', '.join(sorted(BACKENDS))})")
    if "controller" in scenario.spec:
        if backend != "python":
            raise InputError(f"{scenario.origin}: controller: the {backend} backend has no controller; "
                             "run this scenario with --backend python")
        from .control.closed_loop import run_closed_loop

        loop = run_closed_loop(scenario, progress=progress)
        return ScenarioRun(loop.result, backend, loop)
    if backend == "python":
        return ScenarioRun(simulate(scenario, progress), backend)
    return ScenarioRun(get_backend(backend)(scenario), backend)
