"""Generate ``modelDescription.xml`` (FMI 2.0 and 3.0), ``buildDescription.xml``
and the C header ``pam_variables.h`` from :data:`pamsim.fmu.variables.VARIABLES`.

The GUID / instantiation token is a hash of the C sources, the variable table
and the FMI version, so two builds of the same code are interchangeable and
any change gives a new token.
"""

from __future__ import annotations

import hashlib
import math
import uuid
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .variables import BY_NAME, EVENT_INDICATORS, STATES, VARIABLES, value_reference

MODEL_NAME = "pamsim_muscle"
MODEL_IDENTIFIER = "pamsim_muscle"
C_DIR = Path(__file__).resolve().parents[2] / "fmu"  # the source tree; an installed wheel has pamsim.fmu.csrc
CORE_SOURCES = ("pam_core.c", "pam_core.h", "fmi_shell.c", "fmi_shell.h")
WRAPPERS = {2: "fmi2_wrapper.c", 3: "fmi3_wrapper.c"}
HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
           3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
DESCRIPTION = ("McKibben muscle lifting a hanging load (ACRA 2012 model, pamsim): static force polynomial, "
               "load-dependent Coulomb friction with stick/slip, damping, ISO 6358 valve and chamber, end stops")


def compiled_sources(fmi_version: int) -> tuple[str, ...]:
    """The C files the FMU's binary is compiled from (as listed in the XML and by ``build``)."""
    return tuple(n for n in CORE_SOURCES if n.endswith(".c")) + (WRAPPERS[fmi_version],)


def c_source_dir() -> Path:
    """The folder holding ``src/`` and ``include/`` of the C model."""
    if (C_DIR / "src" / "pam_core.c").is_file():
        return C_DIR
    installed = Path(__file__).resolve().with_name("csrc")  # where the wheel puts fmu/ (pyproject.toml)
    if (installed / "src" / "pam_core.c").is_file():
        return installed
    from ..errors import InputError

    raise InputError(f"the FMU's C sources are neither at {C_DIR / 'src'} nor in the installed package")


def table_text() -> str:
    """A canonical text form of the variable table (hashed into the token)."""
    return "\n".join(repr(v) for v in VARIABLES)


def token(fmi_version: int) -> str:
    h = hashlib.sha256()
    src = c_source_dir() / "src"
    for name in CORE_SOURCES + (WRAPPERS[fmi_version],):
        h.update((src / name).read_bytes())
    h.update(table_text().encode())
    h.update(str(fmi_version).encode())
    return "{" + str(uuid.UUID(bytes=h.digest()[:16])) + "}"


def _num(x) -> str:
    return repr(float(x)) if isinstance(x, float) else str(x)


def _units() -> list[str]:
    return sorted({v.unit for v in VARIABLES if v.unit})


def model_description(fmi_version: int) -> str:
    if fmi_version == 2:
        return _fmi2()
    if fmi_version == 3:
        return _fmi3()
    raise ValueError(f"FMI version must be 2 or 3, not {fmi_version!r}")


def _attrs(**kw) -> str:
    return "".join(f" {k}={quoteattr(str(v))}" for k, v in kw.items() if v is not None)


def _fmi2() -> str:
    tok = token(2)
    src_files = "".join(f'\n      <File name="{n}"/>' for n in compiled_sources(2))
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<fmiModelDescription fmiVersion="2.0"{_attrs(modelName=MODEL_NAME, guid=tok, description=DESCRIPTION)}'
             ' generationTool="pamsim.fmu" variableNamingConvention="flat" numberOfEventIndicators="2">',
             f'  <ModelExchange modelIdentifier="{MODEL_IDENTIFIER}" canGetAndSetFMUstate="true"'
             ' canSerializeFMUstate="true" providesDirectionalDerivative="true"'
             ' canNotUseMemoryManagementFunctions="true">',
             f'    <SourceFiles>{src_files}\n    </SourceFiles>', '  </ModelExchange>',
             f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"'
             ' canGetAndSetFMUstate="true" canSerializeFMUstate="true" providesDirectionalDerivative="true"'
             ' canNotUseMemoryManagementFunctions="true">',
             f'    <SourceFiles>{src_files}\n    </SourceFiles>', '  </CoSimulation>',
             '  <UnitDefinitions>']
    lines += [f'    <Unit{_attrs(name=u)}/>' for u in _units()]
    lines += ['  </UnitDefinitions>', '  <DefaultExperiment startTime="0.0" stopTime="8.0" tolerance="1e-06"/>',
              '  <ModelVariables>']
    index = {}
    for i, v in enumerate(VARIABLES, start=1):
        index[v.name] = i
        head = _attrs(name=v.name, valueReference=value_reference(v.name), description=v.description,
                      causality=v.causality, variability=v.variability, initial=v.initial)
        if v.kind == "real":
            inner = _attrs(unit=v.unit, start=_num(v.start) if v.start is not None else None,
                           derivative=index[v.derivative_of] if v.derivative_of else None,
                           nominal=v.nominal)
            lines.append(f'    <ScalarVariable{head}>\n      <Real{inner}/>\n    </ScalarVariable>')
        else:
            inner = _attrs(start=v.start)
            lines.append(f'    <ScalarVariable{head}>\n      <Integer{inner}/>\n    </ScalarVariable>')
    lines.append('  </ModelVariables>')
    outputs = [index[v.name] for v in VARIABLES if v.causality == "output"]
    derivs = [index[v.name] for v in VARIABLES if v.derivative_of]
    initial = sorted(set(outputs + derivs + [index[s] for s in STATES]))
    lines += ['  <ModelStructure>', '    <Outputs>']
    lines += [f'      <Unknown index="{i}"/>' for i in outputs]
    lines += ['    </Outputs>', '    <Derivatives>']
    lines += [f'      <Unknown index="{i}"/>' for i in derivs]
    lines += ['    </Derivatives>', '    <InitialUnknowns>']
    lines += [f'      <Unknown index="{i}"/>' for i in initial]
    lines += ['    </InitialUnknowns>', '  </ModelStructure>', '</fmiModelDescription>', '']
    return "\n".join(lines)


