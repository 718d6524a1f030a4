"""Generate ``modelDescription.xml`` (FMI 2.0 and 3.0), ``buildDescription.xml``
and the C header ``pam_variables.h`` from :data:`pamsim.fmu.variables.VARIABLES`.

The GUID / instantiation token is a hash of the C sources, the variable table
and the FMI version, so two builds of the same code are interchangeable and
any change gives a new token.
"""

from __future__ import annotations

import datetime
import html
import math
import os
import subprocess
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .. import __version__
from ..references import REFERENCES
from .units import base_unit
from .spec import FmuSpec
from .variables import INPUT_SOURCE_CHOICES, VARIABLES

MODEL_NAME = "pamsim_muscle"
MODEL_IDENTIFIER = "pamsim_muscle"
C_DIR = Path(__file__).resolve().parents[2] / "fmu"  # the source tree; an installed wheel has pamsim.fmu.csrc
WRAPPERS = {2: "fmi2_wrapper.c", 3: "fmi3_wrapper.c"}
HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
           3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
DESCRIPTION = ("McKibben muscle lifting a hanging load (ACRA 2012 model, pamsim): static force polynomial, "
               "load-dependent Coulomb friction with stick/slip, damping, ISO 6358 valve and chamber, end stops")
"""The model description's ``description`` of an FMU without a force table (:func:`description`)."""


def description(table=None, preset=None) -> str:
    """What the FMU is: the exact polynomial (:data:`DESCRIPTION`) or, for a table FMU, which static model
    it tabulates, from what and over which domain; and what it was built for."""
    if table is None:
        text = DESCRIPTION
    else:
        from ..static_models import REGISTRY

        spec = REGISTRY.get(table.model_name)
        what = f"{table.model_name} ({spec.summary}; {spec.source})" if spec else table.model_name
        nx, n_p = table.shape
        text = ("McKibben muscle lifting a hanging load (pamsim): static force " + what + ", tabulated at build "
                f"time as a {nx} x {n_p} bicubic spline table over contraction {table.x_min_m * 1e3:g} to "
                f"{table.x_max_m * 1e3:g} mm and gauge pressure {table.p_min_Pa:g} to {table.p_max_Pa:g} Pa "
                "(never extrapolated), load-dependent Coulomb friction with stick/slip, damping, ISO 6358 valve "
                "and chamber, end stops")
    return text + (f"; built for {preset.built_for}" if preset is not None else "")


AUTHOR = "pamsim developers"
LICENSE = "MIT (pamsim); the FMI headers in sources/ are under their own licence (FMI_HEADERS_LICENSE.txt)"
DEFAULT_STEP_S = 1e-3
"""DefaultExperiment stepSize: the communication step of the tests and the docs' examples."""


def generation_date() -> str | None:
    """``generationDateAndTime``, reproducible: from the sources, never from the clock.

    ``SOURCE_DATE_EPOCH`` if set (the reproducible-builds convention), else the commit time of the
    newest commit that touched the FMU's sources or generator in a git checkout, else ``None``
    (the attribute is left out, as from an installed wheel outside git).
    """
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    if epoch is None:
        here = Path(__file__).resolve().parent
        try:
            proc = subprocess.run(["git", "log", "-1", "--format=%ct", "--", str(c_source_dir()), str(here)],
                                  cwd=here, capture_output=True, text=True, timeout=30)
            epoch = proc.stdout.strip() if proc.returncode == 0 else ""
        except (OSError, subprocess.SubprocessError):
            epoch = ""
    if not epoch:
        return None
    stamp = datetime.datetime.fromtimestamp(int(epoch), datetime.timezone.utc)
    return stamp.strftime("%Y-%m-%dT%H:%M:%SZ")


def c_source_dir() -> Path:
    """The folder holding ``src/`` and ``include/`` of the C model."""
    if (C_DIR / "src" / "pam_gcore.c").is_file():
        return C_DIR
    installed = Path(__file__).resolve().with_name("csrc")  # where the wheel puts fmu/ (pyproject.toml)
    if (installed / "src" / "pam_gcore.c").is_file():
        return installed
    from ..errors import InputError

    raise InputError(f"the FMU's C sources are neither at {C_DIR / 'src'} nor in the installed package")


def _num(x) -> str:
    return repr(float(x)) if isinstance(x, float) else str(x)


