"""An FMU of any assembly of components, generated from its flat model.

The FMU's variables are the flat model's, under their namespaced names
(``variableNamingConvention="structured"``): every parameter of every component (its start value
the scenario's), the model inputs, every state with its derivative, every output, the hybrid
component's mode, and one event indicator per guard.  Its C core (``fmu/src/pam_gcore.c``) holds no
physics: it evaluates the functions :class:`pamsim.modeling.cmodel.CModel` generates for each mode,
and co-simulates on the generic engine (``pam_engine.c``), the one the native backend runs.  Its
directional derivatives are the exact Jacobians CasADi generates, and its ``ModelStructure``
dependencies are their sparsity (:meth:`pamsim.modeling.flat.FlatModel.sparsity`).

Built from a scenario, the FMU starts as the scenario's run: its inputs follow the scenario's
signals (``input_source = scenario``) and its ``DefaultExperiment`` is the scenario's duration,
output step and tolerance.  The one-muscle rig alone keeps its own FMU (:mod:`pamsim.fmu.variables`),
whose variable names predate components.
"""

from __future__ import annotations

import hashlib
import os
import uuid
from collections import OrderedDict
from dataclasses import replace
from pathlib import Path

from .. import __version__
from ..errors import InputError
from .build import FMI_VERSIONS, build_spec
from .generate import WRAPPERS, c_source_dir
from .preset import Experiment, scenario_signals
from .spec import FmuSpec
from .variables import BY_NAME, INPUT_SOURCE_CHOICES, Variable

SOURCES = ("pam_gcore.c", "pam_gcore.h", "pam_engine.c", "pam_engine.h", "pam_dopri.h", "pam_gauss.h", "pam_log.h",
           "pam_fmu_common.c", "pam_fmu_common.h", "fmi_shell.c", "fmi_shell.h")
"""The hand-written C an assembly FMU ships: the generic core and engine, the FMI shell (``pam_gcore.c``
includes the engine, which includes the generated ``pam_model.c``: one translation unit)."""
CORE_HEADER = '#include "pam_gcore.h" /* the generic core: a generated model on the engine */\n'
OWN_PARAMETERS = ("cs_relative_tolerance", "cs_max_step_s", "cs_max_internal_steps", "input_source")
"""The FMU's own parameters, as the one-muscle FMU declares them."""
DD_KINDS = ("NONE", "STATE", "DERIVATIVE", "OUTPUT", "INPUT", "PARAMETER", "KNOB")
"""Where a variable sits in the exact Jacobians (``PAM_DD_KIND`` of ``pam_variables.h``); ``KNOB``: an FMU
parameter that the generated parameter map turns into the model's (:mod:`pamsim.fmu.muscle_fmu`)."""


def _real(name, causality, variability, description, unit, **kw) -> Variable:
    return Variable(name, "real", causality, variability, description, unit, **kw)


