"""Running a joint scenario: its assembly's generated code integrated mode by mode of the joint, with the
same exact stick/slip treatment as the one-muscle rig (:class:`pamsim.simulator.HybridRun`)."""

from __future__ import annotations

import math
import time
from collections.abc import Mapping


from ..modeling.pygen import outputs_by_mode
from ..signals import max_step_hint_s
from ..simulator import GeneratedCode, HybridRun
from .result import JointEvent, JointResult
from .scenario import JointScenario


class JointInputs:
    """The joint model's inputs at a time: each muscle's pressure source's, in the assembly's order, then
    the external torque (a slider's: force), a signal of time."""

    def __init__(self, sources, external_torque):
        self.sources, self.external_torque = sources, external_torque

    def __call__(self, t):
        return [*(v for s in self.sources for v in s.inputs(t)), self.external_torque(t)]

    @classmethod
    def of(cls, scenario: JointScenario, muscles=None) -> "JointInputs":
        """The inputs of ``scenario`` (its muscles from :meth:`JointScenario.joint_muscles` if not given)."""
        return cls([m.source for m in muscles or scenario.joint_muscles()], scenario.external_torque)


ENERGY_SCALE_J = 1e-3
"""Absolute tolerance scale of a joint run's energy states [J] (the integrator's atol is rtol times it).
Assumed: a finger-sized joint turns through its range with millijoules (the shipped pair's largest term
is 11 mJ); the components' own scale, 0.1 J, is the hanging load's, and would leave these energies
balanced only to a few 1e-4 of themselves at rtol 1e-6."""


class SampledSignals(Mapping):
    """Every state and output at the samples, by the flat model's names: the states as sampled, the
    outputs computed from them by the per-mode generated code when one is first asked for (a run whose
    caller reads only the angle does not pay for them)."""

    def __init__(self, code: dict, p, Y, inputs, modes):
        names = next(iter(code.values())).names
        self._states = dict(zip(names["states"], Y))
        self._output_names = [n for n in names["outputs"] if n not in self._states]
        self._args, self._outputs = (code, p, Y, inputs, modes), None

    def __getitem__(self, key: str):
        if key in self._states:
            return self._states[key]
        if self._outputs is None:
            code, p, Y, inputs, modes = self._args
            self._outputs = outputs_by_mode(code, p, list(Y), inputs, modes)
        return self._outputs[key]

    def __contains__(self, key) -> bool:  # by name: asking must not compute the outputs
        return key in self._states or key in self._output_names

    def __iter__(self):
        return iter([*self._states, *self._output_names])

    def __len__(self) -> int:
        return len(self._states) + len(self._output_names)


def sampled_signals(code: dict, p, Y, inputs, modes) -> SampledSignals:
    """Every state (rows of ``Y``) and every output at the samples (:class:`SampledSignals`), from the
    per-mode generated code ``code``; ``inputs`` are the model's inputs at the samples."""
    return SampledSignals(code, p, Y, inputs, modes)


def joint_run(scenario: JointScenario) -> tuple[HybridRun, list[str]]:
    """A run of ``scenario`` ready to integrate, and its muscles' names."""
    muscles = scenario.joint_muscles()
    assembly = scenario.assembly()
    flat = assembly.flatten()
    inputs = JointInputs.of(scenario, muscles)
    gen = GeneratedCode(assembly, scenario.body.name, inputs, [ENERGY_SCALE_J if v.unit == "J" else v.nominal for v in flat.states])
    breaks = tuple(b for m in muscles for b in m.source.breakpoints) + tuple(scenario.external_torque.breakpoints)
    longest = min([getattr(m.source, "max_input_step_s", math.inf) for m in muscles]
                  + [max_step_hint_s(scenario.external_torque)])
    return HybridRun(gen, scenario.duration_s, scenario.solver, breaks, longest, None), [m.name for m in muscles]


def simulate_joint_python(scenario: JointScenario) -> JointResult:
    """Integrate ``scenario`` with ``scipy.integrate.solve_ivp`` and return its :class:`JointResult`.

    Raises
    ------
    SolverFailure
        As :func:`pamsim.simulator.simulate_model` does.
    """
    wall0 = time.perf_counter()
    run, names = joint_run(scenario)
    run.integrate(scenario.duration_s)
    t, Y, modes = run.trace()
    signals = sampled_signals(run.gen.code, run.gen.p, Y, run.gen.inputs(t), modes)
    events = [JointEvent(e.t_s, e.kind, e.from_mode, e.to_mode, e.x_m) for e in run.transitions]
    body = scenario.body
    return JointResult(scenario.name, t, signals, modes, events, [loss for _, loss in run.impact_loss_J],
                       run.stats(), time.perf_counter() - wall0, tuple(names),
                       {body.position: run.peak_x, body.min_key: run.low_x}, body)