def _unit_definitions(variables) -> list[str]:
    """``<UnitDefinitions>`` with each unit's SI ``<BaseUnit>`` (the same element in FMI 2.0 and 3.0)."""
    lines = ["  <UnitDefinitions>"]
    for u in sorted({v.unit for v in variables if v.unit}):
        factor, exponents = base_unit(u)
        base = _attrs(**exponents, factor=repr(factor) if factor != 1.0 else None)
        lines.append(f"    <Unit{_attrs(name=u)}>\n      <BaseUnit{base}/>\n    </Unit>")
    return lines + ["  </UnitDefinitions>"]


def enumeration_type(v) -> str:
    """The declared type of an integer choice: ``friction_model`` -> ``FrictionModel``."""
    return "".join(part.capitalize() for part in v.name.split("_"))


def _type_definitions(fmi_version: int, variables) -> list[str]:
    lines = ["  <TypeDefinitions>"]
    for v in variables:
        if not v.choices:
            continue
        items = [f'      <Item{_attrs(name=c, value=i)}/>' for i, c in enumerate(v.choices)]
        if fmi_version == 2:
            lines += [f"    <SimpleType{_attrs(name=enumeration_type(v))}>", "    <Enumeration>"]
            lines += items + ["    </Enumeration>", "    </SimpleType>"]
        else:
            lines += [f"    <EnumerationType{_attrs(name=enumeration_type(v))}>"] + items + ["    </EnumerationType>"]
    return lines + ["  </TypeDefinitions>"]


LOG_CATEGORIES = (("logStatusOK", "informative messages (only with debug logging on)"),
                  ("logStatusWarning", "warnings"),
                  ("logStatusError", "errors: refused values and calls, failed steps, invalid parameters"))
"""The categories the C code logs under (fmi_shell.c, level_category)."""


def _common_elements(run=None) -> list[str]:
    """Log categories and the DefaultExperiment: a scenario's run, else the paper's 8 s tests."""
    stop, tolerance, step = (run.stop_time_s, run.tolerance, run.step_size_s) if run else (8.0, 1e-6, DEFAULT_STEP_S)
    lines = ["  <LogCategories>"]
    lines += [f"    <Category{_attrs(name=n, description=d)}/>" for n, d in LOG_CATEGORIES]
    run_attrs = _attrs(startTime=0.0, stopTime=float(stop), tolerance=float(tolerance), stepSize=float(step))
    lines += ["  </LogCategories>", f"  <DefaultExperiment{run_attrs}/>"]
    return lines


def _limits(v) -> dict[str, str]:
    """``min``/``max`` from the range the C check enforces; an excluded bound becomes the nearest
    included double (XML bounds are inclusive)."""
    out = {}
    if math.isfinite(v.lower):
        out["min"] = v.lower if not v.lower_open else math.nextafter(v.lower, math.inf)
    if math.isfinite(v.upper):
        out["max"] = v.upper if not v.upper_open else math.nextafter(v.upper, -math.inf)
    if v.kind == "integer":
        return {k: str(int(x)) for k, x in out.items()}
    return {k: repr(float(x)) for k, x in out.items()}


def _dependencies(names, key) -> dict[str, str]:
    """The ``dependencies`` attribute over ``names`` (FMI 2.0 ``index`` numbers or FMI 3.0 value
    references via ``key``), or nothing where the table leaves them undeclared (``None``)."""
    if names is None:
        return {}
    return {"dependencies": " ".join(str(key(n)) for n in sorted(names, key=key))}


def _header(spec: FmuSpec) -> str:
    fmi_version = spec.fmi_version
    token_attr = "guid" if fmi_version == 2 else "instantiationToken"
    attrs = _attrs(modelName=spec.model_name, **{token_attr: spec.token},
                   description=spec.description,
                   author=AUTHOR,
                   version=__version__, license=LICENSE, generationTool="pamsim.fmu",
                   generationDateAndTime=generation_date(), variableNamingConvention=spec.naming)
    extra = f' numberOfEventIndicators="{len(spec.event_indicators)}"' if fmi_version == 2 else ""
    return f'<fmiModelDescription fmiVersion="{fmi_version}.0"{attrs}{extra}>'