class AssemblyVariables:
    """The variables of an assembly's FMU, and where each sits in the generated model's vectors."""

    def __init__(self, cmodel, parameter_values, input_starts):
        flat = cmodel.full
        self.cmodel, self.flat = cmodel, flat
        self._sparsity = flat.sparsity()
        self.places: dict[str, tuple[str, int]] = {}
        rows = (self._parameters(parameter_values) + [BY_NAME[n] for n in OWN_PARAMETERS]
                + self._inputs(input_starts) + self._states() + self._derivatives() + self._outputs())
        self.mode = f"{cmodel.component}.mode" if cmodel.component else None
        if self.mode:
            values = ", ".join(str(v) for v in cmodel.mode_values)
            rows.append(Variable(self.mode, "integer", "output", "discrete",
                                 f"the mode of {cmodel.component} (one of {values}; changes only at events)",
                                 initial="calculated", depends_on=()))
        self.indicators = tuple(f"event_indicator_{k + 1}" for k in range(len(flat.z)))
        rows += [_real(n, "local", "continuous", "event indicator: positive inside the current mode",
                       None, initial="calculated") for n in self.indicators]
        self.variables = tuple(rows)
        self.value_references = {v.name: k for k, v in enumerate(rows, start=1)}

    def _placed(self, kind: str, rows: list[Variable]) -> list[Variable]:
        """``rows``, each noted as entry k of the model's vector of ``kind`` (:data:`DD_KINDS`)."""
        for k, v in enumerate(rows):
            self.places[v.name] = (kind, k)
        return rows

    def _depends(self, row: int, block_x: str, block_u: str) -> tuple[str, ...]:
        """The states and inputs row ``row`` of the Jacobian blocks ``block_x``, ``block_u`` depends on."""
        flat, sp = self.flat, self._sparsity
        return tuple([flat.states[i].name for i in sp[block_x][row]] + [flat.inputs[i].name for i in sp[block_u][row]])

    def _parameters(self, values) -> list[Variable]:
        return self._placed("PARAMETER", [
            _real(v.name, "parameter", "fixed", f"{v.description} [{v.unit}]", v.unit, start=float(values[k]),
                  initial="exact", lower=v.lower, upper=v.upper, lower_open=v.lower_open, upper_open=v.upper_open)
            for k, v in enumerate(self.flat.parameters)])

    def _inputs(self, starts) -> list[Variable]:
        """The model inputs, with the ranges the one-muscle FMU declares for those it has."""
        return self._placed("INPUT", [
            replace(BY_NAME.get(v.name) or _real(v.name, "input", "continuous", "", v.unit),
                    description=f"{v.description or 'model input'} [{v.unit}]", start=float(starts.get(v.name, 0.0)))
            for v in self.flat.inputs])

    def _states(self) -> list[Variable]:
        outputs = {v.name for v in self.flat.outputs}
        return self._placed("STATE", [
            _real(v.name, "output" if v.name in outputs else "local", "continuous", f"{v.description} [{v.unit}]",
                  v.unit, initial="calculated", nominal=float(v.nominal), depends_on=(v.name,))
            for v in self.flat.states])

    def _derivatives(self) -> list[Variable]:
        return self._placed("DERIVATIVE", [
            _real(f"der({v.name})", "local", "continuous", f"d {v.name} / dt", _per_s(v.unit), initial="calculated",
                  derivative_of=v.name, depends_on=self._depends(k, "A", "B")) for k, v in enumerate(self.flat.states)])

    def _outputs(self) -> list[Variable]:
        """Every output but one named as a state or a parameter, which is that variable (``y_vars`` None)."""
        flat = self.flat
        taken = {v.name for v in flat.states} | {v.name for v in flat.parameters}
        self.y_vars: list[str | None] = [None if v.name in taken else v.name for v in flat.outputs]
        rows = []
        for k, v in enumerate(flat.outputs):
            if self.y_vars[k] is not None:
                rows.append(_real(v.name, "output", "continuous", f"{v.description} [{v.unit}]", v.unit,
                                  initial="calculated", depends_on=self._depends(k, "C", "D")))
                self.places[v.name] = ("OUTPUT", k)
        return rows

    def c_lines(self) -> list[str]:
        """What ``pam_gcore.c`` needs beyond the variable table: the model's vectors in ``r[]``, the mode's
        place in ``i[]``, and each variable's place in the exact Jacobians."""
        flat = self.flat
        c = {v.name: v.c_name for v in self.variables}
        idx = lambda names: ", ".join(f"R_{c[n]}" for n in names) or "0"  # noqa: E731
        out = ["", "/* The generated model's vectors in r[] (pamsim.fmu.assembly_fmu). */", *self._parameter_lines(idx),
               f"static const int PAM_U_R[{max(1, len(flat.inputs))}] = {{{idx([v.name for v in flat.inputs])}}};",
               f"static const int PAM_Y_R[{max(1, len(flat.outputs))}] = {{"
               + (", ".join(f"R_{c[n]}" if n else "-1" for n in self.y_vars) or "0") + "};",
               f"#define PAM_I_MODE {'I_' + c[self.mode] if self.mode else -1}",
               "enum { " + ", ".join(f"PAM_DD_{k} = {i}" for i, k in enumerate(DD_KINDS)) + " };"]
        return out + self._jacobian_places()

    def _parameter_lines(self, idx) -> list[str]:
        """Where the model's parameters are in r[] (``idx``: names to a list of r[] indices)."""
        flat = self.flat
        return [f"static const int PAM_P_R[{max(1, len(flat.parameters))}] = {{{idx([v.name for v in flat.parameters])}}};"]

    def _jacobian_places(self) -> list[str]:
        """``PAM_DD_KIND`` and ``PAM_DD_INDEX``, by value reference: each variable's place in the Jacobians."""
        n = max(self.value_references.values())
        kinds, index = ["PAM_DD_NONE"] * n, ["0"] * n
        for name, (kind, k) in self.places.items():
            kinds[self.value_references[name] - 1] = f"PAM_DD_{kind}"
            index[self.value_references[name] - 1] = str(k)
        return [f"static const int PAM_DD_KIND[PAM_NVARS] = {{{', '.join(kinds)}}};",
                f"static const int PAM_DD_INDEX[PAM_NVARS] = {{{', '.join(index)}}};"]


