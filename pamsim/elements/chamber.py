"""The muscle as a gas chamber: volume from braid geometry, polytropic pressure law.

Volume (Chou and Hannaford; MODEL_NOTES sec. 6), with L = L0 - x, thread
length b and n turns::

    V(x) = L (b^2 - L^2) / (4 pi n^2) + V_dead

Pressure (absolute) with polytropic index n_p::

    dp/dt = n_p (R T_in mdot - p dV/dt) / V

T_in is the supply temperature for inflow and the chamber gas temperature
``p V / (m R)`` for outflow.  With n_p = 1.4 this is the adiabatic energy
balance of an open chamber; with n_p = 1 the gas stays at the supply
temperature and ``p V = m R T`` holds exactly, which the tests use as a mass
balance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from ..static_models.geometry import Braid


@dataclass(frozen=True)
class MuscleChamber:
    """Geometry and gas constants of the muscle chamber."""

    L0_m: float
    thread_length_m: float
    turns: float
    dead_volume_m3: float
    polytropic_index: float
    R_J_per_kg_K: float

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "MuscleChamber":
        """The chamber of a muscle's parameters (braid geometry, dead volume, polytropic index, gas constant)."""
        braid = Braid.from_parameters(p)
        return cls(p["L0_m"], braid.b, braid.N, p["dead_volume_m3"], p["polytropic_index"], p["R_J_per_kg_K"])

    def volume_m3(self, x_m):
        """Chamber volume [m^3] at contraction ``x_m``: the braid's cylinder plus the dead volume."""
        L = self.L0_m - x_m
        return L * (self.thread_length_m ** 2 - L * L) / (4.0 * math.pi * self.turns ** 2) + self.dead_volume_m3

    def dvolume_dx_m2(self, x_m):
        """Derivative of the volume with respect to contraction, ``dV/dx`` [m^2]."""
        L = self.L0_m - x_m
        return -(self.thread_length_m ** 2 - 3.0 * L * L) / (4.0 * math.pi * self.turns ** 2)

    def gas_temperature_K(self, p_abs_Pa, volume_m3, air_mass_kg):
        """Gas temperature [K] of the air mass at absolute pressure and volume: ``p V / (m R)``."""
        return p_abs_Pa * volume_m3 / (air_mass_kg * self.R_J_per_kg_K)

    def air_mass_kg(self, p_abs_Pa, volume_m3, T_K):
        """Air mass [kg] of the ideal gas at absolute pressure, volume and temperature: ``p V / (R T)``."""
        return p_abs_Pa * volume_m3 / (self.R_J_per_kg_K * T_K)

    def pressure_rate_Pa_s(self, p_abs_Pa, volume_m3, dvolume_dt_m3_s, inflow_kg_s, T_inflow_K):
        """Rate of the absolute pressure [Pa/s] for the volume's rate of change and an inflow [kg/s] at
        ``T_inflow_K``.
        """
        return self.pressure_rate_from_flow_work_Pa_s(p_abs_Pa, volume_m3, dvolume_dt_m3_s,
                                                      self.flow_work_W(inflow_kg_s, T_inflow_K))

    def flow_work_W(self, inflow_kg_s, T_inflow_K):
        """``R T_in mdot``: the flow work an inflow at ``T_inflow_K`` brings in [W]."""
        return self.R_J_per_kg_K * T_inflow_K * inflow_kg_s

    def pressure_rate_from_flow_work_Pa_s(self, p_abs_Pa, volume_m3, dvolume_dt_m3_s, flow_work_W):
        """``n (R T_in mdot - p dV/dt) / V`` from the summed flow work of every inflow [Pa/s]."""
        return self.polytropic_index * (flow_work_W - p_abs_Pa * dvolume_dt_m3_s) / volume_m3
