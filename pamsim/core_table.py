"""The one table of constants and choices that the Python model and the C core share.

The C header ``fmu/src/pam_shared.h`` is generated from this module (and from
:class:`pamsim.model.Mode`) by :func:`pamsim.fmu.generate.shared_header`; a test
checks that the committed header is the generated one, so a value changed here
without regenerating fails the tests instead of letting Python and C drift apart.
Regenerate with ``python -m pamsim.fmu.generate --shared-header``.

The parameter and input ranges live with the parameters
(:class:`pamsim.parameters.Parameter`) and the FMU variable table
(:mod:`pamsim.fmu.variables`), from which ``pam_variables.h`` is generated;
the checks between two parameters are :data:`ORDER_CHECKS` here.
This module imports nothing from pamsim but :mod:`pamsim.constants`, so any
element can use it.
"""

from __future__ import annotations

from dataclasses import dataclass

from .constants import PA_PER_BAR


@dataclass(frozen=True)
class SharedConstant:
    """A number both implementations use: C name, value, unit and why it has this value."""

    c_name: str
    value: float
    unit: str
    why: str


MIN_REBOUND_SPEED_M_S = 1e-3
"""A rebound slower than this off an end stop is no rebound: the load stays on the stop [m/s]."""
MAX_ZERO_LENGTH_EVENTS = 50
"""In the C core, more events than this at one instant means the switching makes no progress (a solver
failure).  The Python simulator holds such a load briefly instead and has its own limit
(``pamsim.simulator._MAX_ZERO_LENGTH``), so this one is the C core's alone."""
EVENT_V_TOL_M_S = 1e-9
"""C event indicators on velocity are shifted by this, so v = 0 right after a release is no event [m/s]."""
EVENT_X_TOL_M = 1e-9
"""C event indicators on the stop distance are shifted by this, for the same reason [m]."""
BRAID_LOCK_SEC2 = 3.0
"""1 / cos^2 of the braid-lock angle (54.7 deg): the locked length is b / sqrt(3) [1]."""

CONSTANTS: tuple[SharedConstant, ...] = (
    SharedConstant("PAM_PA_PER_BAR", PA_PER_BAR, "Pa/bar", "the paper's polynomials take gauge pressure in bar"),
    SharedConstant("PAM_MIN_REBOUND_M_S", MIN_REBOUND_SPEED_M_S, "m/s",
                   "assumed: slower rebounds would bounce for ever in ever shorter hops"),
    SharedConstant("PAM_MAX_ZERO_LENGTH_EVENTS", MAX_ZERO_LENGTH_EVENTS, "1",
                   "assumed: a legitimate cascade (stop, stick, release) needs a handful"),
    SharedConstant("PAM_V_TOL_M_S", EVENT_V_TOL_M_S, "m/s", "assumed: far below any speed the tests resolve"),
    SharedConstant("PAM_X_TOL_M", EVENT_X_TOL_M, "m", "assumed: far below any contraction the tests resolve"),
    SharedConstant("PAM_BRAID_LOCK_SEC2", BRAID_LOCK_SEC2, "1", "braid lock at cos^2 = 1/3 (MODEL_NOTES sec. 5)"),
)

C_CHOICES: dict[str, tuple[str, ...]] = {
    "static_force": ("acra2012_polynomial",),
    "friction": ("load_dependent", "constant", "none"),
    "damping": ("paper", "linear", "none"),
    "source": ("valve", "prescribed"),
    "friction_negative_level": ("clamp", "abs"),
    "static_force_model": ("acra2012_polynomial", "table"),
}
"""The element choices the C core implements, by scenario key, in the order of their C enumeration.

``static_force_model`` is the FMU's own choice between the polynomial and a force table baked
into the FMU at build time (:mod:`pamsim.fmu.force_table`), through which the FMU runs any
scenario static force; the native library has no table and refuses other static forces.

A choice in a Python registry but not here is refused by the native and FMU
backends (``InputError`` naming the key); ``tests/test_native_table.py``
checks that for every registry entry.
"""

SCENARIO_KEYS: dict[str, str] = {"static_force": "model.static_force", "friction": "model.friction",
                                 "damping": "model.damping", "source": "pressure.source",
                                 "friction_negative_level": "model.friction_negative_level"}
"""Where each choice is named in a scenario file (for error messages)."""

ORDER_CHECKS: tuple[tuple[str, str], ...] = (
    ("valve_b", "valve_laminar_ratio"),
    ("fit_x_min_m", "fit_x_max_m"),
)
"""Parameter pairs ``(a, b)`` that must satisfy ``a < b`` (``ParameterSet.violations`` and the C check)."""


def unimplemented_choice(spec, skip: tuple[str, ...] = ()) -> tuple[str, str] | None:
    """The first ``(scenario key, value)`` of a scenario ``spec`` that names a choice the C core lacks, or None.

    ``skip`` names :data:`C_CHOICES` keys a backend handles otherwise (the FMU tabulates any static force).
    """
    for key, where in SCENARIO_KEYS.items():
        if key in skip:
            continue
        section, name = where.split(".")
        value = spec.get(section, {}).get(name)
        if value is not None and value not in C_CHOICES[key]:
            return where, value
    return None


def c_identifier(text: str) -> str:
    """An upper-case C identifier for a choice name (``load_dependent`` -> ``LOAD_DEPENDENT``)."""
    return "".join(ch if ch.isalnum() else "_" for ch in text).upper()
