"""The parameter schema: every parameter name a muscle file may give, with its unit (read from the
name), bounds and meaning, and the :class:`Parameter` and :class:`ParameterSet` types that carry
values with them.

The unit of every name is read from its suffix (``_m``, ``_Pa``, ``_deg``,
``_N_per_bar_m2`` ...; no suffix means dimensionless) by :func:`unit_of`.
Bounds are physical limits, not typical values.

Muscle files (:mod:`pamsim.muscles`) are read into these types and the dynamics' parameter sets
(:mod:`pamsim.parameters`) are built from them; both import this module and neither imports the
other for it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Mapping

from .core_table import BRAID_LOCK_SEC2, ORDER_CHECKS

INF = math.inf
LOCK_DEG = math.degrees(math.acos(1.0 / math.sqrt(BRAID_LOCK_SEC2)))
"""Braid angle from the axis at which the braid locks (54.7356 deg)."""

SUFFIX_UNITS = (  # longest first: "_N_per_bar_m2" before "_m2" before "_m"
    ("_N_per_bar_m2", "N/(bar m^2)"), ("_N_per_bar_m", "N/(bar m)"), ("_N_per_bar", "N/bar"),
    ("_N_s2_per_m2", "N s^2/m^2"), ("_N_s_per_m", "N s/m"), ("_N_per_m2", "N/m^2"), ("_N_per_m", "N/m"),
    ("_N_per_Pa", "N/Pa"), ("_m3_per_s_Pa", "m^3/(s Pa)"), ("_J_per_kg_K", "J/(kg K)"), ("_bar_per_kg", "bar/kg"),
    ("_W_per_m2_K", "W/(m^2 K)"), ("_m2_per_Pa", "m^2/Pa"), ("_per_Pa", "1/Pa"), ("_per_K", "1/K"), ("_kg_m3", "kg/m^3"), ("_m_s2", "m/s^2"),
    ("_N_s", "N s"), ("_Pa_s", "Pa s"), ("_m_s", "m/s"), ("_Hz", "Hz"), ("_s", "s"), ("_Pa", "Pa"), ("_m3", "m^3"),
    ("_m2", "m^2"), ("_deg", "deg"), ("_N", "N"), ("_K", "K"), ("_m", "m"),
)


def unit_of(name: str) -> str:
    """Unit of a parameter, read from the suffix of its name ("1" when it has none)."""
    for suffix, unit in SUFFIX_UNITS:
        if name.endswith(suffix):
            return unit
    return "1"


@dataclass(frozen=True)
class Known:
    """Bounds and meaning of one known parameter name (``*_open`` excludes the bound)."""

    description: str
    lower: float = -INF
    upper: float = INF
    lower_open: bool = False
    upper_open: bool = False


def _pos(description: str) -> Known:
    return Known(description, 0.0, INF, True)


def _nonneg(description: str) -> Known:
    return Known(description, 0.0)


def _any(description: str) -> Known:
    return Known(description)


KNOWN = MappingProxyType({
    # Shared geometry and materials.
    "L0_m": _pos("rest length"),
    "r0_m": _pos("braid (= bladder outer) radius at rest"),
    "ri0_m": _pos("bladder inner radius at rest"),
    "wall_thickness_m": _pos("bladder wall thickness at rest"),
    "theta0_deg": Known("rest braid angle from the muscle axis", 0.0, 90.0, True, True),
    "n_fibres": _pos("number of braid fibres (strands)"),
    "fibre_area_m2": _pos("cross-sectional area of one braid fibre"),
    "fibre_radius_m": _pos("radius of one braid fibre (strand)"),
    "fibre_width_m": _pos("width of one braid fibre across the braid's surface (a flat yarn's; a round strand's "
                          "is twice fibre_radius_m)"),
    "braid_area_fraction": Known("fraction of the cross-section taken by the braid material", 0.0, 1.0, True),
    "E_braid_Pa": _pos("Young's modulus of the braid fibres"),
    "E_bladder_Pa": _nonneg("Young's modulus of the bladder"),
    "nu_bladder": Known("Poisson ratio of the bladder", -1.0, 0.5, True, True),
    "C10_Pa": _any("Mooney-Rivlin constant C10"),
    "C01_Pa": _any("Mooney-Rivlin constant C01"),
    "ogden_mu1_Pa": _any("Ogden modulus of term 1"), "ogden_alpha1": _any("Ogden exponent of term 1"),
    "ogden_mu2_Pa": _any("Ogden modulus of term 2"), "ogden_alpha2": _any("Ogden exponent of term 2"),
    "ogden_mu3_Pa": _any("Ogden modulus of term 3"), "ogden_alpha3": _any("Ogden exponent of term 3"),
    "E_nylon_Pa": _pos("Young's modulus of the nylon braid strands (two-phase model)"),
    "sleeve_gap_m": _nonneg("radial gap between tube and braided sleeve at rest"),
    "end_cone_length_m": _nonneg("length of each fully contacting conical end"),
    "two_phase_F_u_N": _any("two-phase model: unaccounted axial force F_u (survey eq. 71), taken off the pull"),
    "rated_pressure_gauge_Pa": _pos("highest supply pressure accepted (gauge)"),
    # de Volder (survey eq. 35).
    "devolder_P_corr_Pa": _any("de Volder dead-band pressure"),
    "devolder_l_corr_m": _any("de Volder length correction"),
    "devolder_F_min_N": _any("de Volder force floor (<= 0 stops pushing forces)"),
    "devolder_k_b_N_per_m": _nonneg("de Volder bladder spring stiffness"),
    "devolder_l_b0_m": _any("de Volder length above which the bladder spring engages"),
    # Hocking, Pillsbury, Sangian (survey eqs. 37, 39, 40).
    "hocking_E2_Pa": _any("Hocking stress polynomial, quadratic coefficient"),
    "hocking_E3_Pa": _any("Hocking stress polynomial, cubic coefficient"),
    "hocking_P_c_Pa": _any("Hocking dead-band pressure"),
    "pillsbury_E1I_Pa": _any("Pillsbury linear modulus, pressure-independent part"),
    "pillsbury_E1S": _any("Pillsbury linear modulus, pressure coefficient"),
    "pillsbury_E2I_Pa": _any("Pillsbury quadratic modulus, pressure-independent part"),
    "pillsbury_E2S": _any("Pillsbury quadratic modulus, pressure coefficient"),
    "sangian_Pbar_Pa": _any("Sangian threshold (dead-band) pressure"),
    # Normalised-Gaylord models with fitted factors and empirical laws (survey eqs. 6, 13, 14, 33, 41, 43, 44, 46-49).
    "tondu_kappa1": _any("Tondu-Lopez k_eps: amplitude of the exponential"),
    "tondu_kappa2": _any("Tondu-Lopez k_eps: constant"),
    "tondu_pressure_unit_Pa": _pos("Tondu-Lopez k_eps: pressure unit of exp(-p)"),
    "itto_kappa1": _any("Itto k_eps: amplitude"), "itto_kappa2_per_Pa": _any("Itto k_eps: pressure rate"),
    "itto_kappa3": _any("Itto k_eps: constant (text form)"),
    "meller_kappa1_m2": _any("Meller blocked force: slope in pressure"), "meller_kappa2_N": _any("Meller blocked force: offset"),
    "meller_kappa3": _any("Meller free contraction per ln(p/p_u)"),
    "meller_pressure_unit_Pa": _pos("Meller: pressure unit of ln(p)"),
    "andrikopoulos_F_max_N": _pos("Andrikopoulos calibration: blocked force at P_test"),
    "andrikopoulos_x_max_m": _pos("Andrikopoulos calibration: free stroke at P_test"),
    "andrikopoulos_P_test_Pa": _pos("Andrikopoulos calibration pressure"),
    "alpha_l_per_K": _any("thermal expansion coefficient of the bladder"),
    "delta_T_K": _any("temperature change from the calibration"),
    **{f"takosoglu_kappa{i}": _any(f"Takosoglu constant kappa{i}") for i in (1, 3, 4, 6)},
    "takosoglu_kappa2_Pa": _pos("Takosoglu exponent: pressure scale"), "takosoglu_kappa5_Pa": _pos("Takosoglu q1: pressure scale"),
    "bundle_kappa1_m2": _any("muscle-bundle law kappa1"), "bundle_kappa2_N": _any("muscle-bundle law kappa2"),
    "bundle_kappa3_m2": _any("muscle-bundle law kappa3"),
    **{f"emp46_k{i}_m2": _any(f"empirical eq. (46) k{i}") for i in (1, 2, 3)},
    **{f"emp46_k{i}_N": _any(f"empirical eq. (46) k{i}") for i in (4, 5, 6, 7, 8)},
    **{f"emp47_k{i}_N": _any(f"empirical eq. (47) k{i}") for i in (1, 2, 3)},
    **{f"emp47_k{i}_m2": _any(f"empirical eq. (47) k{i}") for i in (4, 5)},
    "emp48_k1_m2_per_Pa": _any("empirical eq. (48) k1"), "emp48_k2_m2": _any("empirical eq. (48) k2"),
    "emp48_k3_N": _any("empirical eq. (48) k3"), "emp48_k4_m2": _any("empirical eq. (48) k4"), "emp48_k5_N": _any("empirical eq. (48) k5"),
    "emp49_k1": _any("empirical eq. (49) k1"), "emp49_Fmax_N": _any("empirical eq. (49) F_max"),
    "emp49_eps_max": Known("empirical eq. (49) eps_max", 0.0, 1.0, True, True),
    # ACRA 2012 polynomial, friction, damping (the Shadow muscle).
    "K1_N_per_bar_m2": _any("static force: pressure term, x^2 coefficient"),
    "K2_N_per_bar_m": _any("static force: pressure term, x coefficient"),
    "C1_N_per_bar": _any("static force: pressure term, constant"),
    "S1_N_per_m2": _any("static force: elastic term, x^2 coefficient"),
    "S2_N_per_m": _any("static force: elastic term, x coefficient"),
    "S3_N": _any("static force: elastic term, constant"),
    "N2_N_per_bar_m2": _any("Coulomb level: x^2 coefficient"),
    "N1_N_per_bar_m": _any("Coulomb level: x coefficient"),
    "N0_N_per_bar": _any("Coulomb level: constant"),
    "phi_bar_per_kg": _any("load correction: phi = -phi_bar_per_kg * m"),
    "coulomb_constant_N": _nonneg("constant-friction comparison model"),
    "D1_N_s_per_m": _any("damping: linear coefficient (air shear)"),
    "D2_N_s2_per_m2": _any("damping: quadratic coefficient (skin friction)"),
    # Dynamics: chamber, valve, gas, load, ranges, stops.
    "dead_volume_m3": _nonneg("volume between valve and muscle"),
    "valve_C_m3_per_s_Pa": _nonneg("sonic conductance"),
    "valve_b": Known("critical pressure ratio", 0.0, 1.0, False, True),
    "valve_laminar_ratio": Known("pressure ratio above which flow is laminar (linear)", 0.0, 1.0, True, True),
    "rho0_kg_m3": _pos("reference density"),
    "T0_K": _pos("reference temperature"),
    "polytropic_index": Known("1 = isothermal, 1.4 = adiabatic", 1.0),
    "T_supply_K": _pos("supply air temperature"),
    "R_J_per_kg_K": _pos("gas constant"),
    "p_atm_Pa": _pos("ambient (exhaust) pressure"),
    "g_m_s2": _pos("gravity"),
    "fit_x_min_m": _any("fitted range of the polynomial: lowest contraction"),
    "fit_x_max_m": _any("fitted range of the polynomial: highest contraction"),
    "fit_p_max_Pa": _any("fitted range of the polynomial: highest pressure"),
    "stop_restitution": Known("coefficient of restitution of both stops", 0.0, 1.0),
})
"""name -> :class:`Known` for every parameter a muscle file may give."""

UPPER_STOPS = {
    "auto": "the braid's jam angle if the muscle gives its fibres' width and count, else the end of the "
            "static model's domain",
    "jam": "the braid's jam angle, where neighbouring fibres touch (needs n_fibres and fibre_width_m or "
           "fibre_radius_m), or the end of the static model's domain if that comes first",
    "domain_end": "the end of the static model's domain (the braid lock if the domain has no finite end)",
    "braid_lock": "the braid-lock angle 54.7356 deg, where Gaylord's ideal force vanishes",
}
"""Choice of where the upper stop stands -> where that is: a muscle file's ``[upper_stop] at``, a scenario's
``[model] upper_stop``, ``pamsim static --upper-stop`` (:meth:`pamsim.elements.stops.EndStops.for_model`)."""

UPPER_BASES = {"jam": "the braid's jam angle", "domain_end": "the end of the static model's domain",
               "braid_lock": "the braid lock, 54.7356 deg"}
"""What placed an upper stop (:attr:`pamsim.elements.stops.EndStops.upper_basis`), in words."""

UPPER_STOP_DEFAULT = "auto"
"""The choice of a muscle file that names none."""


FILE_INPUTS = ("force_map_file",)
"""Model inputs that are files, not numbers (given by a muscle file's top-level ``force_map`` key)."""


@dataclass(frozen=True)
class Parameter:
    """One parameter value with its unit, provenance, meaning and physical range.

    ``lower``/``upper`` bound the value; ``*_open`` excludes the bound itself.
    The FMU's C parameter check is generated from the same bounds.
    """

    value: float
    unit: str
    source: str
    description: str
    lower: float = -math.inf
    upper: float = math.inf
    lower_open: bool = False
    upper_open: bool = False

    def violation(self, value: float) -> str | None:
        """Why ``value`` is out of range, or None."""
        if not math.isfinite(value):
            return "must be a finite number"
        low_bad = value <= self.lower if self.lower_open else value < self.lower
        high_bad = value >= self.upper if self.upper_open else value > self.upper
        if not (low_bad or high_bad):
            return None
        if not math.isfinite(self.upper):
            return f"must be {'>' if self.lower_open else '>='} {self.lower:g}"
        if not math.isfinite(self.lower):
            return f"must be {'<' if self.upper_open else '<='} {self.upper:g}"
        lo = ("(" if self.lower_open else "[") + f"{self.lower:g}"
        hi = f"{self.upper:g}" + (")" if self.upper_open else "]")
        return f"must lie in {lo}, {hi}"


class ParameterSet(Mapping[str, float]):
    """An immutable, named set of parameters; reads as ``{name: value}``.

    ``with_overrides`` returns a new set, so scenarios never mutate the
    registered sets.
    """

    def __init__(self, name: str, citation: str, entries: Mapping[str, Parameter]):
        self.name = name
        self.citation = citation
        self.entries: Mapping[str, Parameter] = MappingProxyType(dict(entries))

    def __reduce__(self):
        # A read-only mapping proxy does not pickle; a plain dict rebuilds it (process pools).
        return ParameterSet, (self.name, self.citation, dict(self.entries))

    def __getitem__(self, key: str) -> float:
        return self.entries[key].value

    def __iter__(self):
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self.entries)

    def with_overrides(self, overrides: Mapping[str, float], source: str = "override") -> "ParameterSet":
        """Return a copy with some values replaced; unknown names raise KeyError."""
        entries = dict(self.entries)
        for key, value in overrides.items():
            if key not in entries:
                raise KeyError(key)
            entries[key] = replace(entries[key], value=float(value), source=source)
        return ParameterSet(self.name, self.citation, entries)

    def violations(self) -> list[tuple[str, float, str]]:
        """``(name, value, reason)`` for every value outside its range or inconsistent with another."""
        out = [(k, p.value, why) for k, p in self.entries.items() if (why := p.violation(p.value))]
        if out:
            return out
        v = self
        for a, b in ORDER_CHECKS:
            if a in v and b in v and not v[a] < v[b]:
                out.append((a, v[a], f"must be below {b} = {v[b]:g}"))
        if "wall_thickness_m" in v and "r0_m" in v and not v["r0_m"] > v["wall_thickness_m"]:
            out.append(("r0_m", v["r0_m"], f"must exceed the bladder wall thickness wall_thickness_m = "
                        f"{v['wall_thickness_m']:g}"))
        return out

    def table(self) -> list[tuple[str, float, str, str, str]]:
        """Rows ``(name, value, unit, source, description)`` for docs and CLI."""
        return [(k, p.value, p.unit, p.source, p.description) for k, p in self.entries.items()]


def known_parameter(name: str, value: float, source: str) -> Parameter:
    """A :class:`Parameter` of a known name (unit, range and meaning from the muscle schema)."""
    k = KNOWN[name]
    return Parameter(float(value), unit_of(name), source, k.description, k.lower, k.upper, k.lower_open, k.upper_open)
