"""The one-muscle FMU generated from components: its :class:`~pamsim.fmu.spec.FmuSpec`, and building it.

Its variables are those of :mod:`pamsim.fmu.variables` (the names, value references, ranges and
choices it has always had), then the generated model's work integrals and outputs that have no
name there, under their namespaced names.  Its C core is the generic one (``pam_gcore.c``) with the
parameter map and the checks of :mod:`pamsim.fmu.muscle_fmu` generated beside the model.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..errors import InputError
from .build import FMI_VERSIONS, build_spec, default_output
from .force_table import ForceTable
from .generate import (_usage, description, spec_c_header, spec_documentation_html, spec_model_description,
                       write_spec_documentation, write_spec_sources)
from .generated import CORE_HEADER, SOURCES, AssemblyVariables
from .generated import token as spec_token
from .muscle_fmu import MASS_INPUT, MODE_NAME, OUTPUT_NAMES, STATE_NAMES, knob_map, muscle_assembly
from .spec import FmuSpec
from .variables import INPUTS, VARIABLES, value_reference, with_preset

OWN = ("cs_relative_tolerance", "cs_max_step_s", "cs_max_internal_steps", "input_source")
"""The FMU's own parameters: read by its C core, not the model's."""


def knob_names() -> tuple[str, ...]:
    """The FMU variables the model's parameters are derived from: every parameter but the FMU's own, and the
    load's mass (an input)."""
    return tuple(v.name for v in VARIABLES if v.causality == "parameter" and v.name not in OWN) + (MASS_INPUT,)


@dataclass(frozen=True)
class Check:
    """A condition on the FMU's knobs and inputs, refused with ``message`` (printf, at most three ``%g``-like
    conversions, of ``values``) where ``holds`` is 0; ``input``: the input it concerns, checked whenever that
    input is set, or None (checked at the end of initialisation)."""

    holds: Any
    message: str
    values: tuple = ()
    input: str | None = None


TABLE_COVER_TOL = 1e-12
"""The part of the table's range by which a bound computed in Python (the tabulated domain) and in the
FMU's generated map may differ: a few roundings."""


def checks(k: dict, u: dict, table=None) -> list[Check]:
    """The one-muscle FMU's checks between its parameters, of its force ``table`` against the travel and
    the rating, and of its pressure inputs against the rating."""
    from ..core_table import ORDER_CHECKS
    from .muscle_fmu import on_table, own_upper_stop

    x_high = own_upper_stop(k)
    rated = k["rated_pressure_gauge_Pa"]
    out = [Check(k[a] < k[b], f"invalid parameters: {a} = %g: must be below {b} = %g", (k[a], k[b]))
           for a, b in ORDER_CHECKS]
    out += [
        Check(k["release_margin_N"] > k["stick_margin_N"],
              "invalid parameters: release_margin_N = %g: must be above stick_margin_N = %g",
              (k["release_margin_N"], k["stick_margin_N"])),
        Check(k["initial_pressure_gauge_Pa"] <= rated,
              "invalid parameters: initial_pressure_gauge_Pa = %g: must be at most rated_pressure_gauge_Pa = %g",
              (k["initial_pressure_gauge_Pa"], rated)),
        Check((k["x_high_m"] <= 0.0) + (k["x_high_m"] < k["L0_m"]) > 0,
              "invalid parameters: x_high_m = %g: the upper stop must be below the rest length L0_m = %g "
              "(x_high_m = 0: the braid lock from the geometry)", (k["x_high_m"], k["L0_m"])),
        Check((k["initial_contraction_m"] >= 0.0) * (k["initial_contraction_m"] <= x_high) > 0,
              "invalid parameters: initial_contraction_m = %g: must lie between the stops, 0 and %.4f m "
              "(the upper stop)", (k["initial_contraction_m"], x_high)),
    ]
    out += _table_checks(k, table, x_high, on_table(k, table)) if table is not None else [
        Check(k["static_force_model"] != 1.0, "invalid parameters: static_force_model = 1 (table): this FMU was "
              "built without a force table (build it with pamsim fmu build --scenario)")]
    for name in ("supply_pressure_gauge_Pa", "prescribed_pressure_gauge_Pa"):
        out.append(Check(u[name] <= rated, f"{name} = %g Pa: exceeds the muscle's rating rated_pressure_gauge_Pa = "
                         "%g Pa", (u[name], rated), name))
    out.append(Check(u["prescribed_pressure_gauge_Pa"] >= -k["p_atm_Pa"],
                     "prescribed_pressure_gauge_Pa = %g Pa: below vacuum", (u["prescribed_pressure_gauge_Pa"],),
                     "prescribed_pressure_gauge_Pa"))
    return out


