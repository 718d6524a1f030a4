"""A joint scenario on the native backend: the joint's assembly compiled into the generic C engine
(:mod:`pamsim.native.engine`), its inputs cut into exact segments as the one-muscle rig's are, and the
engine's samples and events turned into the same :class:`JointResult` as the python backend's."""

from __future__ import annotations

import time

import numpy as np

from ..components.stick_slip import BodyMode, event_name
from ..errors import InputError
from ..assemblies.one_muscle import RUN_FUNCTIONS
from ..modeling.pygen import compiled_by_mode
from ..native.backend import (SCENARIO_CACHE_SIZE, KeptByObject, check_status, engine_stats, event_capacity,
                              exact_segments, native_rtol, stiff_switch)
from ..native.engine import EngineCase, engine_library
from .result import JointEvent, JointResult
from .scenario import JointScenario
from .simulate import JointInputs, sampled_signals

MAX_STEP_S = 0.1
"""The engine's longest step when the scenario sets none [s] (the one-muscle FMU's default step)."""
MAX_INTERNAL_STEPS = 1_000_000
"""Integrator steps the engine may take per input segment before it gives up."""
_PREPARED = KeptByObject(SCENARIO_CACHE_SIZE)


def simulate_joint_native(scenario: JointScenario) -> JointResult:
    """Integrate ``scenario`` on the native engine and return its :class:`JointResult`.

    Raises
    ------
    InputError
        A muscle's input signal the engine cannot carry (a Python callable), or a bad value the engine
        finds (a parameter out of range).
    SolverFailure
        The integrator failed, or the run had more than ``solver.max_events`` events.
    """
    assembly, library, case, muscles = _prepared(scenario)
    opts = scenario.solver
    wall0 = time.perf_counter()
    out = library.run([case])
    wall = time.perf_counter() - wall0
    check_status(out, 0, scenario.origin, opts.max_events)
    return _result(scenario, assembly, muscles, library.names, out, np.linspace(0.0, scenario.duration_s, case.n_samples),
                   wall)


def _prepared(scenario: JointScenario) -> tuple:
    """The assembly, engine, :class:`EngineCase` and muscles of ``scenario``, built at its first native run
    and kept for the next, by the scenario object (a scenario does not change once made; a sweep's new
    scenarios build their own)."""
    kept = _PREPARED.get(scenario)
    if kept is not None:
        return kept
    assembly = scenario.assembly()
    library = engine_library(assembly)
    muscles = scenario.joint_muscles()
    signals = [s for m in muscles for s in m.source.signals] + [scenario.external_torque]
    pieces = exact_segments(signals, scenario.duration_s)
    if pieces is None:
        raise InputError(f"{scenario.origin}: a muscle's pressure input is a Python function, which the native "
                         "backend cannot carry; run it with the python backend")
    starts, u, du = pieces
    opts = scenario.solver
    n = int(round(scenario.duration_s * opts.sample_rate_Hz)) + 1
    case = EngineCase(np.array(assembly.parameter_values()), native_rtol(opts),
                      opts.max_step_s if np.isfinite(opts.max_step_s) else MAX_STEP_S, MAX_INTERNAL_STEPS,
                      scenario.duration_s, n, starts, u, event_capacity(opts.max_events), du, stiff_switch(opts))
    for array in (case.params, case.segment_t_s, case.segment_u, case.segment_du):
        array.flags.writeable = False  # kept for the next run: no run may change it
    kept = (assembly, library, case, muscles)
    _PREPARED.put(scenario, kept)
    return kept


def _result(scenario: JointScenario, assembly, muscles, names: dict, out: dict, t: np.ndarray, wall_s: float) -> JointResult:
    """The engine's output as a :class:`JointResult`: every state sampled, the outputs computed from them
    by the python backend's generated code, the events named from the indicators that fired."""
    ns, n = len(names["states"]), len(t)
    Y = np.array(out["samples"][:ns * n].reshape(ns, n))
    modes = out["modes"][:n].astype(int)
    code = compiled_by_mode(assembly, scenario.body.name, RUN_FUNCTIONS)
    signals = sampled_signals(code, assembly.parameter_values(), Y, JointInputs.of(scenario, muscles)(t), modes)
    outputs = names["outputs"]
    body = scenario.body
    theta, ke = outputs.index(f"{body.name}.{body.position}"), outputs.index(f"{body.name}.kinetic_energy_J")
    ny = len(outputs)
    events, losses = [], []
    others = tuple(f"{c}.{n}" for c, n in assembly.indicator_names()[2:])  # the muscles' hysteresis elements'
    for e in out["events"][:int(out["n_events"][0])].tolist():
        before, after = e[4:4 + ny], e[4 + ny:4 + 2 * ny]
        mode, to = BodyMode(int(e[1])), BodyMode(int(e[2]))
        events.append(JointEvent(e[0], event_name(mode, int(e[3]), to, others), mode.label, to.label, after[theta]))
        if before[ke] != after[ke]:
            losses.append(before[ke] - after[ke])
    high, low = out["extremes"][0][:ny], out["extremes"][0][ny:]
    stats = engine_stats(out, 0, scenario.solver, len(events))
    return JointResult(scenario.name, t, signals, modes, events, losses, stats, wall_s, tuple(m.name for m in muscles),
                       {body.position: float(high[theta]), body.min_key: float(low[theta])}, body)