def spec_model_description(spec: FmuSpec) -> str:
    """``modelDescription.xml`` of the FMU ``spec`` describes."""
    return _fmi2(spec) if spec.fmi_version == 2 else _fmi3(spec)


def _attrs(**kw) -> str:
    return "".join(f" {k}={quoteattr(str(v))}" for k, v in kw.items() if v is not None)


def _document(spec: FmuSpec, interfaces: list[str], model_variables: list[str], structure: list[str]) -> str:
    """A ``modelDescription.xml``: the parts FMI 2.0 and 3.0 write alike (header, units, types, log categories,
    experiment) around the ``interfaces`` (Model Exchange, Co-Simulation), the variables' elements and the
    model structure's, which each standard writes its own way."""
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', _header(spec), *interfaces]
    lines += (_unit_definitions(spec.variables) + _type_definitions(spec.fmi_version, spec.variables)
              + _common_elements(spec.experiment))
    lines += ['  <ModelVariables>', *model_variables, '  </ModelVariables>']
    lines += ['  <ModelStructure>', *structure, '  </ModelStructure>', '</fmiModelDescription>', '']
    return "\n".join(lines)


def _variable_attrs(spec: FmuSpec, v) -> str:
    """The attributes a variable has in both standards: name, value reference, description, causality,
    variability and initial."""
    return _attrs(name=v.name, valueReference=spec.vr(v.name), description=v.description,
                  causality=v.causality, variability=v.variability, initial=v.initial)


def _start(v) -> str | None:
    """The ``start`` attribute's text, or None (left out) for a variable without one."""
    return _num(v.start) if v.start is not None else None


def _unknowns(spec: FmuSpec, key) -> tuple[list, list, list]:
    """The model structure's unknowns: the outputs and the state derivatives in table order, and the initial
    unknowns (outputs, derivatives and states, each once) ordered by ``key`` of their name."""
    outputs = [v for v in spec.variables if v.causality == "output"]
    derivs = [v for v in spec.variables if v.derivative_of]
    states = [spec.by_name[s] for s in spec.states]
    initial = sorted({v.name: v for v in outputs + derivs + states}.values(), key=lambda v: key(v.name))
    return outputs, derivs, initial


def _fmi2(spec: FmuSpec) -> str:
    index = {v.name: i for i, v in enumerate(spec.variables, start=1)}  # FMI 2.0 refers to variables by position
    return _document(spec, _fmi2_interfaces(spec), [_fmi2_variable(spec, v, index) for v in spec.variables],
                     _fmi2_structure(spec, index))


def _fmi2_interfaces(spec: FmuSpec) -> list[str]:
    """``<ModelExchange>`` and ``<CoSimulation>`` of FMI 2.0, each listing the C files to compile."""
    src_files = "".join(f'\n      <File name="{n}"/>' for n in spec.compiled() + (WRAPPERS[2],))
    return [f'  <ModelExchange modelIdentifier="{spec.identifier}" canGetAndSetFMUstate="true"'
            ' canSerializeFMUstate="true" providesDirectionalDerivative="true"'
            ' canNotUseMemoryManagementFunctions="true">',
            f'    <SourceFiles>{src_files}\n    </SourceFiles>', '  </ModelExchange>',
            f'  <CoSimulation modelIdentifier="{spec.identifier}" canHandleVariableCommunicationStepSize="true"'
            ' canGetAndSetFMUstate="true" canSerializeFMUstate="true" providesDirectionalDerivative="true"'
            ' canNotUseMemoryManagementFunctions="true">',
            f'    <SourceFiles>{src_files}\n    </SourceFiles>', '  </CoSimulation>']


def _fmi2_variable(spec: FmuSpec, v, index: dict[str, int]) -> str:
    """A ``<ScalarVariable>`` with its type element inside; a derivative names its state by ``index``."""
    start = _start(v)
    if v.choices:
        inner = f"<Enumeration{_attrs(declaredType=enumeration_type(v), **_limits(v), start=start)}/>"
    elif v.kind == "real":
        inner = (f'<Real{_attrs(unit=v.unit, **_limits(v), start=start, nominal=v.nominal)}'
                 f'{_attrs(derivative=index[v.derivative_of] if v.derivative_of else None)}/>')
    else:
        inner = f'<Integer{_attrs(**_limits(v), start=start)}/>'
    return f'    <ScalarVariable{_variable_attrs(spec, v)}>\n      {inner}\n    </ScalarVariable>'