def _per_s(unit: str) -> str:
    return {"m": "m/s", "m/s": "m/s^2", "1": "1/s"}.get(unit, f"{unit}/s")


def assembly_spec(scenario, fmi_version: int = 2, model=None) -> FmuSpec:
    """The :class:`~pamsim.fmu.spec.FmuSpec` of the FMU of ``scenario``'s assembly: its components'
    parameters at the scenario's values, its inputs following the scenario's signals, its run as the
    ``DefaultExperiment``.

    ``model`` is the scenario's model with its pressure source replaced: for a scenario with a
    ``[controller]``, the model with the controller (:func:`pamsim.control.closed_loop.design_closed_loop`),
    which the FMU then contains, its inputs the controller's reference and feedforward signals.

    Raises
    ------
    InputError
        For a scenario with a controller but no ``model`` (the FMU would run it open loop), or whose
        model has no C (a static force computed by Python alone), or whose signals the FMU cannot carry.
    """
    from ..assemblies.one_muscle import scenario_assembly

    if "controller" in scenario.spec and model is None:
        raise InputError(f"{scenario.origin}: controller: without the controller's model the FMU would run this "
                         "scenario open loop; build it with pamsim fmu build --scenario, which designs the "
                         "controller and puts it in the FMU")
    assembly = scenario_assembly(scenario, model)
    try:
        cmodel, model_c = _generated(assembly)
    except NotImplementedError as exc:
        raise InputError(f"{scenario.origin}: the FMU of this assembly needs C for every component: {exc}") from None
    names = [v.name for v in cmodel.full.inputs]
    signals = scenario_signals(scenario, names, model)
    table = AssemblyVariables(cmodel, assembly.parameter_values(), {n: s(0.0) for n, s in signals.items()})
    variables = tuple(replace(v, start=INPUT_SOURCE_CHOICES.index("scenario")) if v.name == "input_source" else v
                      for v in table.variables)
    opts = scenario.solver
    experiment = Experiment(scenario.duration_s, 1.0 / opts.sample_rate_Hz, opts.rtol)
    where = f"scenario {scenario.name} ({scenario.origin})"
    description = (f"{cmodel.full.name} assembly of components ({', '.join(c.name for c in assembly.components)}) "
                   f"generated by pamsim from {where}; every equation from the components' description")
    spec = FmuSpec(variables, table.value_references, tuple(v.name for v in cmodel.full.states), table.indicators,
                   tuple(names), "pamsim_assembly", "pamsim_assembly", "structured", description, SOURCES,
                   {"pam_model.c": model_c, "pam_fmu_core.h": CORE_HEADER}, tuple(table.c_lines()), signals,
                   experiment, fmi_version=fmi_version, usage=_usage(table, where), included=("pam_engine.c",))
    return replace(spec, token=_token(spec))


