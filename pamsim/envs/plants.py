"""The muscle an environment steps, on either backend: its one input set per control step, its state read.

A plant holds one input of the scenario's model (the valve command, or the prescribed pressure) at
the value of each control step and integrates to the step's end:

- :class:`NativePlant`: the scenario's assembly in the compiled generic engine, one library call a step
  (:class:`pamsim.native.engine.EngineSession`);
- :class:`PythonPlant`: the generated Python integrated by ``solve_ivp``
  (:class:`pamsim.simulator.SteppedRun`).

Each takes, between two control instants, the steps its backend's ``pamsim.simulate`` takes for a
scenario whose signal holds the same values (:class:`pamsim.signals.PiecewiseConstant`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..elements.pressure_source import ValveChamberSource
from ..errors import InputError
from ..scenario import Scenario
from ..simulator import SteppedRun

PRESSURE_INPUT = "muscle.p_gauge_Pa"
"""The muscle component's pressure input: what feeds it is the pressure the environment observes."""


def _pressure_output(assembly) -> str:
    return next(a for a, b in assembly.connections if b == PRESSURE_INPUT)


class HeldValue:
    """A signal whose value its owner sets: constant between two settings, with no breakpoints of its own.

    Parameters
    ----------
    value : float
        The value until it is set again.
    """

    breakpoints: tuple[float, ...] = ()
    max_step_s = math.inf

    def __init__(self, value: float = 0.0):
        self.value = float(value)

    def __call__(self, t):
        """The held value (an array of it for an array of times)."""
        return self.value if isinstance(t, float) else np.full(np.shape(t), self.value)

    @property
    def final_value(self) -> float:
        """The held value."""
        return self.value


class NativePlant:
    """The scenario's model in the compiled generic engine, stepped through an engine session.

    Parameters
    ----------
    scenario : Scenario
        The model, load and solver settings; its pressure source says which input is held.
    input_name : str
        The flat model's input set at each step (``valve_command`` or ``prescribed_pressure_gauge_Pa``).

    Raises
    ------
    InputError
        For what the native backend refuses (naming the key), a static force it runs only as a force
        table, and without a C compiler.
    """

    backend = "native"

    def __init__(self, scenario: Scenario, input_name: str):
        from ..native.backend import case_inputs  # a compiler is needed only for this backend
        from ..native.engine import engine_library

        case = case_inputs(scenario)
        if case.assembly is None:
            raise InputError(f"{scenario.origin}: model.static_force = {scenario.spec['model']['static_force']!r}: "
                             "the native backend runs this model as a force table, which cannot be stepped; "
                             "use backend='python'")
        self.library = library = engine_library(case.assembly)
        first = case.engine_case(library, 1)
        self._params = np.array(first.params, dtype=float)
        self._settings = (first.rtol, first.max_step_s, first.max_steps, first.stiff_switch)
        self._u = np.array(first.segment_u[0], dtype=float)  # a copy: the case's own is read-only, shared by its runs
        self._k = library.names["inputs"].index(input_name)
        states, outputs = library.names["states"], library.names["outputs"]
        self._ix, self._iv = states.index("load.x_m"), states.index("load.v_m_s")
        self._ip = outputs.index(_pressure_output(case.assembly))
        self._session = library.session()
        self._x, self._y = self._session.states, self._session.outputs
        self.state_names = tuple(states)
        """The states' names, in the order of :meth:`states`."""

    def reset(self, value: float) -> tuple[float, float, float]:
        """Start again at t = 0 with the input at ``value``; returns contraction [m], velocity [m/s] and
        gauge pressure [Pa] at the start."""
        self._u[self._k] = value
        self._session.reset(self._params, self._u, *self._settings)
        return self._read()

    def step(self, value: float, t_end_s: float) -> tuple[float, float, float]:
        """Hold the input at ``value`` until ``t_end_s`` [s]; returns contraction, velocity, pressure there."""
        self._u[self._k] = value
        self._session.step(self._u, t_end_s)
        return self._read()

    def _read(self) -> tuple[float, float, float]:
        x, y = self._x, self._y
        return float(x[self._ix]), float(x[self._iv]), float(y[self._ip])

    def states(self) -> np.ndarray:
        """Every state of the model now (a copy), in the order of :attr:`state_names`."""
        return self._session.states.copy()

    def mode(self) -> int:
        """The load's mode now (:class:`pamsim.model.Mode`'s value)."""
        return self._session.read()

    def stats(self) -> dict:
        """Right-hand-side evaluations and events since the reset."""
        self._session.read()
        stats = self._session.stats
        return {"rhs_evaluations": stats["rhs_evaluations"], "events": stats["events"]}


class PythonPlant:
    """The scenario's model as generated Python, integrated by ``solve_ivp`` one control step at a time.

    Parameters
    ----------
    scenario : Scenario
        As :class:`NativePlant` takes it.
    input_name : str
        ``valve_command`` or ``prescribed_pressure_gauge_Pa``.
    """

    backend = "python"

    def __init__(self, scenario: Scenario, input_name: str):
        self._scenario = scenario
        self._held = HeldValue()
        model = scenario.build_model()
        field = {"valve_command": "command", "prescribed_pressure_gauge_Pa": "p_gauge_Pa"}[input_name]
        if (field == "command") != isinstance(model.source, ValveChamberSource):
            raise ValueError(f"input {input_name!r} does not drive the scenario's pressure source")
        self._model = dataclasses.replace(model, source=dataclasses.replace(model.source, **{field: self._held}))
        self._run = self._new_run()
        self.state_names = self._run.state_names
        """The states' names, in the order of :meth:`states`."""
        self._ip = self._run.output_names.index(_pressure_output(self._run.assembly))

    def _new_run(self) -> SteppedRun:
        sc = self._scenario
        return SteppedRun(self._model, sc.solver, sc.initial_contraction_m, sc.initial_pressure_gauge_Pa,
                          sc.added_components)

    def reset(self, value: float) -> tuple[float, float, float]:
        """As :meth:`NativePlant.reset`."""
        self._held.value = float(value)
        self._run = self._new_run()
        return self._read()

    def step(self, value: float, t_end_s: float) -> tuple[float, float, float]:
        """As :meth:`NativePlant.step`."""
        self._held.value = float(value)
        self._run.advance(t_end_s)
        return self._read()

    def _read(self) -> tuple[float, float, float]:
        y = self._run.y
        return float(y[0]), float(y[1]), float(self._run.outputs()[self._ip])

    def states(self) -> np.ndarray:
        """As :meth:`NativePlant.states`."""
        return np.array(self._run.y, dtype=float)

    def mode(self) -> int:
        """As :meth:`NativePlant.mode`."""
        return int(self._run.mode)

    def stats(self) -> dict:
        """As :meth:`NativePlant.stats`."""
        return self._run.stats


PLANTS = {"native": NativePlant, "python": PythonPlant}
"""The backends an environment runs on, by name."""
