"""The one table of constants and choices of the rig: the element choices the one-muscle FMU offers at
run time, the constants of its stops and event indicators, and the checks between parameters.  The
components read the constants from here, so the generated code (Python and C) has them from one place.

The parameter and input ranges live with the parameters
(:class:`pamsim.parameters.Parameter`) and the FMU variable table
(:mod:`pamsim.fmu.variables`), from which ``pam_variables.h`` is generated;
the checks between two parameters are :data:`ORDER_CHECKS` here.
This module imports nothing from pamsim, so any
element can use it.
"""

from __future__ import annotations

MIN_REBOUND_SPEED_M_S = 1e-3
"""A rebound slower than this off an end stop is no rebound: the load stays on the stop [m/s] (assumed:
slower rebounds would bounce for ever in ever shorter hops)."""
EVENT_V_TOL_M_S = 1e-9
"""Event indicators on velocity are shifted by this in the engine, so v = 0 right after a release is no
event [m/s] (assumed: far below any speed the tests resolve)."""
EVENT_X_TOL_M = 1e-9
"""Event indicators on the stop distance are shifted by this, for the same reason [m] (assumed: far below
any contraction the tests resolve)."""
BRAID_LOCK_SEC2 = 3.0
"""1 / cos^2 of the braid-lock angle (54.7 deg): the locked length is b / sqrt(3) [1] (MODEL_NOTES sec. 5)."""

C_CHOICES: dict[str, tuple[str, ...]] = {
    "static_force": ("acra2012_polynomial",),
    "friction": ("load_dependent", "constant", "none"),
    "damping": ("paper", "linear", "none"),
    "source": ("valve", "prescribed"),
    "friction_negative_level": ("clamp", "abs"),
    "static_force_model": ("acra2012_polynomial", "table"),
}
"""The element choices the one-muscle FMU offers at run time, by scenario key, in the order of its
enumerations.

``static_force_model`` is the FMU's own choice between the polynomial and a force table baked
into the FMU at build time (:mod:`pamsim.fmu.force_table`), through which the FMU runs any
scenario static force.

A choice in a Python registry but not here is refused by the one-muscle FMU's runner
(``InputError`` naming the key); the native backend runs any law that has generated C.
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
