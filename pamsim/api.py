"""The three-line path: ``load_scenario``, ``simulate``, ``result.plot()``.

``simulate`` and ``as_scenario`` live in :mod:`pamsim.backends` and ``simulate_python`` in
:mod:`pamsim.simulator`, so that sweeps, fits and the control tools, which this module's
:func:`run` calls, can run scenarios without importing it; they are re-exported here.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

from .backends import BACKENDS, as_scenario, simulate
from .errors import InputError
from .result import Result
from .scenario import Scenario, load_scenario  # noqa: F401 -- re-exported
from .simulator import simulate_python  # noqa: F401 -- re-exported

if TYPE_CHECKING:
    from .control.closed_loop import ClosedLoopRun
    from .paperdata import SteadyState


@dataclass
class ScenarioRun:
    """One run of a scenario as ``pamsim run`` does it: open loop, or with its ``[controller]``.

    ``closed_loop`` is the :class:`~pamsim.control.closed_loop.ClosedLoopRun`
    of a scenario with a controller, else None.  ``measured`` is the measured end of
    the test the scenario's ``[measured]`` table names
    (:meth:`~pamsim.scenario.Scenario.measured_steady_state`), else None.
    """

    result: Result
    backend: str
    closed_loop: "ClosedLoopRun | None" = None
    measured: "SteadyState | None" = None

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

    def figure(self, measured: bool = True):
        """The run's figure: contraction, pressure and forces (with the measured end of the test, unless
        ``measured`` is False), or the closed-loop response."""
        if self.closed_loop is None:
            from .plotting import result_figure

            return result_figure(self.result, backend=self.backend, measured=self.measured if measured else None)
        from .control.plots import closed_loop_figure

        return closed_loop_figure(self.closed_loop)


def run(scenario: "Scenario | str | os.PathLike", backend: str = "python",
        progress: "Callable[[float], None] | None" = None) -> ScenarioRun:
    """Run ``scenario`` on ``backend`` (a name of :data:`pamsim.backends.BACKENDS`).

    A scenario with a ``[controller]`` table runs with its controller on every backend: the controller
    is a component of the run's assembly, which the native backend runs on the generic C engine and the
    FMU backends through the FMU generated from it.  ``progress`` receives the simulated time reached
    (python backend; the others do not report it).
    """
    scenario = as_scenario(scenario)
    if backend not in BACKENDS:
        raise InputError(f"unknown backend {backend!r} (choose from {', '.join(sorted(BACKENDS))})")
    if "controller" in scenario.spec:
        from .control.closed_loop import run_closed_loop

        loop = run_closed_loop(scenario, progress=progress, backend=backend)
        return ScenarioRun(loop.result, backend, loop)
    return ScenarioRun(simulate(scenario, backend, progress), backend, measured=scenario.measured_steady_state())

