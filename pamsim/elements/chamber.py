"""The muscle as a gas chamber: volume and wall area from braid geometry, and three laws for its gas.

Geometry (Chou and Hannaford; MODEL_NOTES sec. 6), with L = L0 - x, thread length b and n turns: the
braid is a cylinder of length L and radius ``r = sqrt(b^2 - L^2) / (2 pi n)``, so::

    V(x) = pi r^2 L + V_dead = L (b^2 - L^2) / (4 pi n^2) + V_dead
    A(x) = 2 pi r L + 2 pi r^2        (the cylinder's inner surface: its side and two ends)

The dead volume (fittings, tube) has no wall area here: its air exchanges heat through the muscle's.

Every law has the states absolute pressure p and air mass m (``dm/dt = mdot``, the summed inflow), and
the gas temperature ``T = p V / (m R)``.  What differs is the pressure's rate, with the flow work
``R T_in mdot`` summed over the flows (T_in: the supply temperature for an inflow, the chamber gas
temperature for an outflow):

- :class:`MuscleChamber`, **polytropic** (index n_p)::

      dp/dt = n_p (R T_in mdot - p dV/dt) / V

  With n_p = 1.4 this is the adiabatic energy balance of an open chamber; with n_p = 1 the gas stays at
  the supply temperature and ``p V = m R T`` holds exactly, which the tests use as a mass balance.
- :class:`IsothermalChamber`, **isothermal**: the gas is held at the wall temperature,
  ``p V = m R T_wall``::

      dp/dt = (R T_wall mdot - p dV/dt) / V

- :class:`ThermalChamber`, **thermal**: the energy equation of the open chamber (internal energy
  ``U = m c_v T = p V / (gamma - 1)``, enthalpy ``c_p T_in`` per kg of each flow, boundary work
  ``p dV/dt``, heat ``Q = h A(x) (T_wall - T)`` from the wall)::

      dU/dt = c_p T_in mdot - p dV/dt + Q
      dp/dt = gamma (R T_in mdot - p dV/dt) / V + (gamma - 1) Q / V

  the second line being the first with ``c_p = gamma R / (gamma - 1)``.  With h = 0 it is the
  polytropic law with n_p = gamma.

Each law is a mixin (:class:`PolytropicLaw`, :class:`IsothermalLaw`, :class:`ThermalLaw`) over a
geometry: the braid's cylinder (:class:`BraidCylinder`, the muscle's chamber) or a rigid volume
(:class:`RigidVessel`: a reservoir, a tube's bore; ``V`` constant, ``dV/dt = 0``), so a reservoir's gas
follows the muscle's laws written once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from ..static_models.geometry import Braid


class IdealGas:
    """The gas of a volume as an ideal gas: what every law and every geometry shares.  A mixin of a
    dataclass with the field ``R_J_per_kg_K``."""

    def gas_temperature_K(self, p_abs_Pa, volume_m3, air_mass_kg):
        """Gas temperature [K] of the air mass at absolute pressure and volume: ``p V / (m R)``."""
        return p_abs_Pa * volume_m3 / (air_mass_kg * self.R_J_per_kg_K)

    def air_mass_kg(self, p_abs_Pa, volume_m3, T_K):
        """Air mass [kg] of the ideal gas at absolute pressure, volume and temperature: ``p V / (R T)``."""
        return p_abs_Pa * volume_m3 / (self.R_J_per_kg_K * T_K)

    def flow_work_W(self, inflow_kg_s, T_inflow_K):
        """``R T_in mdot``: the flow work an inflow at ``T_inflow_K`` brings in [W]."""
        return self.R_J_per_kg_K * T_inflow_K * inflow_kg_s

    def pressure_rate_Pa_s(self, p_abs_Pa, volume_m3, dvolume_dt_m3_s, inflow_kg_s, T_inflow_K,
                           air_mass_kg=None, x_m=None):
        """Rate of the absolute pressure [Pa/s] for the volume's rate of change and an inflow [kg/s] at
        ``T_inflow_K``; ``air_mass_kg`` and ``x_m``: for the laws that need them (the thermal law's heat).
        """
        return self.pressure_rate_of_flows_Pa_s(p_abs_Pa, volume_m3, dvolume_dt_m3_s, inflow_kg_s,
                                                self.flow_work_W(inflow_kg_s, T_inflow_K), air_mass_kg, x_m)


class BraidCylinder(IdealGas):
    """The chamber's geometry: the braid's cylinder.  A mixin of a dataclass with the fields ``L0_m``,
    ``thread_length_m``, ``turns``, ``dead_volume_m3`` and ``R_J_per_kg_K``, and a law's
    ``pressure_rate_of_flows_Pa_s`` and ``start_temperature_K`` (:class:`PolytropicLaw`,
    :class:`IsothermalLaw`, :class:`ThermalLaw`)."""

    def volume_m3(self, x_m):
        """Chamber volume [m^3] at contraction ``x_m``: the braid's cylinder plus the dead volume."""
        L = self.L0_m - x_m
        return L * (self.thread_length_m ** 2 - L * L) / (4.0 * math.pi * self.turns ** 2) + self.dead_volume_m3

    def dvolume_dx_m2(self, x_m):
        """Derivative of the volume with respect to contraction, ``dV/dx`` [m^2]."""
        L = self.L0_m - x_m
        return -(self.thread_length_m ** 2 - 3.0 * L * L) / (4.0 * math.pi * self.turns ** 2)

    def radius_m(self, x_m):
        """Radius [m] of the braid's cylinder at contraction ``x_m``: ``sqrt(b^2 - L^2) / (2 pi n)``."""
        L = self.L0_m - x_m
        return (self.thread_length_m ** 2 - L * L) ** 0.5 / (2.0 * math.pi * self.turns)

    def wall_area_m2(self, x_m):
        """Inner surface [m^2] of the braid's cylinder at contraction ``x_m``: its side ``2 pi r L`` and its
        two ends ``2 pi r^2``, the cylinder whose volume :meth:`volume_m3` gives."""
        r = self.radius_m(x_m)
        return 2.0 * math.pi * r * (self.L0_m - x_m + r)


class RigidVessel(IdealGas):
    """A rigid volume (a reservoir, a tube's bore): a mixin of a dataclass with the fields
    ``vessel_volume_m3`` and ``R_J_per_kg_K`` (and ``vessel_area_m2`` for the thermal law), and a law.
    Its volume and wall do not move; the argument ``x_m`` of the geometry's methods is ignored, so that a
    law reads a vessel as it reads the muscle's chamber."""

    def volume_m3(self, x_m=0.0):
        """The vessel's volume [m^3], whatever ``x_m``."""
        return self.vessel_volume_m3

    def dvolume_dx_m2(self, x_m=0.0):
        """Zero: the volume does not move."""
        return 0.0

    def wall_area_m2(self, x_m=0.0):
        """The vessel's inner surface [m^2] (the thermal law's heat goes through it)."""
        return self.vessel_area_m2


class PolytropicLaw:
    """The polytropic law (index ``polytropic_index``): a mixin of a geometry's dataclass."""

    law = "polytropic"

    def start_temperature_K(self, T_supply_K):
        """Gas temperature [K] at the start: the supply's (the chamber was last filled from it)."""
        return T_supply_K

    def pressure_rate_of_flows_Pa_s(self, p_abs_Pa, volume_m3, dvolume_dt_m3_s, inflow_kg_s, flow_work_W,
                                    air_mass_kg=None, x_m=None):
        """``n (R T_in mdot - p dV/dt) / V`` [Pa/s]; the inflow, air mass and contraction do not enter."""
        return self.pressure_rate_from_flow_work_Pa_s(p_abs_Pa, volume_m3, dvolume_dt_m3_s, flow_work_W)

    def pressure_rate_from_flow_work_Pa_s(self, p_abs_Pa, volume_m3, dvolume_dt_m3_s, flow_work_W):
        """``n (R T_in mdot - p dV/dt) / V`` from the summed flow work of every inflow [Pa/s]."""
        return self.polytropic_index * (flow_work_W - p_abs_Pa * dvolume_dt_m3_s) / volume_m3


class IsothermalLaw:
    """The isothermal law: the gas at the wall temperature ``T_wall_K``, ``p V = m R T_wall``; a mixin of
    a geometry's dataclass."""

    law = "isothermal"

    def start_temperature_K(self, T_supply_K):
        """Gas temperature [K] at the start: the wall's."""
        return self.T_wall_K

    def gas_temperature_K(self, p_abs_Pa, volume_m3, air_mass_kg):
        """Gas temperature [K]: the wall's, as the law has it (``p V / (m R)`` equals it along a run to the
        integrator's tolerance).  An outflow carries it; taken as ``p V / (m R)`` it tied the pressure's rate to
        the air mass, which the law's ``p V = m R T_wall`` already fixes, and a linearisation kept the air mass
        as a state with a pole at 0."""
        return self.T_wall_K + 0.0 * p_abs_Pa

    def pressure_rate_of_flows_Pa_s(self, p_abs_Pa, volume_m3, dvolume_dt_m3_s, inflow_kg_s, flow_work_W,
                                    air_mass_kg=None, x_m=None):
        """``(R T_wall mdot - p dV/dt) / V`` [Pa/s]: every flow at the wall temperature, whatever it brings."""
        return (self.R_J_per_kg_K * self.T_wall_K * inflow_kg_s - p_abs_Pa * dvolume_dt_m3_s) / volume_m3


class ThermalLaw:
    """The thermal law: the energy equation with the flows' enthalpy, the boundary work and the heat
    ``h A(x) (T_wall - T)`` from the wall; ``heat_capacity_ratio`` is gamma = c_p / c_v.  A mixin of a
    geometry's dataclass."""

    law = "thermal"

    def start_temperature_K(self, T_supply_K):
        """Gas temperature [K] at the start: the wall's (the gas has rested against it)."""
        return self.T_wall_K

    def wall_heat_W(self, p_abs_Pa, volume_m3, air_mass_kg, x_m):
        """Heat [W] the wall gives the gas: ``h A(x) (T_wall - T)``."""
        T = self.gas_temperature_K(p_abs_Pa, volume_m3, air_mass_kg)
        return self.h_W_per_m2_K * self.wall_area_m2(x_m) * (self.T_wall_K - T)

    def pressure_rate_of_flows_Pa_s(self, p_abs_Pa, volume_m3, dvolume_dt_m3_s, inflow_kg_s, flow_work_W,
                                    air_mass_kg=None, x_m=None):
        """``gamma (R T_in mdot - p dV/dt) / V + (gamma - 1) Q / V`` [Pa/s]."""
        gamma = self.heat_capacity_ratio
        Q = self.wall_heat_W(p_abs_Pa, volume_m3, air_mass_kg, x_m)
        return (gamma * (flow_work_W - p_abs_Pa * dvolume_dt_m3_s) + (gamma - 1.0) * Q) / volume_m3


def _braid_fields(p: Mapping[str, float]) -> tuple:
    """``(L0_m, thread_length_m, turns, dead_volume_m3)`` of a muscle's parameters."""
    braid = Braid.from_parameters(p)
    return p["L0_m"], braid.b, braid.N, p["dead_volume_m3"]


@dataclass(frozen=True)
class MuscleChamber(PolytropicLaw, BraidCylinder):
    """The polytropic law: geometry, polytropic index and gas constant."""

    L0_m: float
    thread_length_m: float
    turns: float
    dead_volume_m3: float
    polytropic_index: float
    R_J_per_kg_K: float

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "MuscleChamber":
        """The chamber of a muscle's parameters (braid geometry, dead volume, polytropic index, gas constant)."""
        return cls(*_braid_fields(p), p["polytropic_index"], p["R_J_per_kg_K"])


@dataclass(frozen=True)
class IsothermalChamber(IsothermalLaw, BraidCylinder):
    """The isothermal law: the gas at the wall temperature ``T_wall_K``, ``p V = m R T_wall``."""

    L0_m: float
    thread_length_m: float
    turns: float
    dead_volume_m3: float
    R_J_per_kg_K: float
    T_wall_K: float

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], T_wall_K: float) -> "IsothermalChamber":
        """The chamber of a muscle's parameters (braid geometry, dead volume, gas constant) at ``T_wall_K``."""
        return cls(*_braid_fields(p), p["R_J_per_kg_K"], T_wall_K)