def _fmi2_structure(spec: FmuSpec, index: dict[str, int]) -> list[str]:
    """``<Outputs>``, ``<Derivatives>`` and ``<InitialUnknowns>``, each unknown and its dependencies by index."""
    outputs, derivs, initial = _unknowns(spec, index.__getitem__)

    def unknowns(variables, depends) -> list[str]:
        return [f'      <Unknown index="{index[v.name]}"{_attrs(**_dependencies(depends(v), index.get))}/>'
                for v in variables]

    return (['    <Outputs>', *unknowns(outputs, lambda v: v.depends_on), '    </Outputs>',
             '    <Derivatives>', *unknowns(derivs, lambda v: v.depends_on), '    </Derivatives>',
             '    <InitialUnknowns>', *unknowns(initial, lambda v: v.initial_depends_on), '    </InitialUnknowns>'])


_FMI3_TIME = ('    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"'
              ' description="simulation time [s]" unit="s"/>')
"""FMI 3.0's independent variable, which FMI 2.0 leaves implicit."""


def _fmi3(spec: FmuSpec) -> str:
    return _document(spec, _fmi3_interfaces(spec), [_FMI3_TIME] + [_fmi3_variable(spec, v) for v in spec.variables],
                     _fmi3_structure(spec))


def _fmi3_interfaces(spec: FmuSpec) -> list[str]:
    """``<ModelExchange>`` and ``<CoSimulation>`` of FMI 3.0."""
    return [f'  <ModelExchange modelIdentifier="{spec.identifier}" needsCompletedIntegratorStep="true"'
            ' canGetAndSetFMUState="true" canSerializeFMUState="true" providesDirectionalDerivatives="true"/>',
            f'  <CoSimulation modelIdentifier="{spec.identifier}" canHandleVariableCommunicationStepSize="true"'
            ' canGetAndSetFMUState="true" canSerializeFMUState="true" providesDirectionalDerivatives="true"/>']


def _fmi3_variable(spec: FmuSpec, v) -> str:
    """The variable's element, named by its type; a derivative names its state by value reference."""
    head, start = _variable_attrs(spec, v), _start(v)
    if v.choices:
        return f"    <Enumeration{head}{_attrs(declaredType=enumeration_type(v), **_limits(v), start=start)}/>"
    if v.kind == "real":
        tail = _attrs(unit=v.unit, **_limits(v), start=start,
                      derivative=spec.vr(v.derivative_of) if v.derivative_of else None, nominal=v.nominal)
        return f'    <Float64{head}{tail}/>'
    return f'    <Int32{head}{_attrs(**_limits(v), start=start)}/>'


def _fmi3_structure(spec: FmuSpec) -> list[str]:
    """The unknowns of FMI 3.0, each its own element naming its value reference and dependencies: outputs, state
    derivatives, initial unknowns and event indicators."""
    outputs, derivs, initial = _unknowns(spec, spec.vr)

    def unknown(tag: str, name: str, depends) -> str:
        return f'    <{tag} valueReference="{spec.vr(name)}"{_attrs(**_dependencies(depends, spec.vr))}/>'

    return ([unknown("Output", v.name, v.depends_on) for v in outputs]
            + [unknown("ContinuousStateDerivative", v.name, v.depends_on) for v in derivs]
            + [unknown("InitialUnknown", v.name, v.initial_depends_on) for v in initial]
            + [unknown("EventIndicator", n, spec.by_name[n].depends_on) for n in spec.event_indicators])


def build_description(spec: FmuSpec) -> str:
    """The FMU's ``buildDescription.xml``: its C sources and include folders, for importers that compile it."""
    files = "".join(f'\n      <SourceFile name="{n}"/>' for n in spec.compiled() + (WRAPPERS[spec.fmi_version],))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{spec.identifier}">\n'
            f'    <SourceFileSet language="C99">{files}\n    </SourceFileSet>\n'
            '  </BuildConfiguration>\n</fmiBuildDescription>\n')


def _c_bound(x: float) -> str:
    """A bound as a C constant expression: ``HUGE_VAL`` (math.h) for an infinite one."""
    if math.isinf(x):
        return "HUGE_VAL" if x > 0 else "-HUGE_VAL"
    return repr(float(x))


