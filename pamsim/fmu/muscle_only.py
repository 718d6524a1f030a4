"""The muscle-only FMU: a muscle whose length and lengthening velocity are inputs and whose force is an
output (:mod:`pamsim.assemblies.muscle_only`), for an importer that owns the mechanics (Simulink and
Simscape, OpenModelica, Dymola, a multibody engine).

Built from a one-muscle scenario: its muscle, static force model, friction and damping laws, pressure
source, the components it adds (its ``[hysteresis]`` among them) and their values; its load and stops
are not used (the importer's mechanics take their place).
The pressure inputs follow the scenario's signals and the length holds at the scenario's start
(``input_source = scenario``) until the importer drives them (``input_source = importer``).
"""

from __future__ import annotations

import os
from pathlib import Path

from ..assemblies.muscle_only import MOTION_INPUTS, muscle_only_assembly
from ..errors import InputError
from ..signals import Constant
from .assembly_fmu import spec_of_assembly
from .build import FMI_VERSIONS, build_spec
from .preset import Experiment, input_signal, scenario_signals
from .spec import FmuSpec

MOTION_UNITS = {"length_m": "m", "lengthening_velocity_m_s": "m/s"}
"""The units of the inputs that move the muscle."""


def muscle_only_spec(scenario, fmi_version: int = 2, motion=None) -> FmuSpec:
    """The :class:`~pamsim.fmu.spec.FmuSpec` of the muscle-only FMU of a one-muscle ``scenario``.

    ``motion``: the scenario's :class:`~pamsim.muscle_alone.motion.Motion`, whose length and its derivative
    the FMU then follows by itself (``input_source = scenario``); None, the length holds at the scenario's
    start until the importer drives it.

    Raises
    ------
    InputError
        For a static force without C (a model written for floats alone), or a pressure input the FMU
        cannot carry.
    """
    if "controller" in scenario.spec:
        raise InputError(f"{scenario.origin}: controller: a muscle-only FMU has no load to control; the importer "
                         "drives its pressure inputs")
    model = scenario.build_model()
    L0 = scenario.parameters["L0_m"]
    try:
        assembly = muscle_only_assembly(model, L0, scenario.parameters["g_m_s2"], scenario.initial_pressure_gauge_Pa,
                                        scenario.added_components)
    except ValueError as exc:
        raise InputError(f"{scenario.origin}: component: {exc}") from None
    if motion is None:
        motion = {"length_m": Constant(L0 - scenario.initial_contraction_m), "lengthening_velocity_m_s": Constant(0.0)}
    else:
        motion = {"length_m": motion.length_signal(), "lengthening_velocity_m_s": motion.velocity_signal()}

    def signals_of(names):
        pressure = [n for n in names if n not in MOTION_INPUTS]
        signals = scenario_signals(scenario, pressure)
        signals.update({n: input_signal(motion[n], MOTION_UNITS[n]) for n in names if n in MOTION_INPUTS})
        return signals

    opts = scenario.solver
    return spec_of_assembly(assembly, signals_of, Experiment(scenario.duration_s, 1.0 / opts.sample_rate_Hz, opts.rtol),
                            f"the muscle of scenario {scenario.name} ({scenario.origin})", fmi_version)


def build_muscle_only(scenario, output_path: str | os.PathLike | None = None, fmi_version: int = 2,
                      motion=None) -> Path:
    """Generate, compile and zip the muscle-only FMU of ``scenario`` (default ``pamsim_assembly_fmi<version>.fmu``),
    following ``motion`` (see :func:`muscle_only_spec`) until the importer drives it.

    Raises :class:`~pamsim.errors.InputError` for an unknown FMI version, a scenario the FMU cannot carry, a
    missing C compiler or a failed compilation.
    """
    if fmi_version not in FMI_VERSIONS:
        raise InputError(f"FMI version must be 2 or 3, not {fmi_version!r}")
    spec = muscle_only_spec(scenario, fmi_version, motion)
    return build_spec(Path(output_path) if output_path else Path(f"{spec.identifier}_fmi{fmi_version}.fmu"), spec)


