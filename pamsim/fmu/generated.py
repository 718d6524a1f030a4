"""What every FMU generated from components shares: the C it ships, its variables and where each sits
in the generated model's vectors, and its token.

An FMU generated from an assembly of components (:mod:`pamsim.fmu.assembly_fmu`) and the one-muscle
FMU (:mod:`pamsim.fmu.muscle_spec`) run the model :class:`pamsim.modeling.cmodel.CModel` generates on
the generic core (``fmu/src/pam_gcore.c``), which holds no physics.
"""

from __future__ import annotations

import hashlib
import uuid
from dataclasses import replace

from .. import __version__
from .generate import WRAPPERS, c_source_dir
from .spec import FmuSpec
from .variables import BY_NAME, Variable

SOURCES = ("pam_gcore.c", "pam_gcore.h", "pam_engine.c", "pam_engine.h", "pam_dopri.h", "pam_rosenbrock.h", "pam_gauss.h", "pam_log.h",
           "pam_fmu_common.c", "pam_fmu_common.h", "fmi_shell.c", "fmi_shell.h")
"""The hand-written C an assembly FMU ships: the generic core and engine, the FMI shell (``pam_gcore.c``
includes the engine, which includes the generated ``pam_model.c``: one translation unit)."""
CORE_HEADER = '#include "pam_gcore.h" /* the generic core: a generated model on the engine */\n'
OWN_PARAMETERS = ("cs_relative_tolerance", "cs_max_step_s", "cs_max_internal_steps", "input_source")
"""The FMU's own parameters, as the one-muscle FMU declares them."""
DD_KINDS = ("NONE", "STATE", "DERIVATIVE", "OUTPUT", "INPUT", "PARAMETER", "KNOB")
"""Where a variable sits in the exact Jacobians (``PAM_DD_KIND`` of ``pam_variables.h``); ``KNOB``: an FMU
parameter that the generated parameter map turns into the model's (:mod:`pamsim.fmu.muscle_fmu`)."""


def real_variable(name, causality, variability, description, unit, **kw) -> Variable:
    """A real FMU variable (:class:`pamsim.fmu.variables.Variable` of kind ``"real"``)."""
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
        rows += [real_variable(n, "local", "continuous", "event indicator: positive inside the current mode",
                       None, initial="calculated") for n in self.indicators]
        self.variables = tuple(rows)
        self.value_references = {v.name: k for k, v in enumerate(rows, start=1)}

    def _placed(self, kind: str, rows: list[Variable]) -> list[Variable]:
        """``rows``, each noted as entry k of the model's vector of ``kind`` (:data:`DD_KINDS`)."""
        for k, v in enumerate(rows):
            self.places[v.name] = (kind, k)
        return rows

    def _name(self, flat_name: str) -> str:
        """The FMU's name of the flat model's variable ``flat_name`` (its own; an FMU may give older ones)."""
        return flat_name

    def _depends(self, row: int, block_x: str, block_u: str) -> tuple[str, ...]:
        """The states and inputs row ``row`` of the Jacobian blocks ``block_x``, ``block_u`` depends on."""
        flat, sp = self.flat, self._sparsity
        return tuple([self._name(flat.states[i].name) for i in sp[block_x][row]]
                     + [self._name(flat.inputs[i].name) for i in sp[block_u][row]])

    def _parameters(self, values) -> list[Variable]:
        return self._placed("PARAMETER", [
            real_variable(v.name, "parameter", "fixed", f"{v.description} [{v.unit}]", v.unit, start=float(values[k]),
                  initial="exact", lower=v.lower, upper=v.upper, lower_open=v.lower_open, upper_open=v.upper_open)
            for k, v in enumerate(self.flat.parameters)])

    def _inputs(self, starts) -> list[Variable]:
        """The model inputs, with the ranges the one-muscle FMU declares for those it has."""
        return self._placed("INPUT", [
            replace(BY_NAME.get(v.name) or real_variable(v.name, "input", "continuous", "", v.unit),
                    description=f"{v.description or 'model input'} [{v.unit}]", start=float(starts.get(v.name, 0.0)))
            for v in self.flat.inputs])

    def _states(self) -> list[Variable]:
        outputs = {v.name for v in self.flat.outputs}
        return self._placed("STATE", [
            real_variable(self._name(v.name), "output" if v.name in outputs else "local", "continuous",
                          f"{v.description} [{v.unit}]", v.unit, initial="calculated", nominal=float(v.nominal),
                          depends_on=(self._name(v.name),))
            for v in self.flat.states])

    def _derivatives(self) -> list[Variable]:
        return self._placed("DERIVATIVE", [
            real_variable(f"der({self._name(v.name)})", "local", "continuous", f"d {v.name} / dt", per_s(v.unit),
                          initial="calculated", derivative_of=self._name(v.name), depends_on=self._depends(k, "A", "B"))
            for k, v in enumerate(self.flat.states)])

    def _outputs(self) -> list[Variable]:
        """Every output but one named as a state or a parameter, which is that variable (``y_vars`` None)."""
        flat = self.flat
        taken = {v.name for v in flat.states} | {v.name for v in flat.parameters}
        self.y_vars: list[str | None] = [None if v.name in taken else self._name(v.name) for v in flat.outputs]
        rows = []
        for k, v in enumerate(flat.outputs):
            if self.y_vars[k] is not None:
                rows.append(real_variable(self.y_vars[k], "output", "continuous", f"{v.description} [{v.unit}]", v.unit,
                                          initial="calculated", depends_on=self._depends(k, "C", "D")))
                self.places[self.y_vars[k]] = ("OUTPUT", k)
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


def per_s(unit: str) -> str:
    """The unit of a rate of a quantity in ``unit``."""
    if unit == "1":
        return "1/s"
    numerator, slash, denominator = unit.partition("/")
    if not slash:
        return f"{unit}/s"
    symbol, _, power = denominator.partition("^")
    if symbol == "s":
        return f"{numerator}/s^{int(power or 1) + 1}"
    return f"{numerator}/({denominator.strip('()')} s)"


def token(spec: FmuSpec) -> str:
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