def spec_c_header(spec: FmuSpec) -> str:
    """``pam_variables.h``: indices into the value arrays, value references, start values, the token, and
    the input signals of the scenario the FMU is built for, if any."""
    variables = spec.variables
    reals = [v for v in variables if v.kind == "real"]
    ints = [v for v in variables if v.kind == "integer"]
    out = ["/* Generated by pamsim.fmu.generate. Do not edit. */",
           "#ifndef PAM_VARIABLES_H", "#define PAM_VARIABLES_H", "", "#include <math.h>", "",
           f'#define PAM_TOKEN "{spec.token}"', f"#define PAM_NR {len(reals)}",
           f"#define PAM_NI {len(ints)}",
           f"#define PAM_NVARS {max(spec.vr(v.name) for v in variables)}", f"#define PAM_NX {len(spec.states)}",
           f"#define PAM_NZ {len(spec.event_indicators)}", ""]
    out += [f"#define R_{v.c_name} {i}" for i, v in enumerate(reals)]
    out += [f"#define I_{v.c_name} {i}" for i, v in enumerate(ints)]
    out += [f"#define VR_{v.c_name} {spec.vr(v.name)}u" for v in variables]
    out += _c_variable_table(spec) + _c_state_vectors(spec) + _c_signals(spec)
    return "\n".join(out + list(spec.c_extra) + ["", "#endif", ""])


_C_CAUSALITY = {"parameter": "PAM_PARAMETER", "input": "PAM_INPUT", "output": "PAM_OUTPUT", "local": "PAM_LOCAL"}


def _c_variable_table(spec: FmuSpec) -> list[str]:
    """``PAM_VARS``: each variable's name, kind, index, causality, start and range, by value reference."""
    out = ["", "typedef enum { PAM_PARAMETER, PAM_INPUT, PAM_OUTPUT, PAM_LOCAL } PamCausality;",
           "/* kind: 'r' real, 'i' integer, 'e' enumeration (in i[]), 0 an unused value reference.",
           " * lower/upper: the range a parameter or input must lie in (-/+HUGE_VAL: none); *_open: the bound",
           " * is excluded. */",
           "typedef struct {",
           "    const char *name; char kind; int index; PamCausality causality; double start;",
           "    double lower, upper; int lower_open, upper_open;",
           "} PamVarInfo;",
           "", "/* Indexed by value reference - 1 (the numbers are pinned, so there may be gaps). */",
           "static const PamVarInfo PAM_VARS[PAM_NVARS] = {"]
    slots = ['    {"", 0, 0, PAM_LOCAL, 0.0, -HUGE_VAL, HUGE_VAL, 0, 0},'] * max(spec.vr(v.name) for v in spec.variables)
    index = {"real": 0, "integer": 0}
    for v in spec.variables:
        # an Enumeration ('e') is an Integer in FMI 2.0 but an Int64 in FMI 3.0
        kind = "'r'" if v.kind == "real" else "'e'" if v.choices else "'i'"
        idx, index[v.kind] = index[v.kind], index[v.kind] + 1
        start = repr(float(v.start)) if v.start is not None else "0.0"
        slots[spec.vr(v.name) - 1] = (
            f'    {{"{v.name}", {kind}, {idx}, {_C_CAUSALITY[v.causality]}, {start}, {_c_bound(v.lower)}, '
            f'{_c_bound(v.upper)}, {int(v.lower_open)}, {int(v.upper_open)}}},')
    return out + slots + ["};"]


def _c_state_vectors(spec: FmuSpec) -> list[str]:
    """The continuous states, their derivatives and nominals, and the event indicators (indices into r[])."""
    by_name = spec.by_name
    derivative = {v.derivative_of: v for v in spec.variables if v.derivative_of}
    return ["", "/* Continuous states and their derivatives, in state-vector order (indices into r[]). */",
            "static const int PAM_STATE_R[PAM_NX] = {" + ", ".join(f"R_{by_name[s].c_name}" for s in spec.states) + "};",
            "static const int PAM_DERIV_R[PAM_NX] = {"
            + ", ".join(f"R_{derivative[s].c_name}" for s in spec.states) + "};",
            "static const double PAM_NOMINAL[PAM_NX] = {"
            + ", ".join(repr(float(by_name[s].nominal)) for s in spec.states) + "};",
            "static const int PAM_INDICATOR_R[" + str(max(1, len(spec.event_indicators))) + "] = {"
            + (", ".join(f"R_{by_name[n].c_name}" for n in spec.event_indicators) or "0") + "};", ""]