def _fmi3() -> str:
    tok = token(3)
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<fmiModelDescription fmiVersion="3.0"'
             f'{_attrs(modelName=MODEL_NAME, instantiationToken=tok, description=DESCRIPTION)}'
             ' generationTool="pamsim.fmu" variableNamingConvention="flat">',
             f'  <ModelExchange modelIdentifier="{MODEL_IDENTIFIER}" canGetAndSetFMUState="true"'
             ' canSerializeFMUState="true" providesDirectionalDerivatives="true"/>',
             f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"'
             ' canGetAndSetFMUState="true" canSerializeFMUState="true" providesDirectionalDerivatives="true"/>',
             '  <UnitDefinitions>']
    lines += [f'    <Unit{_attrs(name=u)}/>' for u in _units()]
    lines += ['  </UnitDefinitions>', '  <DefaultExperiment startTime="0.0" stopTime="8.0" tolerance="1e-06"/>',
              '  <ModelVariables>',
              '    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"'
              ' description="simulation time [s]" unit="s"/>']
    for v in VARIABLES:
        vr = value_reference(v.name)
        head = _attrs(name=v.name, valueReference=vr, description=v.description, causality=v.causality,
                      variability=v.variability, initial=v.initial)
        if v.kind == "real":
            tail = _attrs(unit=v.unit, start=_num(v.start) if v.start is not None else None,
                          derivative=value_reference(v.derivative_of) if v.derivative_of else None,
                          nominal=v.nominal)
            lines.append(f'    <Float64{head}{tail}/>')
        else:
            lines.append(f'    <Int32{head}{_attrs(start=v.start)}/>')
    lines.append('  </ModelVariables>')
    outputs = [value_reference(v.name) for v in VARIABLES if v.causality == "output"]
    derivs = [value_reference(v.name) for v in VARIABLES if v.derivative_of]
    initial = sorted(set(outputs + derivs + [value_reference(s) for s in STATES]))
    lines.append('  <ModelStructure>')
    lines += [f'    <Output valueReference="{vr}"/>' for vr in outputs]
    lines += [f'    <ContinuousStateDerivative valueReference="{vr}"/>' for vr in derivs]
    lines += [f'    <InitialUnknown valueReference="{vr}"/>' for vr in initial]
    lines += [f'    <EventIndicator valueReference="{value_reference(n)}"/>' for n in EVENT_INDICATORS]
    lines += ['  </ModelStructure>', '</fmiModelDescription>', '']
    return "\n".join(lines)


def build_description(fmi_version: int) -> str:
    files = "".join(f'\n      <SourceFile name="{n}"/>' for n in compiled_sources(fmi_version))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{MODEL_IDENTIFIER}">\n'
            f'    <SourceFileSet language="C99">{files}\n    </SourceFileSet>\n'
            '  </BuildConfiguration>\n</fmiBuildDescription>\n')


def _c_bound(x: float) -> str:
    """A bound as a C constant expression: ``HUGE_VAL`` (math.h) for an infinite one."""
    if math.isinf(x):
        return "HUGE_VAL" if x > 0 else "-HUGE_VAL"
    return repr(float(x))


