"""A pneumatic tube as one lumped cell: the gas in its bore (a rigid volume under a chamber law) and the
bore's laminar resistance.

Resistance: fully developed laminar flow of an ideal gas at temperature ``T`` through a round bore of
diameter ``d`` and length ``L``.  Hagen-Poiseuille gives the pressure gradient of a volume flow ``Q``,
``dp/dz = -128 mu Q / (pi d^4)`` (F. M. White, Fluid Mechanics, 7th ed., McGraw-Hill 2011, eq. 6.44,
pipe flow); with ``Q = mdot R T / p`` and ``mdot`` the same along the bore, ``p dp = -128 mu mdot R T dz
/ (pi d^4)``, which integrates over the length to::

    mdot = pi d^4 (p_a^2 - p_b^2) / (256 mu L R T)

the isothermal compressible form of the law (it is the incompressible one, ``mdot = rho Q``, with the
density at the mean pressure ``(p_a + p_b) / 2``).  It holds while the Reynolds number ``4 mdot / (pi d
mu)`` stays below about 2300; :meth:`Bore.reynolds_number` gives it, so a run shows where it does not.
Entrance losses and the gas's inertia are left out.

Capacitance: the bore's volume ``V = pi d^2 L / 4`` follows one of the chamber's laws
(:mod:`pamsim.elements.chamber`), with the bore's inner wall ``A = pi d L`` for the thermal law's heat.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .chamber import IdealGas, IsothermalLaw, PolytropicLaw, ThermalLaw


class Bore(IdealGas):
    """A tube's bore: its geometry, its gas and its laminar resistance.  A mixin of a dataclass with the
    fields ``length_m``, ``diameter_m``, ``viscosity_Pa_s``, ``R_J_per_kg_K``, and a law's."""

    def volume_m3(self, x_m=0.0):
        """The bore's volume [m^3], ``pi d^2 L / 4`` (``x_m`` is ignored: the bore is rigid)."""
        return math.pi * self.diameter_m ** 2 * self.length_m / 4.0

    def dvolume_dx_m2(self, x_m=0.0):
        """Zero: the bore does not move."""
        return 0.0

    def wall_area_m2(self, x_m=0.0):
        """The bore's inner wall [m^2], ``pi d L``."""
        return math.pi * self.diameter_m * self.length_m

    def mass_flow_kg_s(self, p_a_Pa, p_b_Pa, T_K, length_fraction=1.0):
        """Laminar mass flow [kg/s] from side a to side b through ``length_fraction`` of the bore's length,
        ``pi d^4 (p_a^2 - p_b^2) / (256 mu l R T)`` (absolute pressures, the gas at ``T_K``)."""
        length = self.length_m * length_fraction
        return (math.pi * self.diameter_m ** 4 * (p_a_Pa * p_a_Pa - p_b_Pa * p_b_Pa)
                / (256.0 * self.viscosity_Pa_s * length * self.R_J_per_kg_K * T_K))

    def reynolds_number(self, mass_flow_kg_s):
        """The flow's Reynolds number ``4 |mdot| / (pi d mu)``: laminar below about 2300."""
        return 4.0 * abs(mass_flow_kg_s) / (math.pi * self.diameter_m * self.viscosity_Pa_s)


@dataclass(frozen=True)
class PolytropicTube(PolytropicLaw, Bore):
    """A tube whose gas follows the polytropic law."""

    length_m: float
    diameter_m: float
    viscosity_Pa_s: float
    polytropic_index: float
    R_J_per_kg_K: float


@dataclass(frozen=True)
class IsothermalTube(IsothermalLaw, Bore):
    """A tube whose gas stays at its wall's temperature."""

    length_m: float
    diameter_m: float
    viscosity_Pa_s: float
    R_J_per_kg_K: float
    T_wall_K: float


@dataclass(frozen=True)
class ThermalTube(ThermalLaw, Bore):
    """A tube whose gas follows the thermal law, through the bore's wall ``pi d L``."""

    length_m: float
    diameter_m: float
    viscosity_Pa_s: float
    R_J_per_kg_K: float
    heat_capacity_ratio: float
    h_W_per_m2_K: float
    T_wall_K: float


TUBE_LAWS = {"isothermal": IsothermalTube, "polytropic": PolytropicTube, "thermal": ThermalTube}
"""A tube's element by its gas's law (the scenario names of :data:`pamsim.elements.chamber.CHAMBER_LAWS`)."""