def _c_signals(spec: FmuSpec) -> list[str]:
    """The input signals (:class:`pamsim.fmu.preset.InputSignal`) for the C core, in the order of the inputs."""
    signals, by_name = spec.signals, spec.by_name
    out = ["/* input_source (pamsim.fmu.variables.INPUT_SOURCE_CHOICES) */",
           "enum { " + ", ".join(f"PAM_INPUT_SOURCE_{c.upper()} = {i}" for i, c in enumerate(INPUT_SOURCE_CHOICES))
           + " };",
           "/* An input's signal (pamsim.fmu.preset.InputSignal): n knots (t_s, value), or with n = 0 a step from",
           " * initial to final at time_s through a first-order lag tau_s.  r: the input's index in r[]. */",
           "typedef struct {", "    int r; unsigned vr; int n; const double *t_s, *value;",
           "    double time_s, initial, final, tau_s;", "} PamSignal;",
           "/* The signals of the scenario this FMU was built for (none: PAM_NSIG 0). */",
           f"#define PAM_NSIG {len(signals)}"]
    rows = []
    for k, name in enumerate(n for n in spec.inputs if n in signals):
        sig, c = signals[name], by_name[name].c_name
        if sig.lag is not None:
            rows.append(f"    {{R_{c}, VR_{c}, 0, 0, 0, " + ", ".join(repr(float(x)) for x in sig.lag) + "},")
            continue
        out.append(f"static const double PAM_SIG{k}_T[{len(sig.knots_t_s)}] = {{"
                   + ", ".join(repr(float(t)) for t in sig.knots_t_s) + "};")
        out.append(f"static const double PAM_SIG{k}_V[{len(sig.knots)}] = {{"
                   + ", ".join(repr(float(x)) for x in sig.knots) + "};")
        rows.append(f"    {{R_{c}, VR_{c}, {len(sig.knots)}, PAM_SIG{k}_T, PAM_SIG{k}_V, 0.0, 0.0, 0.0, 0.0}},")
    rows = rows or ["    {0, 0u, 0, 0, 0, 0.0, 0.0, 0.0, 0.0},"]
    size = str(len(signals)) if signals else "1"
    return out + [f"static const PamSignal PAM_SIGNALS[{size}] = {{"] + rows + ["};"]


def write_spec_sources(dest: Path, spec: FmuSpec) -> list[str]:
    """Write the sources an FMU ships (C files, generated headers, FMI headers, licence) into ``dest``."""
    dest.mkdir(parents=True, exist_ok=True)
    root = c_source_dir()
    names = []
    fmi_version = spec.fmi_version
    for name in spec.sources + (WRAPPERS[fmi_version],):
        (dest / name).write_bytes((root / "src" / name).read_bytes())
        names.append(name)
    for name in HEADERS[fmi_version]:
        (dest / name).write_bytes((root / "include" / f"fmi{fmi_version}" / name).read_bytes())
        names.append(name)
    (dest / "FMI_HEADERS_LICENSE.txt").write_bytes((root / "include" / "LICENSE.txt").read_bytes())
    (dest / "pam_variables.h").write_text(spec_c_header(spec))
    for name, text in spec.generated.items():
        (dest / name).write_text(text)
    (dest / "buildDescription.xml").write_text(build_description(spec))
    return names + ["pam_variables.h", *spec.generated, "buildDescription.xml"]


def range_text(v) -> str:
    """A variable's range as the docs show it: ``(0, 1)``, ``> 0``, ``<= 1``, or empty."""
    lo, hi = math.isfinite(v.lower), math.isfinite(v.upper)
    if lo and hi:
        return f"{'(' if v.lower_open else '['}{v.lower:g}, {v.upper:g}{')' if v.upper_open else ']'}"
    if lo:
        return f"{'>' if v.lower_open else '>='} {v.lower:g}"
    if hi:
        return f"{'<' if v.upper_open else '<='} {v.upper:g}"
    return ""