def _table_checks(k: dict, table, x_high, inside) -> list[Check]:
    """The table covers the load's travel (0 to the upper stop) and the gauge pressures the chamber starts and is
    driven at (0 to the rating): a table is built for one muscle, and another's geometry or rating would leave
    it.  Checked where the FMU runs on it."""
    x_tol = TABLE_COVER_TOL * (table.x_max_m - table.x_min_m)
    p_tol = TABLE_COVER_TOL * (table.p_max_Pa - table.p_min_Pa)
    name = table.model_name
    return [
        Check(1 - inside * ((x_high > table.x_max_m + x_tol) + (table.x_min_m > x_tol) > 0),
              "invalid parameters: L0_m = %g, theta0_deg = %g, x_high_m = %g: the load's travel, 0 to %.6g m (the "
              f"upper stop), leaves the force table of {name}, which covers contraction {table.x_min_m:.6g} to "
              f"{table.x_max_m:.6g} m (a table is built for one muscle: build the FMU for this geometry)",
              (k["L0_m"], k["theta0_deg"], k["x_high_m"], x_high)),
        Check(1 - inside * (k["rated_pressure_gauge_Pa"] > table.p_max_Pa + p_tol),
              f"invalid parameters: rated_pressure_gauge_Pa = %g: above the force table of {name}, which covers gauge "
              f"pressure {table.p_min_Pa:g} to {table.p_max_Pa:g} Pa (the supply, prescribed and initial pressures "
              "may reach the rating)", (k["rated_pressure_gauge_Pa"],)),
        Check(1 - inside * float(table.p_min_Pa > p_tol),
              f"invalid parameters: static_force_model = 1 (table): the force table of {name} starts at gauge "
              f"pressure {table.p_min_Pa:g} Pa, above the ambient pressure an exhausted chamber reaches"),
    ]


def _c_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


class MuscleVariables(AssemblyVariables):
    """The one-muscle FMU's variables over the generated model (see the module)."""

    def __init__(self, cmodel, legacy: tuple, knobs: tuple[str, ...], mass_rows: list[bool]):
        self.cmodel, self.flat = cmodel, cmodel.full
        flat = cmodel.full
        self._sparsity = flat.sparsity()
        self.places = {}
        self.knobs = knobs
        self.mass_rows = mass_rows
        self.names = {**{v.name: v.name for v in flat.inputs}, **STATE_NAMES, **OUTPUT_NAMES}
        by_name = {v.name: v for v in legacy}
        for k, name in enumerate(knobs):
            self.places[name] = ("KNOB", k)
        for k, v in enumerate(flat.inputs):
            self.places[v.name] = ("INPUT", k)
        generated = self._states() + self._derivatives() + self._outputs()
        rows = [self._declared(v, generated) for v in legacy] + [v for v in generated if v.name not in by_name]
        self.mode = MODE_NAME
        self.indicators = tuple(f"event_indicator_{k + 1}" for k in range(len(flat.z)))
        if len(self.indicators) != 2:
            raise ValueError(f"the one-muscle FMU has 2 event indicators, the generated model {len(self.indicators)}")
        self.variables = tuple(rows)
        pinned = {v.name: value_reference(v.name) for v in legacy}
        nxt = max(pinned.values())
        self.value_references = dict(pinned)
        for v in rows:
            if v.name not in pinned:
                nxt += 1
                self.value_references[v.name] = nxt

    def _name(self, flat_name: str) -> str:
        return self.names.get(flat_name, flat_name)

    def _declared(self, own, generated):
        """The one-muscle FMU's own row (its description, range, start), with the dependencies the Jacobians'
        sparsity gives where the generated model has the variable."""
        for v in generated:
            if v.name == own.name and v.depends_on is not None:
                return replace(own, depends_on=v.depends_on)
        return own

    def _depends(self, row: int, block_x: str, block_u: str) -> tuple[str, ...]:
        offset = len(self.flat.states) if block_x == "C" else 0
        return super()._depends(row, block_x, block_u) + ((MASS_INPUT,) if self.mass_rows[offset + row] else ())

    def _parameter_lines(self, idx) -> list[str]:
        return self._knob_lines()

    def _knob_lines(self) -> list[str]:
        c = {v.name: v for v in self.variables}
        kind = ", ".join("1" if c[n].kind == "integer" else "0" for n in self.knobs)
        index = ", ".join(f"{'I' if c[n].kind == 'integer' else 'R'}_{c[n].c_name}" for n in self.knobs)
        return ["", "/* The knobs the generated map derives the model's parameters from (pamsim.fmu.muscle_fmu). */",
                f"#define PAM_NK {len(self.knobs)}", f"static const int PAM_K_INT[PAM_NK] = {{{kind}}};",
                f"static const int PAM_K_INDEX[PAM_NK] = {{{index}}};",
                "static const unsigned PAM_K_VR[PAM_NK] = {"
                + ", ".join(f"{self.value_references[n]}u" for n in self.knobs) + "};",
                f"static const unsigned PAM_U_VR[{max(1, len(self.flat.inputs))}] = {{"
                + ", ".join(f"{self.value_references[v.name]}u" for v in self.flat.inputs) + "};"]


