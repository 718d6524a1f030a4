"""The FMU backends for a scenario's model with its pressure source replaced (a position controller's,
:mod:`pamsim.control.closed_loop`): the FMU generated from the model's assembly
(:mod:`pamsim.fmu.assembly_fmu`), which contains the controller, run by fmpy.

The one-muscle FMU (:mod:`pamsim.fmu.runner`) has no controller.  The assembly's FMU follows the
scenario's signals itself (``input_source = scenario``): fmpy sets no input.  Every state, the work
integrals included, is a variable of the FMU, so the result is read from its states and its outputs
are the generated ones, as on the native backend; the events are counted from the mode's changes
between samples, as for the one-muscle FMU.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from ..assemblies.one_muscle import RigOutputs, scenario_assembly
from ..errors import InputError, SolverFailure
from ..result import Result
from .assembly_fmu import assembly_spec
from .build import build_spec, temp_fmu
from .runner import grid_rows, trace_stats

KINDS = {"cs": "CoSimulation", "me": "ModelExchange"}
"""fmpy's name of each interface."""


def cached_assembly_fmu(scenario, model, fmi_version: int = 2) -> tuple[Path, tuple[str, ...]]:
    """The FMU of the assembly of ``scenario`` with ``model`` (:func:`~pamsim.fmu.assembly_fmu.assembly_spec`),
    built on first use and kept in the temporary folder under its token, and the names of its states."""
    spec = assembly_spec(scenario, fmi_version, model)
    path = temp_fmu(spec.token, f"{spec.identifier}_fmi{fmi_version}.fmu", lambda out: build_spec(out, spec))
    return path, spec.states


def simulate_assembly(scenario, model, interface: str = "cs", fmi_version: int = 2) -> Result:
    """Run ``scenario`` with ``model`` through the FMU of its assembly with fmpy and return its :class:`Result`.

    Parameters
    ----------
    scenario : Scenario
        The scenario: its start, duration, output grid and tolerance.
    model : MuscleModel
        The scenario's model with its pressure source replaced (a controller's).
    interface : str
        ``"cs"``: co-simulation, the FMU's own Dormand-Prince 5(4) at the scenario's ``rtol``; ``"me"``:
        model exchange, fmpy's CVode at that ``rtol``.
    fmi_version : int
        2 or 3.

    Raises
    ------
    InputError
        For an unknown interface, or a model the FMU cannot carry.
    SolverFailure
        When fmpy or the FMU fails.
    """
    if interface not in KINDS:
        raise InputError(f"FMU interface must be 'cs' or 'me', not {interface!r}")
    path, states = cached_assembly_fmu(scenario, model, fmi_version)
    t, Y, modes, wall = run_trace(path, interface, scenario.duration_s, scenario.solver, states, "load.mode")
    assembly = scenario_assembly(scenario, model)
    return Result.from_trace(model, scenario.name, t, Y, modes, [], [],
                             trace_stats(modes, f"fmu-{interface}", scenario.solver.rtol), wall,
                             outputs=RigOutputs(assembly, model, t, Y, modes))


def run_trace(path: Path, interface: str, duration_s: float, opts, states, mode: str | None):
    """Run the FMU at ``path`` with fmpy (``interface`` ``"cs"`` or ``"me"``) over ``duration_s`` at the
    solver settings ``opts`` (its ``rtol``, ``max_step_s`` and output rate) and return the output grid's
    times [s], the ``states`` (one row each), the hybrid component's ``mode`` variable (zeros for an assembly
    without one, ``mode`` None) and the wall time [s].

    Raises
    ------
    SolverFailure
        When fmpy or the FMU fails.
    """
    from fmpy import simulate_fmu

    dt = 1.0 / opts.sample_rate_Hz
    start = {"cs_relative_tolerance": opts.rtol}
    if math.isfinite(opts.max_step_s):
        start["cs_max_step_s"] = opts.max_step_s
    wall0 = time.perf_counter()
    try:
        res = simulate_fmu(str(path), fmi_type=KINDS[interface], solver="CVode", start_time=0.0,
                           stop_time=duration_s, output_interval=dt, relative_tolerance=opts.rtol,
                           start_values=start, output=[*states, *([mode] if mode else [])], validate=False)
    except Exception as exc:  # fmpy raises a bare Exception carrying the FMI status
        raise SolverFailure(f"FMU {KINDS[interface]} of {Path(path).name} failed: {exc}") from None
    wall = time.perf_counter() - wall0
    rows, t = grid_rows(res["time"], dt)
    return (t, np.array([np.asarray(res[n][rows], dtype=float) for n in states]),
            np.asarray(res[mode][rows], dtype=int) if mode else np.zeros(len(rows), dtype=int), wall)


def simulate_cs(scenario, model) -> Result:
    """Backend ``fmu-cs`` for ``scenario`` with ``model``: FMI 2.0 co-simulation of its assembly's FMU."""
    return simulate_assembly(scenario, model, "cs")


def simulate_me(scenario, model) -> Result:
    """Backend ``fmu-me`` for ``scenario`` with ``model``: FMI 2.0 model exchange of its assembly's FMU."""
    return simulate_assembly(scenario, model, "me")