def markdown_table() -> str:
    """The variable table for ``docs/fmu.md`` (a test checks the docs carry this exact text)."""
    rows = ["| name | causality | type | unit | start | range | description |", "|---|---|---|---|---|---|---|"]
    for v in VARIABLES:
        kind = "Real / Float64" if v.kind == "real" else "Enumeration" if v.choices else "Integer / Int32"
        start = "" if v.start is None else f"{v.start:g}" if isinstance(v.start, float) else str(v.start)
        desc = v.description.replace("|", "\\|")
        rows.append(f"| `{v.name}` | {v.causality} | {kind} | {v.unit or ''} | {start} | {range_text(v)} | {desc} |")
    return "\n".join(rows) + "\n"


USAGE = (
    ("What it is", DESCRIPTION + ". The same model as pamsim.simulate, compiled C with no Python inside; "
     "Model Exchange and Co-Simulation."),
    ("Driving it", "Set the parameters before the end of initialisation; the defaults are the Shadow 6 mm x 300 mm "
     f"muscle of {REFERENCES['acra2012'].short} ({REFERENCES['acra2012'].full()}) with a 22.74 N load. "
     "Drive valve_command (1 open to supply, 0 "
     "closed, -1 open to exhaust) and supply_pressure_gauge_Pa, or with pressure_source = prescribed, "
     "prescribed_pressure_gauge_Pa; set load_mass_kg and external_force_N; read contraction_m, p_gauge_Pa, "
     "F_static_N, F_friction_N and friction_mode."),
    ("Co-Simulation", "The FMU integrates with its own Dormand-Prince 5(4) solver (cs_relative_tolerance, "
     "cs_max_step_s) and locates the stick/slip and end-stop events inside each step; inputs are held over a "
     "step, and any step size works."),
    ("Model Exchange", "The importer integrates the four states; the two event indicators change sign at the "
     "stick/slip and end-stop events, handled at the event update."),
    ("Errors", "A refused value or call returns an error status and logs one message naming the variable and the "
     "limit (log categories logStatusError, logStatusWarning, logStatusOK)."),
)
"""The usage page in the FMU's documentation/index.html."""


def _usage(table, preset) -> tuple[tuple[str, str], ...]:
    """The usage page of the one-muscle FMU: :data:`USAGE` for what it was built with and for."""
    usage = (("What it is", description(table, preset) + USAGE[0][1][len(DESCRIPTION):]),) + USAGE[1:]
    if preset is not None:  # its start values are not the Shadow muscle's
        usage = usage[:1] + (("Driving it", f"Set the parameters before the end of initialisation; the defaults are "
                              f"the values of {preset.built_for}, each variable's description naming its source. "
                              + USAGE[1][1].split(" with a 22.74 N load. ", 1)[1]
                              + (" As built, the inputs follow the scenario's signals (input_source = scenario), "
                                 "exactly within each step; set input_source = importer to drive them."
                                 if preset.signals else "")),) + usage[2:]
    return usage


def spec_documentation_html(spec: FmuSpec) -> str:
    """``documentation/index.html``: a short usage page and the variable table."""
    rows = []
    for v in spec.variables:
        cells = (str(spec.vr(v.name)), v.name, v.causality, v.kind, v.unit or "",
                 "" if v.start is None else f"{v.start:g}" if isinstance(v.start, float) else str(v.start),
                 range_text(v), ", ".join(f"{i} = {c}" for i, c in enumerate(v.choices or ())), v.description)
        rows.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
    head = "".join(f"<th>{h}</th>" for h in ("value reference", "name", "causality", "type", "unit", "start",
                                              "range", "choices", "description"))
    sections = "".join(f"<h2>{html.escape(t)}</h2>\n<p>{html.escape(p)}</p>\n" for t, p in spec.usage)
    fmi_version = spec.fmi_version
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head><meta charset="utf-8"><title>{spec.model_name} (FMI '
            f'{fmi_version}.0)</title></head>\n<body>\n<h1>{spec.model_name}: pamsim {__version__}, FMI '
            f'{fmi_version}.0</h1>\n{sections}<h2>Variables</h2>\n<table>\n<tr>{head}</tr>\n' + "\n".join(rows)
            + "\n</table>\n</body>\n</html>\n")


def write_spec_documentation(dest: Path, spec: FmuSpec) -> None:
    """Write an FMU's ``documentation/`` folder into ``dest``."""
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "index.html").write_text(spec_documentation_html(spec))
