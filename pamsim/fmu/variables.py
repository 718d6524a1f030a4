"""The one table of FMU variables.

Both ``modelDescription.xml`` files (FMI 2.0 and 3.0) and the C header of
value references and start values (``pam_variables.h``) are generated from
:data:`VARIABLES` by :mod:`pamsim.fmu.generate`; nothing is kept in step by
hand.  Model parameters are taken from the parameter set
``shadow_6x300_acra2012`` (name, unit, start value, description), so a new
parameter there becomes an FMU parameter on the next build.

Value references are pinned in :data:`VALUE_REFERENCES` (0 is ``time`` in
FMI 3.0), so adding, moving or renaming a variable never renumbers the others;
a variable not yet pinned there gets the next free number after the pinned
ones, in table order (a test compares the table with the committed list
``tests/data/fmu_value_references.csv``).  Integer variables are ``Integer``
in FMI 2.0 and ``Int32`` in FMI 3.0.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

from ..core_table import C_CHOICES
from ..model import STATE_SCALES
from ..parameters import LOAD_MASS, get_parameter_set
from ..simulator import MIN_MAX_STEP_S, SolverOptions

PARAMETER_SET = "shadow_6x300_acra2012"

FRICTION_CHOICES = C_CHOICES["friction"]
"""``friction_model`` values 0, 1, 2 (the scenario's ``model.friction`` names)."""
DAMPING_CHOICES = C_CHOICES["damping"]
"""``damping_model`` values 0, 1, 2 (the scenario's ``model.damping`` names)."""
SOURCE_CHOICES = C_CHOICES["source"]
"""``pressure_source`` values 0, 1 (the scenario's ``pressure.source`` names)."""
STATIC_FORCE_CHOICES = C_CHOICES["static_force_model"]
"""``static_force_model`` values 0, 1: the ACRA 2012 polynomial, exact, or the force table baked into the FMU at
build time (any other static model; :mod:`pamsim.fmu.force_table`)."""
NEGATIVE_LEVEL = C_CHOICES["friction_negative_level"]
"""``friction_negative_level`` values 0, 1 (the scenario's ``model.friction_negative_level`` names)."""
INPUT_SOURCE_CHOICES = ("importer", "scenario")
"""``input_source`` values 0, 1: the inputs are the importer's, or follow the signals of the scenario the
FMU was built from (:mod:`pamsim.fmu.preset`).  Its C enumeration is generated into ``pam_variables.h``."""


VALUE_REFERENCES = {
    # The parameter set shadow_6x300_acra2012.
    "K1_N_per_bar_m2": 1, "K2_N_per_bar_m": 2, "C1_N_per_bar": 3, "S1_N_per_m2": 4, "S2_N_per_m": 5, "S3_N": 6,
    "N2_N_per_bar_m2": 7, "N1_N_per_bar_m": 8, "N0_N_per_bar": 9, "phi_bar_per_kg": 10, "coulomb_constant_N": 11,
    "D1_N_s_per_m": 12, "D2_N_s2_per_m2": 13, "L0_m": 14, "r0_m": 15, "theta0_deg": 16,
    "dead_volume_m3": 17, "valve_C_m3_per_s_Pa": 18, "valve_b": 19, "valve_laminar_ratio": 20, "rho0_kg_m3": 21,
    "T0_K": 22, "polytropic_index": 23, "T_supply_K": 24, "R_J_per_kg_K": 25, "p_atm_Pa": 26, "g_m_s2": 27,
    "rated_pressure_gauge_Pa": 28, "fit_x_min_m": 29, "fit_x_max_m": 30, "fit_p_max_Pa": 31, "stop_restitution": 32,
    # The FMU's own parameters.
    "friction_model": 33, "damping_model": 34, "pressure_source": 35, "initial_contraction_m": 36,
    "stick_margin_N": 37, "release_margin_N": 38, "cs_relative_tolerance": 39, "cs_max_step_s": 40,
    "friction_negative_level": 41, "initial_pressure_gauge_Pa": 42, "cs_max_internal_steps": 62,
    "static_force_model": 63, "input_source": 64, "x_high_m": 65,
    # Inputs, states, derivatives, outputs, event indicators.
    "valve_command": 43, "supply_pressure_gauge_Pa": 44, "prescribed_pressure_gauge_Pa": 45, "load_mass_kg": 46,
    "external_force_N": 47, "contraction_m": 48, "velocity_m_s": 49, "chamber_pressure_abs_Pa": 50, "air_mass_kg": 51,
    "der(contraction_m)": 52, "der(velocity_m_s)": 53, "der(chamber_pressure_abs_Pa)": 54, "der(air_mass_kg)": 55,
    "p_gauge_Pa": 56, "F_static_N": 57, "F_friction_N": 58, "friction_mode": 59,
    "event_indicator_1": 60, "event_indicator_2": 61,
}
"""Pinned value references.  Never change or reuse a number: a renamed variable keeps its number
(``p_gauge_Pa``, ``F_static_N`` and ``F_friction_N`` were ``pressure_gauge_Pa``,
``muscle_force_N`` and ``friction_force_N``; ``r0_m`` and ``theta0_deg`` were ``D0_m`` and
``braid_angle_rest_deg``), a removed one leaves a gap."""


@dataclass(frozen=True)
class Variable:
    """One FMU variable.

    ``kind`` is ``"real"`` or ``"integer"``; ``derivative_of`` names the state
    a derivative belongs to; ``nominal`` sets the state scale the importer's
    error control uses.  ``lower``/``upper`` (``*_open``: bound excluded) is
    the range a parameter must lie in, as :class:`pamsim.parameters.Parameter`;
    the C parameter check loops over these bounds (``PAM_VARS[]`` in
    ``pam_variables.h``).  An integer choice's range is ``[0, len(choices) - 1]``;
    it is an Enumeration in ``modelDescription.xml``.  ``depends_on`` lists
    the states and inputs an output, derivative or event indicator depends on
    in continuous time (the ``ModelStructure`` dependencies); ``None`` leaves
    them undeclared (depends on everything).  ``initial_depends_on`` does the
    same for a state's initial value, over parameters and inputs.
    """

    name: str
    kind: str
    causality: str
    variability: str
    description: str
    unit: str | None = None
    start: float | int | None = None
    initial: str | None = None
    derivative_of: str | None = None
    nominal: float | None = None
    lower: float = -math.inf
    upper: float = math.inf
    lower_open: bool = False
    upper_open: bool = False
    choices: tuple[str, ...] | None = None
    depends_on: tuple[str, ...] | None = None
    initial_depends_on: tuple[str, ...] | None = None

    @property
    def c_name(self) -> str:
        """Identifier used in the generated C header."""
        return re.sub(r"\W", "_", self.name.replace("der(", "der_").rstrip(")"))


def _choices(values: tuple[str, ...]) -> str:
    return ", ".join(f"{i} = {v}" for i, v in enumerate(values))


def _choice(name: str, description: str, choices: tuple[str, ...]) -> Variable:
    """An integer parameter choosing one of ``choices`` (0 = the first, the default)."""
    return Variable(name, "integer", "parameter", "fixed", description.format(_choices(choices)), None, 0, "exact",
                    lower=0, upper=len(choices) - 1, choices=choices)


X, V, P, M = "contraction_m", "velocity_m_s", "chamber_pressure_abs_Pa", "air_mass_kg"
MECHANICS = (X, V, P, "prescribed_pressure_gauge_Pa", "load_mass_kg", "external_force_N")
"""What the load's acceleration and the event indicators depend on: the state, the pressure (a state
or an input, by ``pressure_source``), the load and the external force.  The mode is a discrete
state: it changes only at events, so ``friction_mode`` depends on nothing in continuous time."""


def _table() -> tuple[Variable, ...]:
    params = get_parameter_set(PARAMETER_SET)
    solver = SolverOptions()
    rows = [Variable(name, "real", "parameter", "fixed", f"{p.description} [{p.unit}] (source: {p.source})",
                     p.unit, p.value, "exact", lower=p.lower, upper=p.upper, lower_open=p.lower_open,
                     upper_open=p.upper_open)
            for name, p in params.entries.items()]
    rows += [
        _choice("friction_model", "Coulomb friction law: {}", FRICTION_CHOICES),
        _choice("damping_model", "viscous damping law: {}", DAMPING_CHOICES),
        _choice("pressure_source", "pressure source: {} (input prescribed_pressure_gauge_Pa)", SOURCE_CHOICES),
        Variable("initial_contraction_m", "real", "parameter", "fixed",
                 "contraction at t = 0, load at rest, between the stops [m]", "m", 0.0, "exact"),
        Variable("stick_margin_N", "real", "parameter", "fixed",
                 "a stopping load is held when the net force exceeds friction by no more than this [N]",
                 "N", solver.stick_margin_N, "exact", lower=0.0),
        Variable("release_margin_N", "real", "parameter", "fixed",
                 "a held load is released when the net force exceeds friction by this [N] (> stick_margin_N)",
                 "N", solver.release_margin_N, "exact", lower=0.0, lower_open=True),
        Variable("cs_relative_tolerance", "real", "parameter", "fixed",
                 "relative tolerance of the co-simulation integrator (Dormand-Prince 5(4)) [1]", "1", 1e-8, "exact",
                 lower=0.0, upper=1e-2, lower_open=True),
        Variable("cs_max_step_s", "real", "parameter", "fixed",
                 "largest internal step of the co-simulation integrator while the load slides [s]", "s", 0.01,
                 "exact",
                 lower=MIN_MAX_STEP_S),  # as a scenario's solver.max_step_s: smaller ones only make a step hang
        _choice("friction_negative_level", "load-dependent friction where its level "
                "(P_bar - phi m)(N2 x^2 + N1 x + N0) is negative: {} (clamp: level 0; abs: its magnitude)",
                NEGATIVE_LEVEL),
        Variable("initial_pressure_gauge_Pa", "real", "parameter", "fixed",
                 "chamber gauge pressure at t = 0 (valve source), at most rated_pressure_gauge_Pa [Pa]",
                 "Pa", 0.0, "exact", lower=0.0),
        # Inputs.
        Variable("valve_command", "real", "input", "continuous",
                 "proportional 3/3 valve: 1 open to supply, 0 closed, -1 open to exhaust [1]", "1", 0.0,
                 lower=-1.0, upper=1.0),
        Variable("supply_pressure_gauge_Pa", "real", "input", "continuous",
                 "valve supply gauge pressure, at most rated_pressure_gauge_Pa [Pa]", "Pa", 0.0, lower=0.0),
        Variable("prescribed_pressure_gauge_Pa", "real", "input", "continuous",
                 "chamber gauge pressure when pressure_source = 1 (prescribed) [Pa]", "Pa", 0.0),
        Variable("load_mass_kg", "real", "input", "continuous", f"{LOAD_MASS.description} [kg] (range: "
                 f"{LOAD_MASS.source})", LOAD_MASS.unit, LOAD_MASS.value, lower=LOAD_MASS.lower),
        Variable("external_force_N", "real", "input", "continuous",
                 "extra force on the load, positive along the contraction [N]", "N", 0.0),
        # States (the two mechanical ones are also outputs).
        Variable("contraction_m", "real", "output", "continuous", "contraction x = L0 - L [m]", "m",
                 initial="calculated", nominal=STATE_SCALES["x_m"], depends_on=(X,), initial_depends_on=("initial_contraction_m",)),
        Variable("velocity_m_s", "real", "output", "continuous", "contraction velocity dx/dt [m/s]", "m/s",
                 initial="calculated", nominal=STATE_SCALES["v_m_s"], depends_on=(V,), initial_depends_on=()),
        Variable("chamber_pressure_abs_Pa", "real", "local", "continuous",
                 "absolute chamber pressure (valve source) [Pa]", "Pa", initial="calculated",
                 nominal=STATE_SCALES["p_abs_Pa"],
                 initial_depends_on=("p_atm_Pa", "initial_pressure_gauge_Pa")),
        Variable("air_mass_kg", "real", "local", "continuous", "air mass in the chamber (valve source) [kg]",
                 "kg", initial="calculated", nominal=STATE_SCALES["air_mass_kg"],
                 initial_depends_on=("p_atm_Pa", "initial_pressure_gauge_Pa", "initial_contraction_m", "L0_m", "r0_m",
                                     "theta0_deg", "dead_volume_m3", "R_J_per_kg_K", "T_supply_K")),
        Variable("der(contraction_m)", "real", "local", "continuous", "d contraction / dt [m/s]", "m/s",
                 initial="calculated", derivative_of="contraction_m", depends_on=(V,)),
        Variable("der(velocity_m_s)", "real", "local", "continuous", "acceleration [m/s^2]", "m/s^2",
                 initial="calculated", derivative_of="velocity_m_s", depends_on=MECHANICS),
        Variable("der(chamber_pressure_abs_Pa)", "real", "local", "continuous", "chamber pressure rate [Pa/s]",
                 "Pa/s", initial="calculated", derivative_of="chamber_pressure_abs_Pa",
                 depends_on=(X, V, P, M, "valve_command", "supply_pressure_gauge_Pa")),
        Variable("der(air_mass_kg)", "real", "local", "continuous", "valve mass flow into the chamber [kg/s]",
                 "kg/s", initial="calculated", derivative_of="air_mass_kg",
                 depends_on=(X, P, M, "valve_command", "supply_pressure_gauge_Pa")),
        # Outputs.
        # Named as the columns of pamsim.Result that hold the same quantity.
        Variable("p_gauge_Pa", "real", "output", "continuous", "chamber gauge pressure [Pa]", "Pa",
                 initial="calculated", depends_on=(P, "prescribed_pressure_gauge_Pa")),
        Variable("F_static_N", "real", "output", "continuous",
                 "static muscle force F_static(x, p) alone, without damping or friction [N]", "N",
                 initial="calculated", depends_on=(X, P, "prescribed_pressure_gauge_Pa")),
        Variable("F_friction_N", "real", "output", "continuous",
                 "friction force on the load along x; when held, whatever holds it [N]", "N", initial="calculated",
                 depends_on=(X, P, "prescribed_pressure_gauge_Pa", "load_mass_kg", "external_force_N")),
        Variable("friction_mode", "integer", "output", "discrete",
                 "-1 slip down, 0 stick, 1 slip up, 2 on the lower stop, 3 on the upper stop (pamsim.model.Mode)",
                 initial="calculated", depends_on=()),
        # Event indicators (FMI 3.0 declares them as variables).
        Variable("event_indicator_1", "real", "local", "continuous",
                 "sliding: velocity; held: upward force margin [m/s or N]", initial="calculated",
                 depends_on=MECHANICS),
        Variable("event_indicator_2", "real", "local", "continuous",
                 "sliding: distance to the stop ahead; stuck: downward force margin [m or N]", initial="calculated",
                 depends_on=MECHANICS),
        _choice("static_force_model", "static force: {} (the force table baked into this FMU at build time; "
                "0 uses the parameters K1..S3)", STATIC_FORCE_CHOICES),
        Variable("cs_max_internal_steps", "integer", "parameter", "fixed",
                 "co-simulation: a doStep that needs more internal steps than this fails (a bound on its "
                 "run time) [1]", None, 10_000_000, "exact", lower=1, upper=2**31 - 1),
        _choice("input_source", "where the inputs come from: {} (the signals of the scenario this FMU was "
                "built from; an input set to another value than its signal's is then refused)",
                INPUT_SOURCE_CHOICES),
        Variable("x_high_m", "real", "parameter", "fixed",
                 "contraction of the upper end stop: the muscle's own (pamsim.muscle_setup.end_stops: its braid's "
                 "jam angle, its model's domain end or the braid lock), or 0 for the braid lock at 54.7 deg from "
                 "L0_m, r0_m and theta0_deg [m]", "m", 0.0, "exact", lower=0.0),
    ]
    return tuple(rows)


def assign_value_references(variables, pinned) -> dict[str, int]:
    """``{name: value reference}``: the pinned number, else the next free one after all pinned
    numbers, in table order."""
    out, nxt = {}, max(pinned.values(), default=0) + 1
    for v in variables:
        if v.name in pinned:
            out[v.name] = pinned[v.name]
        else:
            out[v.name], nxt = nxt, nxt + 1
    return out


def with_force_table(variables: tuple[Variable, ...], has_table: bool) -> tuple[Variable, ...]:
    """The table of an FMU built with (``has_table``) or without a force table: with one, the FMU
    starts on it (``static_force_model`` = table)."""
    if not has_table:
        return variables
    return tuple(replace(v, start=STATIC_FORCE_CHOICES.index("table")) if v.name == "static_force_model" else v
                 for v in variables)


def _with_source(v: Variable, source: str) -> str:
    """``v``'s description with its start value's provenance: a parameter's ``(source: ...)`` replaced,
    anything else's appended."""
    head, sep, _ = v.description.rpartition(" (source: ")
    if sep and v.causality == "parameter" and v.kind == "real":
        return f"{head} (source: {source})"
    return f"{v.description} (start value: {source})"


def with_preset(variables: tuple[Variable, ...], table, preset) -> tuple[Variable, ...]:
    """The table of an FMU built with a force ``table`` and a :class:`pamsim.fmu.preset.Preset` (or
    None): the preset's start values, each with its provenance in the description."""
    variables = with_force_table(variables, table is not None)
    if preset is None:
        return variables
    unknown = sorted(set(preset.starts) - {v.name for v in variables})
    if unknown:
        raise ValueError(f"preset start values for variables the FMU does not have: {unknown}")
    out = []
    for v in variables:
        if v.name in preset.starts:
            start = preset.starts[v.name]
            v = replace(v, start=int(start) if v.kind == "integer" else float(start),
                        description=_with_source(v, preset.sources[v.name]))
        out.append(v)
    return tuple(out)


VARIABLES: tuple[Variable, ...] = _table()
BY_NAME = {v.name: v for v in VARIABLES}
_VRS = assign_value_references(VARIABLES, VALUE_REFERENCES)


def value_reference(name: str) -> int:
    """Value reference of ``name`` (pinned in :data:`VALUE_REFERENCES`; 0 is FMI 3.0 ``time``)."""
    return _VRS[BY_NAME[name].name]


STATES = tuple(v.derivative_of for v in VARIABLES if v.derivative_of)
INPUTS = tuple(v.name for v in VARIABLES if v.causality == "input")
"""The inputs, in table order: the FMU's, and the columns of a native case's ``segment_u``."""
EVENT_INDICATORS = ("event_indicator_1", "event_indicator_2")
