"""Parameter sets, each value with its unit and provenance, and the dynamics' assumed defaults.

A parameter set is a mapping from name to :class:`Parameter`.  Names carry the
unit (``L0_m``, ``valve_C_m3_per_s_Pa``); the paper's polynomial coefficients keep
the paper's units (pressure in bar, contraction in metres) because the elements
convert at their edge.

The values of a muscle come from its muscle file (:mod:`pamsim.muscles`).  The
dynamics also need values that the static-model papers do not give for their
muscles (valve, dead volume, friction, damping, rating): :data:`DYNAMICS_DEFAULTS`
supplies them, each marked "assumed" with its reason, under whatever the muscle
file gives (:func:`dynamics_parameters`).  Only the Shadow muscle's file gives
them all, from its paper.
"""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType
from typing import Mapping

from .muscles import load_muscle
from .parameter_schema import LOCK_DEG, Parameter, ParameterSet, known_parameter


LOAD_MASS = Parameter(
    round(22.74 / 9.81, 6), "kg", "assumed: lower bound 1 g, about 1/280 of the paper's lightest load "
    "(the 2.74 N holder); lighter loads make the hanging mass's dynamics needlessly stiff (a 1e-12 kg load "
    "oscillates at MHz)", "hanging mass, holder included; start value: the paper's 22.74 N (Fig. 4)", lower=1e-3)
"""The hanging load's mass and its range: checked by ``pamsim.Scenario`` and, through the FMU's
generated variable table, by the FMU's ``load_mass_kg`` input."""


_SHADOW = "the Shadow 6 mm x 300 mm muscle's value (ACRA 2012 paper)"
DYNAMICS_DEFAULTS: Mapping[str, tuple[float, str]] = MappingProxyType({
    # Friction and damping: measured for the Shadow muscle only.
    "N2_N_per_bar_m2": (0.0, "assumed: no friction measured for this muscle in the sources; zero"),
    "N1_N_per_bar_m": (0.0, "assumed: no friction measured for this muscle in the sources; zero"),
    "N0_N_per_bar": (0.0, "assumed: no friction measured for this muscle in the sources; zero"),
    "phi_bar_per_kg": (1.0, "ACRA 2012 eq. (7), phi = -m; irrelevant while N0..N2 are zero"),
    "coulomb_constant_N": (0.0, "assumed: no friction measured for this muscle in the sources; zero"),
    "D1_N_s_per_m": (1.01, f"assumed: magnitude of {_SHADOW}, dissipative sign; no damping measured for this muscle"),
    "D2_N_s2_per_m2": (0.80, f"assumed: {_SHADOW}; no damping measured for this muscle"),
    # Chamber and valve: not part of a static model.
    "dead_volume_m3": (1.0e-6, "assumed: fittings and ~8 cm of 4 mm tube, as for the Shadow muscle"),
    "valve_C_m3_per_s_Pa": (1.0e-9, f"assumed: {_SHADOW} (a small solenoid valve)"),
    "valve_b": (0.3, "assumed: typical small valve, 0.3..0.4"),
    "valve_laminar_ratio": (0.999, "assumed: as Simscape's ISO 6358 block"),
    "rho0_kg_m3": (1.185, "ISO 6358 reference density"),
    "T0_K": (293.15, "ISO 6358 reference temperature"),
    "polytropic_index": (1.0, "assumed: isothermal (pamsim decision, docs/model.md)"),
    "T_supply_K": (293.15, "assumed: room temperature supply"),
    "R_J_per_kg_K": (287.05, "specific gas constant of dry air"),
    "p_atm_Pa": (101325.0, "standard atmosphere"),
    "g_m_s2": (9.81, "standard gravity"),
    "rated_pressure_gauge_Pa": (8.0e5, "assumed: the sources give no rating; 8 bar, above the highest test "
                                       "pressure they report (0.758 MPa)"),
    "stop_restitution": (0.0, "assumed: inelastic contact at both stops"),
})
"""name -> (value, source) of every dynamics value a muscle file may leave out."""

CHAMBER_DEFAULTS: Mapping[str, tuple[float | str, str]] = MappingProxyType({
    "law": ("polytropic", "pamsim's law before the choice existed: every earlier result stands"),
    "T_wall_K": (293.15, "assumed: room temperature, the default supply temperature (T_supply_K)"),
    "h_W_per_m2_K": (15.7, "assumed: no measured value for a McKibben muscle found; laminar heat transfer in a "
                           "6 mm tube, Nu_D = h D / k = 3.66 (fully developed laminar flow, uniform wall "
                           "temperature: Incropera and DeWitt, Fundamentals of Heat and Mass Transfer, eq. 8.55) "
                           "with k_air = 0.0257 W/(m K) at 20 C and D = 6 mm; within the 2..25 W/(m^2 K) of free "
                           "convection in gases (ibid., Table 1.1)"),
    "heat_capacity_ratio": (1.4, "dry air near 20 C: c_p / c_v = 1005 / 718 (ideal diatomic gas, 7/5)"),
})
"""``[chamber]`` key -> (default, source): the chamber's law and the parameters of the laws that need them
(isothermal: ``T_wall_K``; thermal: all three; polytropic: none, its index is ``polytropic_index``)."""

CHAMBER_LAW_KEYS: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "isothermal": ("T_wall_K",), "polytropic": (), "thermal": ("T_wall_K", "h_W_per_m2_K", "heat_capacity_ratio")})
"""The ``[chamber]`` keys each law takes besides ``law``."""


def dynamics_parameters(muscle: ParameterSet) -> ParameterSet:
    """A muscle's parameters completed with :data:`DYNAMICS_DEFAULTS` for what it does not give.

    The rest braid angle is bounded by the locking angle: the dynamics model a
    contracting muscle, whose upper stop is the braid lock.
    """
    entries = dict(muscle.entries)
    for name, (value, source) in DYNAMICS_DEFAULTS.items():
        if name not in entries:
            entries[name] = known_parameter(name, value, source)
    if "theta0_deg" in entries:
        entries["theta0_deg"] = replace(entries["theta0_deg"], upper=min(entries["theta0_deg"].upper, LOCK_DEG),
                                        upper_open=True)
    return ParameterSet(muscle.name, muscle.citation, entries)


def get_parameter_set(name: str) -> ParameterSet:
    """The dynamics' parameter set of a shipped muscle (or muscle file): its values, then the defaults.

    Raises
    ------
    pamsim.muscles.MuscleError
        For an unknown muscle.
    """
    return dynamics_parameters(load_muscle(name).parameters)
