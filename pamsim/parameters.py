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

import math
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Mapping

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
        if "valve_b" in v and "valve_laminar_ratio" in v and not v["valve_b"] < v["valve_laminar_ratio"]:
            out.append(("valve_b", v["valve_b"], f"must be below valve_laminar_ratio = {v['valve_laminar_ratio']:g}"))
        if "fit_x_min_m" in v and "fit_x_max_m" in v and not v["fit_x_min_m"] < v["fit_x_max_m"]:
            out.append(("fit_x_min_m", v["fit_x_min_m"], f"must be below fit_x_max_m = {v['fit_x_max_m']:g}"))
        if "wall_thickness_m" in v and "r0_m" in v and not v["r0_m"] > v["wall_thickness_m"]:
            out.append(("r0_m", v["r0_m"], f"must exceed the bladder wall thickness wall_thickness_m = "
                        f"{v['wall_thickness_m']:g}"))
        return out

    def table(self) -> list[tuple[str, float, str, str, str]]:
        """Rows ``(name, value, unit, source, description)`` for docs and CLI."""
        return [(k, p.value, p.unit, p.source, p.description) for k, p in self.entries.items()]




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


def dynamics_parameters(muscle: ParameterSet) -> ParameterSet:
    """A muscle's parameters completed with :data:`DYNAMICS_DEFAULTS` for what it does not give.

    The rest braid angle is bounded by the locking angle: the dynamics model a
    contracting muscle, whose upper stop is the braid lock.
    """
    from .muscles.schema import LOCK_DEG  # pamsim.muscles imports this module: imported late

    entries = dict(muscle.entries)
    for name, (value, source) in DYNAMICS_DEFAULTS.items():
        if name not in entries:
            entries[name] = known_parameter(name, value, source)
    if "theta0_deg" in entries:
        entries["theta0_deg"] = replace(entries["theta0_deg"], upper=min(entries["theta0_deg"].upper, LOCK_DEG),
                                        upper_open=True)
    return ParameterSet(muscle.name, muscle.citation, entries)


def known_parameter(name: str, value: float, source: str) -> Parameter:
    """A :class:`Parameter` of a known name (unit, range and meaning from the muscle schema)."""
    from .muscles.schema import KNOWN, unit_of

    k = KNOWN[name]
    return Parameter(float(value), unit_of(name), source, k.description, k.lower, k.upper, k.lower_open, k.upper_open)


def get_parameter_set(name: str) -> ParameterSet:
    """The dynamics' parameter set of a shipped muscle (or muscle file): its values, then the defaults.

    Raises
    ------
    pamsim.muscles.MuscleError
        For an unknown muscle.
    """
    from .muscles import load_muscle  # the muscle loader builds ParameterSets: imported late

    return dynamics_parameters(load_muscle(name).parameters)
