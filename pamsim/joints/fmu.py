"""Muscles on a joint as an FMU, and the FMU backends of a joint scenario.

The FMU is the joint's assembly's (:func:`pamsim.fmu.assembly_fmu.spec_of_assembly`): structured names
(``joint.theta_rad``, ``flexor_chamber.p_gauge_Pa``), every parameter of every component at the
scenario's value, each muscle's pressure inputs (``flexor.valve_command``...) following the scenario's
signals unless the importer drives them, exact directional derivatives, Model Exchange and
Co-Simulation.  Run by fmpy, it gives the same :class:`JointResult` as the other backends; its events
are counted from the mode's changes between samples (an FMU does not report its events).
"""

from __future__ import annotations

import os
from pathlib import Path


from ..assemblies.one_muscle import RUN_FUNCTIONS, source_parts
from ..errors import InputError
from ..fmu.assembly_fmu import spec_of_assembly
from ..fmu.build import FMI_VERSIONS, build_spec, temp_fmu
from ..fmu.preset import SIGNAL_UNITS, Experiment, input_signal
from ..fmu.assembly_runner import KINDS, run_trace
from ..fmu.runner import trace_stats
from ..fmu.spec import FmuSpec
from ..modeling.pygen import compiled_by_mode
from .result import JointResult
from .scenario import JointScenario
from .simulate import JointInputs, sampled_signals

def joint_fmu_spec(scenario: JointScenario, fmi_version: int = 2) -> FmuSpec:
    """The :class:`~pamsim.fmu.spec.FmuSpec` of the FMU of ``scenario``'s joint and muscles.

    Raises
    ------
    InputError
        For a muscle's input the FMU cannot carry (a Python function), naming it.
    """
    signals = {}
    for m in scenario.joint_muscles():
        names = list(source_parts(m.source, None).inputs)
        signals.update({f"{m.name}.{n}": s for n, s in zip(names, m.source.signals)})
    external = scenario.body.external
    signals[external] = scenario.external_torque

    def signals_of(names):
        out = {}
        for name in names:
            unit = {"Nm": "N m", "N": "N"}[scenario.body.unit] if name == external else SIGNAL_UNITS[name.split(".", 1)[1]]
            try:
                out[name] = input_signal(signals[name], unit)
            except InputError as exc:
                raise InputError(f"{scenario.origin}: input {name}: {exc}") from None
        return out

    opts = scenario.solver
    return spec_of_assembly(scenario.assembly(), signals_of,
                            Experiment(scenario.duration_s, 1.0 / opts.sample_rate_Hz, opts.rtol),
                            f"joint scenario {scenario.name} ({scenario.origin})", fmi_version)


def build_joint_fmu(scenario: JointScenario, output_path: str | os.PathLike | None = None,
                    fmi_version: int = 2) -> Path:
    """Generate, compile and zip the FMU of ``scenario``'s joint (default ``pamsim_assembly_fmi<version>.fmu``).

    Raises :class:`~pamsim.errors.InputError` for an unknown FMI version, an input the FMU cannot carry,
    a missing C compiler or a failed compilation.
    """
    if fmi_version not in FMI_VERSIONS:
        raise InputError(f"FMI version must be 2 or 3, not {fmi_version!r}")
    spec = joint_fmu_spec(scenario, fmi_version)
    return build_spec(Path(output_path) if output_path else Path(f"{spec.identifier}_fmi{fmi_version}.fmu"), spec)


def simulate_joint_fmu(scenario: JointScenario, interface: str = "cs", fmi_version: int = 2) -> JointResult:
    """Run ``scenario`` through its joint's FMU with fmpy: ``"cs"``, the FMU's own Dormand-Prince 5(4) at
    the scenario's ``rtol``; ``"me"``, fmpy's CVode at that ``rtol``.

    Raises
    ------
    InputError
        For an unknown interface, or an input the FMU cannot carry.
    SolverFailure
        When fmpy or the FMU fails.
    """
    if interface not in KINDS:
        raise InputError(f"FMU interface must be 'cs' or 'me', not {interface!r}")
    spec = joint_fmu_spec(scenario, fmi_version)
    path = temp_fmu(spec.token, f"{spec.identifier}_fmi{fmi_version}.fmu", lambda out: build_spec(out, spec))
    body = scenario.body
    t, Y, modes, wall = run_trace(path, interface, scenario.duration_s, scenario.solver, spec.states, f"{body.name}.mode")
    opts = scenario.solver
    assembly = scenario.assembly()
    muscles = scenario.joint_muscles()
    signals = sampled_signals(compiled_by_mode(assembly, body.name, RUN_FUNCTIONS), assembly.parameter_values(), Y,
                              JointInputs.of(scenario, muscles)(t), modes)
    return JointResult(scenario.name, t, signals, modes, [], [], trace_stats(modes, f"fmu-{interface}", opts.rtol),
                       wall, tuple(m.name for m in muscles), body=body)


def simulate_joint_cs(scenario: JointScenario) -> JointResult:
    """Backend ``fmu-cs`` for a joint: FMI 2.0 co-simulation of its FMU."""
    return simulate_joint_fmu(scenario, "cs")


def simulate_joint_me(scenario: JointScenario) -> JointResult:
    """Backend ``fmu-me`` for a joint: FMI 2.0 model exchange of its FMU."""
    return simulate_joint_fmu(scenario, "me")