MESSAGE_VALUES = 4
"""The values every check's message is given (``pam_gcore.c`` passes four; a message shows at most these)."""


def check_lines(found: list[Check], value_references: dict) -> tuple[list[str], int]:
    """The C table of ``found`` (``PAM_CHECKS``) and the number of values their messages show."""
    rows, first = [], 0
    for ch in found:
        vr = value_references[ch.input] if ch.input else 0
        rows.append(f"    {{{_c_string(ch.message)}, {first}, {vr}u}},")
        first += len(ch.values)
    n_values = first + MESSAGE_VALUES  # room for the values any message is given
    return (["", "/* The checks of pm_checks: each message, where its values start, the input it concerns (0: none). */",
             "typedef struct { const char *message; int first_value; unsigned input_vr; } PamCheck;",
             f"#define PAM_NCHECKS {len(found)}", f"#define PAM_NCHECK_VALUES {n_values}",
             "static const PamCheck PAM_CHECKS[PAM_NCHECKS] = {"] + rows + ["};"], n_values)


_SPECS: dict = {}
SPECS_KEPT = 16
"""Specs kept per process: the token, header and model description of one FMU are asked for apart, and
generating the model takes about 0.5 s."""


def muscle_generated_spec(fmi_version: int = 2, preset=None, table=None) -> FmuSpec:
    """The spec of the one-muscle FMU generated from components, for a ``preset`` (its start values and
    signals) and with a force ``table`` (:class:`pamsim.fmu.force_table.ForceTable`; the preset's if None)."""
    table = table if table is not None else (preset.table if preset is not None else None)
    key = (fmi_version, preset.digest() if preset is not None else None, table.digest() if table else None)
    if key not in _SPECS:
        if len(_SPECS) >= SPECS_KEPT:
            _SPECS.pop(next(iter(_SPECS)))
        _SPECS[key] = _generated_spec(fmi_version, preset, table)
    return _SPECS[key]


def _generated_spec(fmi_version: int, preset, table) -> FmuSpec:
    import casadi as ca

    from ..modeling.cmodel import CModel

    legacy = with_preset(VARIABLES, table, preset)
    knobs = knob_names()
    rows = {v.name: v for v in legacy}
    start = {n: float(rows[n].start) for n in knobs}
    assembly = muscle_assembly(start, table)
    flat = assembly.flatten()
    kmap, dkmap = knob_map(knobs, tuple(v.name for v in flat.parameters), start, table)
    ksym = ca.SX.sym("k", len(knobs))
    usym = ca.SX.sym("u", len(flat.inputs))
    k = {n: ksym[i] for i, n in enumerate(knobs)}
    u = {v.name: usym[i] for i, v in enumerate(flat.inputs)}
    found = checks(k, u, table)
    values = [ca.SX(v) for ch in found for v in ch.values] + [ca.SX(0.0)] * MESSAGE_VALUES
    check_fn = ca.Function("pm_checks_fn", [ksym, usym], [ca.vertcat(*[ca.SX(ch.holds) for ch in found], *values)])
    cmodel = CModel(assembly, jacobians=True, extra=(kmap, dkmap, check_fn))
    p_mass = flat.p[[v.name for v in flat.parameters].index("load.mass_kg")]
    mass_rows = [bool(ca.depends_on(ca.SX(e), p_mass)) for e in list(flat.f) + list(flat.y)]
    mv = MuscleVariables(cmodel, legacy, knobs, mass_rows)
    lines, _ = check_lines(found, mv.value_references)
    spec = FmuSpec(mv.variables, mv.value_references, tuple(mv._name(v.name) for v in flat.states),
                   mv.indicators, INPUTS, "pamsim_muscle", "pamsim_muscle", "flat", _description(table, preset),
                   SOURCES, {"pam_model.c": cmodel.sources()["pam_model.c"], "pam_fmu_core.h": CORE_HEADER},
                   tuple(mv.c_lines()) + tuple(lines), preset.signals if preset is not None else {},
                   preset.experiment if preset is not None else None, fmi_version=fmi_version,
                   included=("pam_engine.c",), usage=_usage(table, preset))
    return replace(spec, token=spec_token(spec))


