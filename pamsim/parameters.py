"""Named parameter sets, each value with its unit and provenance.

A parameter set is a mapping from name to :class:`Parameter`.  Names carry the
unit (``L0_m``, ``valve_C_m3_per_s_Pa``); the paper's polynomial coefficients keep
the paper's units (pressure in bar, contraction in metres) because the elements
convert at their edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Mapping

from .references import REFERENCES

ACRA2012 = REFERENCES["acra2012"].short
BRAID_LOCK_DEG = math.degrees(math.acos(1.0 / math.sqrt(3.0)))
"""Braid angle at which a McKibben braid locks (54.7356 deg): the muscle cannot shorten further."""


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
        return out

    def table(self) -> list[tuple[str, float, str, str, str]]:
        """Rows ``(name, value, unit, source, description)`` for docs and CLI."""
        return [(k, p.value, p.unit, p.source, p.description) for k, p in self.entries.items()]


def _shadow_6x300_acra2012() -> ParameterSet:
    P = Parameter
    e = {
        # Static force, eq. (3)/(11): F = (K1 x^2 + K2 x + C1) P_bar + S1 x^2 + S2 x + S3.
        "K1_N_per_bar_m2": P(-476.95, "N/(bar m^2)", f"{ACRA2012} eq. (11)", "static force: pressure term, x^2 coefficient"),
        "K2_N_per_bar_m": P(-188.39, "N/(bar m)", f"{ACRA2012} eq. (11)", "static force: pressure term, x coefficient"),
        "C1_N_per_bar": P(23.90, "N/bar", f"{ACRA2012} eq. (11)", "static force: pressure term, constant"),
        "S1_N_per_m2": P(2562.4, "N/m^2", f"{ACRA2012} eq. (11)", "static force: elastic term, x^2 coefficient"),
        "S2_N_per_m": P(-245.48, "N/m", f"{ACRA2012} eq. (11)", "static force: elastic term, x coefficient"),
        "S3_N": P(-11.56, "N", f"{ACRA2012} eq. (11)", "static force: elastic term, constant"),
        # Coulomb friction, eq. (7): F_c = (P_bar + phi)(N2 x^2 + N1 x + N0), phi = -m.
        "N2_N_per_bar_m2": P(228.93, "N/(bar m^2)", f"{ACRA2012} Table 4 (3.6 bar, 22.74 N)", "Coulomb level: x^2 coefficient"),
        "N1_N_per_bar_m": P(-90.43, "N/(bar m)", f"{ACRA2012} Table 4 (3.6 bar, 22.74 N)", "Coulomb level: x coefficient"),
        "N0_N_per_bar": P(6.87, "N/bar", f"{ACRA2012} Table 4 (3.6 bar, 22.74 N)", "Coulomb level: constant"),
        "phi_bar_per_kg": P(1.0, "bar/kg", f"{ACRA2012} eq. (7), text: phi(F_ext) = -m", "load correction: phi = -phi_bar_per_kg * m"),
        "coulomb_constant_N": P(2.5, "N", f"{ACRA2012} sec. 3.4, after Chou and Hannaford (1996)", "constant-friction comparison model", lower=0.0),
        # Viscous damping, eq. (8) (form lost in extraction; literal reading, MODEL_NOTES sec. 3).
        "D1_N_s_per_m": P(-1.01, "N s/m", f"{ACRA2012} Table 4", "damping: linear coefficient (air shear)"),
        "D2_N_s2_per_m2": P(0.80, "N s^2/m^2", f"{ACRA2012} Table 4", "damping: quadratic coefficient (skin friction)"),
        # Geometry.
        "L0_m": P(0.300, "m", f"{ACRA2012} sec. 3 (Shadow 6 mm x 300 mm muscle)", "nominal (preloaded rest) length", lower=0.0, lower_open=True),
        "D0_m": P(0.006, "m", f"{ACRA2012} sec. 3 (Shadow 6 mm x 300 mm muscle)", "rest diameter", lower=0.0, lower_open=True),
        "braid_angle_rest_deg": P(20.0, "deg", "assumed: MODEL_NOTES sec. 6; gives 8.5 cm^3 at rest and ~3x at 75 mm", "braid angle to the axis at rest length", lower=0.0, upper=BRAID_LOCK_DEG, lower_open=True, upper_open=True),
        "dead_volume_m3": P(1.0e-6, "m^3", "assumed: fittings and ~8 cm of 4 mm tube between valve and muscle", "volume between valve and muscle", lower=0.0),
        # Valve, ISO 6358 (not in the paper; MODEL_NOTES sec. 6).
        "valve_C_m3_per_s_Pa": P(1.0e-9, "m^3/(s Pa)", "assumed: small solenoid valve, low end of 1e-9..4e-9 (MODEL_NOTES sec. 6); the paper's transients last seconds", "sonic conductance", lower=0.0),
        "valve_b": P(0.3, "1", "assumed: typical small valve, 0.3..0.4 (MODEL_NOTES sec. 6)", "critical pressure ratio", lower=0.0, upper=1.0, upper_open=True),
        "valve_laminar_ratio": P(0.999, "1", "assumed: as Simscape's ISO 6358 block (MODEL_NOTES sec. 6)", "pressure ratio above which flow is laminar (linear)", lower=0.0, upper=1.0, lower_open=True, upper_open=True),
        "rho0_kg_m3": P(1.185, "kg/m^3", "ISO 6358 reference density", "reference density", lower=0.0, lower_open=True),
        "T0_K": P(293.15, "K", "ISO 6358 reference temperature", "reference temperature", lower=0.0, lower_open=True),
        # Chamber.
        "polytropic_index": P(1.0, "1", "assumed: isothermal; thin-walled 6 mm tube, transients of seconds (pamsim decision, docs/model.md)", "1 = isothermal, 1.4 = adiabatic", lower=1.0),
        "T_supply_K": P(293.15, "K", "assumed: room temperature supply", "supply air temperature", lower=0.0, lower_open=True),
        "R_J_per_kg_K": P(287.05, "J/(kg K)", "specific gas constant of dry air", "gas constant", lower=0.0, lower_open=True),
        "p_atm_Pa": P(101325.0, "Pa", "standard atmosphere", "ambient (exhaust) pressure", lower=0.0, lower_open=True),
        # Load and ranges.
        "g_m_s2": P(9.81, "m/s^2", f"{ACRA2012} (2.74 N holder; 10 N steps)", "gravity", lower=0.0, lower_open=True),
        "rated_pressure_gauge_Pa": P(4.5e5, "Pa", "assumed: paper tested to 4.07 bar (Table 1); 10 % margin, no datasheet in the sources", "highest supply pressure accepted", lower=0.0, lower_open=True),
        "fit_x_min_m": P(-0.1e-3, "m", f"{ACRA2012} Table 2 (smallest measured contraction)", "fitted range of the polynomial: lowest contraction"),
        "fit_x_max_m": P(0.076, "m", f"{ACRA2012} Table 2 (largest measured contraction 75 mm)", "fitted range of the polynomial: highest contraction"),
        "fit_p_max_Pa": P(4.1e5, "Pa", f"{ACRA2012} Table 1 (highest stable pressure 4.07 bar)", "fitted range of the polynomial: highest pressure"),
        # End stops (MODEL_NOTES sec. 5).
        "stop_restitution": P(0.0, "1", "assumed: inelastic contact; Table 2 shows the loaded muscle resting on a very stiff stop", "coefficient of restitution of both stops", lower=0.0, upper=1.0),
    }
    return ParameterSet("shadow_6x300_acra2012", "Shadow Robot 6 mm x 300 mm muscle, " + REFERENCES["acra2012"].full(), e)


PARAMETER_SETS: Mapping[str, ParameterSet] = MappingProxyType({
    "shadow_6x300_acra2012": _shadow_6x300_acra2012(),
})


def get_parameter_set(name: str) -> ParameterSet:
    """Return a registered parameter set by name (KeyError if unknown)."""
    return PARAMETER_SETS[name]


def braid_geometry(params: Mapping[str, float]) -> tuple[float, float]:
    """Thread length b [m] and number of turns n [-] from L0, D0 and the rest braid angle."""
    theta = math.radians(params["braid_angle_rest_deg"])
    b = params["L0_m"] / math.cos(theta)
    n = b * math.sin(theta) / (math.pi * params["D0_m"])
    return b, n