_GENERATED: "OrderedDict[tuple, tuple]" = OrderedDict()
GENERATED_KEPT = 16
"""Generated C models kept per process, by structure: runs of one scenario, or of a sweep over its
values, generate their C once (about 0.2 s) and only recompute the token."""


def _generated(assembly):
    """The :class:`~pamsim.modeling.cmodel.CModel` of ``assembly`` with exact Jacobians and its
    ``pam_model.c``, shared by assemblies of one structure: the code depends on nothing else (the
    parameter values are the FMU's start values, written apart from it)."""
    from ..modeling.cmodel import CModel

    key = assembly.structure_key()
    if key in _GENERATED:
        _GENERATED.move_to_end(key)
        return _GENERATED[key]
    cmodel = CModel(assembly, jacobians=True)
    _GENERATED[key] = cmodel, cmodel.sources()["pam_model.c"]
    while len(_GENERATED) > GENERATED_KEPT:
        _GENERATED.popitem(last=False)
    return _GENERATED[key]


def _usage(table: AssemblyVariables, where: str) -> tuple[tuple[str, str], ...]:
    return (
        ("What it is", f"An assembly of pamsim components built from {where}: every equation, derivative, event "
         "indicator and output generated from the components' one description; Model Exchange and Co-Simulation."),
        ("Driving it", "The parameters start at the scenario's values; the inputs follow the scenario's signals "
         "(input_source = scenario), exactly within each step; set input_source = importer to drive them."),
        ("Co-Simulation", "The FMU integrates with its own Dormand-Prince 5(4) solver (cs_relative_tolerance, "
         "cs_max_step_s) and locates every event inside each step."),
        ("Model Exchange", f"The importer integrates the {len(table.flat.states)} states; the "
         f"{len(table.indicators)} event indicators change sign at the events, handled at the event update."),
    )


def _token(spec: FmuSpec) -> str:
    """A hash of everything the FMU's binary is built from: hand-written and generated sources, variables."""
    h = hashlib.sha256()
    src = c_source_dir() / "src"
    for name in spec.sources + (WRAPPERS[spec.fmi_version],):
        h.update((src / name).read_bytes())
    for name, text in sorted(spec.generated.items()):
        h.update(name.encode() + b"\0" + text.encode())
    h.update("\n".join(repr(v) for v in spec.variables).encode())
    h.update("\n".join(spec.c_extra).encode())
    h.update(repr(sorted(spec.signals.items())).encode())
    h.update(f"{spec.fmi_version} {__version__} {spec.experiment!r}".encode())
    return "{" + str(uuid.UUID(bytes=h.digest()[:16])) + "}"


def build_assembly(scenario, output_path: str | os.PathLike | None = None, fmi_version: int = 2,
                   model=None) -> Path:
    """Generate, compile and zip the FMU of ``scenario``'s assembly of components
    (:mod:`pamsim.fmu.assembly_fmu`): namespaced variables, every equation generated; return its path
    (default ``pamsim_assembly_fmi<version>.fmu``).  ``model``: as :func:`assembly_spec` takes it.

    Raises :class:`~pamsim.errors.InputError` for an unknown FMI version, a scenario the FMU cannot
    carry, a missing C compiler or a failed compilation.
    """
    if fmi_version not in FMI_VERSIONS:
        raise InputError(f"FMI version must be 2 or 3, not {fmi_version!r}")
    spec = assembly_spec(scenario, fmi_version, model)
    return build_spec(Path(output_path) if output_path else Path(f"{spec.identifier}_fmi{fmi_version}.fmu"), spec)