@dataclass(frozen=True)
class ThermalChamber(ThermalLaw, BraidCylinder):
    """The thermal law: the energy equation with the flows' enthalpy, the boundary work and the heat
    ``h A(x) (T_wall - T)`` from the wall; ``heat_capacity_ratio`` is gamma = c_p / c_v."""

    L0_m: float
    thread_length_m: float
    turns: float
    dead_volume_m3: float
    R_J_per_kg_K: float
    heat_capacity_ratio: float
    h_W_per_m2_K: float
    T_wall_K: float

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], heat_capacity_ratio: float, h_W_per_m2_K: float,
                        T_wall_K: float) -> "ThermalChamber":
        """The chamber of a muscle's parameters (braid geometry, dead volume, gas constant) and its heat
        transfer."""
        return cls(*_braid_fields(p), p["R_J_per_kg_K"], heat_capacity_ratio, h_W_per_m2_K, T_wall_K)


@dataclass(frozen=True)
class PolytropicVessel(PolytropicLaw, RigidVessel):
    """A rigid volume under the polytropic law."""

    vessel_volume_m3: float
    polytropic_index: float
    R_J_per_kg_K: float


@dataclass(frozen=True)
class IsothermalVessel(IsothermalLaw, RigidVessel):
    """A rigid volume under the isothermal law."""

    vessel_volume_m3: float
    R_J_per_kg_K: float
    T_wall_K: float


@dataclass(frozen=True)
class ThermalVessel(ThermalLaw, RigidVessel):
    """A rigid volume under the thermal law, its wall's inner surface ``vessel_area_m2``."""

    vessel_volume_m3: float
    vessel_area_m2: float
    R_J_per_kg_K: float
    heat_capacity_ratio: float
    h_W_per_m2_K: float
    T_wall_K: float


VESSEL_LAWS = {"isothermal": IsothermalVessel, "polytropic": PolytropicVessel, "thermal": ThermalVessel}
"""A rigid volume's element by its law's scenario name (the keys of :data:`CHAMBER_LAWS`)."""


def vessel(law: str, values: Mapping[str, float]):
    """The rigid volume of law ``law`` from ``values`` (each of its fields by name; others ignored)."""
    cls = VESSEL_LAWS[law]
    return cls(**{f: float(values[f]) for f in cls.__dataclass_fields__})


CHAMBER_LAWS = ("isothermal", "polytropic", "thermal")
"""The chamber's laws by their scenario names (``[chamber] law``)."""
