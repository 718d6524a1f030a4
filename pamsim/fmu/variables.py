"""The one table of FMU variables.

Both ``modelDescription.xml`` files (FMI 2.0 and 3.0) and the C header of
value references and start values (``pam_variables.h``) are generated from
:data:`VARIABLES` by :mod:`pamsim.fmu.generate`; nothing is kept in step by
hand.  Model parameters are taken from the parameter set
``shadow_6x300_acra2012`` (name, unit, start value, description), so a new
parameter there becomes an FMU parameter on the next build.

Value references are the 1-based position in the table (0 is ``time`` in
FMI 3.0).  Integer variables are ``Integer`` in FMI 2.0 and ``Int32`` in
FMI 3.0.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..elements.friction import NEGATIVE_LEVEL_CHOICES
from ..parameters import get_parameter_set
from ..simulator import SolverOptions

PARAMETER_SET = "shadow_6x300_acra2012"

FRICTION_CHOICES = ("load_dependent", "constant", "none")
"""``friction_model`` values 0, 1, 2 (the scenario's ``model.friction`` names)."""
DAMPING_CHOICES = ("paper", "linear", "none")
"""``damping_model`` values 0, 1, 2 (the scenario's ``model.damping`` names)."""
SOURCE_CHOICES = ("valve", "prescribed")
"""``pressure_source`` values 0, 1 (the scenario's ``pressure.source`` names)."""
NEGATIVE_LEVEL = NEGATIVE_LEVEL_CHOICES
"""``friction_negative_level`` values 0, 1 (the scenario's ``model.friction_negative_level`` names)."""


@dataclass(frozen=True)
class Variable:
    """One FMU variable.

    ``kind`` is ``"real"`` or ``"integer"``; ``derivative_of`` names the state
    a derivative belongs to; ``nominal`` sets the state scale the importer's
    error control uses.  ``lower``/``upper`` (``*_open``: bound excluded) is
    the range a parameter must lie in, as :class:`pamsim.parameters.Parameter`;
    the C parameter check loops over these bounds (``PAM_VARS[]`` in
    ``pam_variables.h``).  An integer choice's range is ``[0, len(choices) - 1]``.
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
                 "largest internal step of the co-simulation integrator [s]", "s", 0.01, "exact",
                 lower=0.0, lower_open=True),
        _choice("friction_negative_level", "load-dependent friction where its level "
                "(P_bar - phi m)(N2 x^2 + N1 x + N0) is negative: {} (clamp: level 0; abs: its magnitude)",
                NEGATIVE_LEVEL),
        Variable("initial_pressure_gauge_Pa", "real", "parameter", "fixed",
                 "chamber gauge pressure at t = 0 (valve source), at most rated_pressure_gauge_Pa [Pa]",
                 "Pa", 0.0, "exact", lower=0.0),
        # Inputs.
        Variable("valve_command", "real", "input", "continuous",
                 "proportional 3/3 valve: 1 open to supply, 0 closed, -1 open to exhaust [1]", "1", 0.0),
        Variable("supply_pressure_gauge_Pa", "real", "input", "continuous",
                 "valve supply gauge pressure, at most rated_pressure_gauge_Pa [Pa]", "Pa", 0.0),
        Variable("prescribed_pressure_gauge_Pa", "real", "input", "continuous",
                 "chamber gauge pressure when pressure_source = 1 (prescribed) [Pa]", "Pa", 0.0),
        Variable("load_mass_kg", "real", "input", "continuous",
                 "hanging mass, holder included, > 0 [kg]", "kg", round(22.74 / params["g_m_s2"], 6)),
        Variable("external_force_N", "real", "input", "continuous",
                 "extra force on the load, positive along the contraction [N]", "N", 0.0),
        # States (the two mechanical ones are also outputs).
        Variable("contraction_m", "real", "output", "continuous", "contraction x = L0 - L [m]", "m",
                 initial="calculated", nominal=0.01),
        Variable("velocity_m_s", "real", "output", "continuous", "contraction velocity dx/dt [m/s]", "m/s",
                 initial="calculated", nominal=0.1),
        Variable("chamber_pressure_abs_Pa", "real", "local", "continuous",
                 "absolute chamber pressure (valve source) [Pa]", "Pa", initial="calculated", nominal=1e5),
        Variable("air_mass_kg", "real", "local", "continuous", "air mass in the chamber (valve source) [kg]",
                 "kg", initial="calculated", nominal=1e-5),
        Variable("der(contraction_m)", "real", "local", "continuous", "d contraction / dt [m/s]", "m/s",
                 initial="calculated", derivative_of="contraction_m"),
        Variable("der(velocity_m_s)", "real", "local", "continuous", "acceleration [m/s^2]", "m/s^2",
                 initial="calculated", derivative_of="velocity_m_s"),
        Variable("der(chamber_pressure_abs_Pa)", "real", "local", "continuous", "chamber pressure rate [Pa/s]",
                 "Pa/s", initial="calculated", derivative_of="chamber_pressure_abs_Pa"),
        Variable("der(air_mass_kg)", "real", "local", "continuous", "valve mass flow into the chamber [kg/s]",
                 "kg/s", initial="calculated", derivative_of="air_mass_kg"),
        # Outputs.
        Variable("pressure_gauge_Pa", "real", "output", "continuous", "chamber gauge pressure [Pa]", "Pa",
                 initial="calculated"),
        Variable("muscle_force_N", "real", "output", "continuous", "static muscle force F_static(x, p) [N]", "N",
                 initial="calculated"),
        Variable("friction_force_N", "real", "output", "continuous",
                 "friction force on the load along x; when held, whatever holds it [N]", "N", initial="calculated"),
        Variable("friction_mode", "integer", "output", "discrete",
                 "-1 slip down, 0 stick, 1 slip up, 2 on the lower stop, 3 on the upper stop (pamsim.model.Mode)",
                 initial="calculated"),
        # Event indicators (FMI 3.0 declares them as variables).
        Variable("event_indicator_1", "real", "local", "continuous",
                 "sliding: velocity; held: upward force margin [m/s or N]", initial="calculated"),
        Variable("event_indicator_2", "real", "local", "continuous",
                 "sliding: distance to the stop ahead; stuck: downward force margin [m or N]", initial="calculated"),
    ]
    return tuple(rows)


VARIABLES: tuple[Variable, ...] = _table()
BY_NAME = {v.name: v for v in VARIABLES}


def value_reference(name: str) -> int:
    """Value reference of ``name`` (1-based table position; 0 is FMI 3.0 ``time``)."""
    return VARIABLES.index(BY_NAME[name]) + 1


STATES = tuple(v.derivative_of for v in VARIABLES if v.derivative_of)
EVENT_INDICATORS = ("event_indicator_1", "event_indicator_2")