def _description(table, preset) -> str:
    return description(table, preset)


def token(fmi_version: int, table: ForceTable | None = None, preset=None) -> str:
    """A hash of everything an FMU's binary is built from: sources, generated headers, table, preset."""
    return one_muscle_spec(fmi_version, table, preset).token


def one_muscle_spec(fmi_version: int, table: ForceTable | None = None, preset=None) -> FmuSpec:
    """The :class:`~pamsim.fmu.spec.FmuSpec` of the one-muscle FMU, built with a force ``table`` and for a
    ``preset``, if any (:func:`muscle_generated_spec`)."""
    return muscle_generated_spec(fmi_version, preset, table)


def model_description(fmi_version: int, table: ForceTable | None = None, preset=None) -> str:
    """``modelDescription.xml``; ``table``: the force table the FMU is built with, if any; ``preset``: the
    :class:`pamsim.fmu.preset.Preset` of the muscle or scenario it is built for, if any."""
    if fmi_version not in (2, 3):
        raise ValueError(f"FMI version must be 2 or 3, not {fmi_version!r}")
    return spec_model_description(one_muscle_spec(fmi_version, table, preset))


def c_header(fmi_version: int, table: ForceTable | None = None, preset=None) -> str:
    """``pam_variables.h`` of the one-muscle FMU (:func:`spec_c_header`)."""
    return spec_c_header(one_muscle_spec(fmi_version, table, preset))


def write_sources(dest: Path, fmi_version: int, table: ForceTable | None = None, preset=None) -> list[str]:
    """Write the sources the one-muscle FMU ships into ``dest`` (:func:`write_spec_sources`)."""
    return write_spec_sources(dest, one_muscle_spec(fmi_version, table, preset))


def documentation_html(fmi_version: int, table: ForceTable | None = None, preset=None) -> str:
    """``documentation/index.html`` of the one-muscle FMU (:func:`spec_documentation_html`)."""
    return spec_documentation_html(one_muscle_spec(fmi_version, table, preset))


def build(output_path: str | os.PathLike | None = None, fmi_version: int = 2,
          force_table: ForceTable | None = None, preset=None) -> Path:
    """Generate, compile and zip the FMU; return the path of the ``.fmu`` file.

    ``force_table`` (:func:`pamsim.fmu.force_table.tabulate`) bakes a static force table into the
    FMU, which then starts with ``static_force_model`` = table; without one the FMU has only the
    exact ACRA 2012 polynomial.  ``preset`` (:func:`pamsim.fmu.preset.for_muscle`,
    :func:`~pamsim.fmu.preset.for_scenario`) builds the FMU for a muscle or a scenario: its values
    become the FMU's start values, and its table the FMU's (``force_table`` must then be None).

    Raises :class:`~pamsim.errors.InputError` for an unknown FMI version, a
    missing C compiler or a failed compilation (with the compiler's message).
    """
    if fmi_version not in FMI_VERSIONS:
        raise InputError(f"FMI version must be 2 or 3, not {fmi_version!r}")
    if preset is not None:
        if force_table is not None:
            raise ValueError("give the force table in the preset, not beside it")
        force_table = preset.table
    out = Path(output_path) if output_path else default_output(fmi_version)
    return build_spec(out, one_muscle_spec(fmi_version, force_table, preset))


def write_documentation(dest: Path, fmi_version: int, table: ForceTable | None = None, preset=None) -> None:
    """Write the one-muscle FMU's ``documentation/`` folder into ``dest``."""
    write_spec_documentation(dest, one_muscle_spec(fmi_version, table, preset))