def c_header(fmi_version: int) -> str:
    """``pam_variables.h``: indices into the value arrays, value references, start values, the token."""
    reals = [v for v in VARIABLES if v.kind == "real"]
    ints = [v for v in VARIABLES if v.kind == "integer"]
    n_slots = max(value_reference(v.name) for v in VARIABLES)
    kinds = {"parameter": "PAM_PARAMETER", "input": "PAM_INPUT", "output": "PAM_OUTPUT", "local": "PAM_LOCAL"}
    out = ["/* Generated by pamsim.fmu.generate from pamsim/fmu/variables.py. Do not edit. */",
           "#ifndef PAM_VARIABLES_H", "#define PAM_VARIABLES_H", "", "#include <math.h>", "",
           f'#define PAM_TOKEN "{token(fmi_version)}"', f"#define PAM_NR {len(reals)}", f"#define PAM_NI {len(ints)}",
           f"#define PAM_NVARS {n_slots}", f"#define PAM_NX {len(STATES)}",
           f"#define PAM_NZ {len(EVENT_INDICATORS)}", ""]
    out += [f"#define R_{v.c_name} {i}" for i, v in enumerate(reals)]
    out += [f"#define I_{v.c_name} {i}" for i, v in enumerate(ints)]
    out += [f"#define VR_{v.c_name} {value_reference(v.name)}u" for v in VARIABLES]
    out += ["", "typedef enum { PAM_PARAMETER, PAM_INPUT, PAM_OUTPUT, PAM_LOCAL } PamCausality;",
            "/* kind: 'r' real, 'i' integer, 0 an unused value reference.  lower/upper: the range a parameter",
            " * or input must lie in (-/+HUGE_VAL: none); *_open: the bound is excluded. */",
            "typedef struct {",
            "    const char *name; char kind; int index; PamCausality causality; double start;",
            "    double lower, upper; int lower_open, upper_open;",
            "} PamVarInfo;",
            "", "/* Indexed by value reference - 1 (the numbers are pinned, so there may be gaps). */",
            "static const PamVarInfo PAM_VARS[PAM_NVARS] = {"]
    slots = ['    {"", 0, 0, PAM_LOCAL, 0.0, -HUGE_VAL, HUGE_VAL, 0, 0},'] * n_slots
    ri = ii = 0
    for v in VARIABLES:
        if v.kind == "real":
            kind, idx, ri = "'r'", ri, ri + 1
        else:
            kind, idx, ii = "'i'", ii, ii + 1
        start = repr(float(v.start)) if v.start is not None else "0.0"
        slots[value_reference(v.name) - 1] = (
            f'    {{"{v.name}", {kind}, {idx}, {kinds[v.causality]}, {start}, {_c_bound(v.lower)}, '
            f'{_c_bound(v.upper)}, {int(v.lower_open)}, {int(v.upper_open)}}},')
    out += slots
    out += ["};", "", "/* Continuous states and their derivatives, in state-vector order (indices into r[]). */",
            "static const int PAM_STATE_R[PAM_NX] = {" + ", ".join(f"R_{BY_NAME[s].c_name}" for s in STATES) + "};",
            "static const int PAM_DERIV_R[PAM_NX] = {"
            + ", ".join(f"R_{v.c_name}" for v in VARIABLES if v.derivative_of) + "};",
            "static const double PAM_NOMINAL[PAM_NX] = {"
            + ", ".join(repr(float(BY_NAME[s].nominal)) for s in STATES) + "};",
            "", "#endif", ""]
    return "\n".join(out)


def write_sources(dest: Path, fmi_version: int) -> list[str]:
    """Write the sources an FMU ships (C files, generated header, FMI headers, licence) into ``dest``."""
    dest.mkdir(parents=True, exist_ok=True)
    root = c_source_dir()
    names = []
    for name in CORE_SOURCES + (WRAPPERS[fmi_version],):
        (dest / name).write_bytes((root / "src" / name).read_bytes())
        names.append(name)
    for name in HEADERS[fmi_version]:
        (dest / name).write_bytes((root / "include" / f"fmi{fmi_version}" / name).read_bytes())
        names.append(name)
    (dest / "FMI_HEADERS_LICENSE.txt").write_bytes((root / "include" / "LICENSE.txt").read_bytes())
    (dest / "pam_variables.h").write_text(c_header(fmi_version))
    (dest / "buildDescription.xml").write_text(build_description(fmi_version))
    return names + ["pam_variables.h", "buildDescription.xml"]


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
        kind = "Real / Float64" if v.kind == "real" else "Integer / Int32"
        start = "" if v.start is None else f"{v.start:g}" if isinstance(v.start, float) else str(v.start)
        desc = v.description.replace("|", "\\|")
        rows.append(f"| `{v.name}` | {v.causality} | {kind} | {v.unit or ''} | {start} | {range_text(v)} | {desc} |")
    return "\n".join(rows) + "\n"
