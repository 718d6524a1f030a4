"""A pneumatic tube: the gas in its bore (a rigid volume under a chamber law), the bore's resistance, laminar
or turbulent, and the gas's inertia along it.

Resistance: fully developed laminar flow of an ideal gas at temperature ``T`` through a round bore of
diameter ``d`` and length ``L``.  Hagen-Poiseuille gives the pressure gradient of a volume flow ``Q``,
``dp/dz = -128 mu Q / (pi d^4)`` (F. M. White, Fluid Mechanics, 7th ed., McGraw-Hill 2011, eq. 6.44,
pipe flow); with ``Q = mdot R T / p`` and ``mdot`` the same along the bore, ``p dp = -128 mu mdot R T dz
/ (pi d^4)``, which integrates over the length to::

    mdot = pi d^4 (p_a^2 - p_b^2) / (256 mu L R T)

the isothermal compressible form of the law (it is the incompressible one, ``mdot = rho Q``, with the
density at the mean pressure ``(p_a + p_b) / 2``).  It holds while the Reynolds number ``4 mdot / (pi d
mu)`` stays below about 2300; :meth:`Bore.reynolds_number` gives it, so a run shows where it does not.

Turbulent resistance: the Darcy-Weisbach gradient ``dp/dz = -f rho u^2 / (2 d)`` with Blasius's friction
factor for a smooth pipe, ``f = 0.316 Re^-1/4`` (H. Blasius, Das Aehnlichkeitsgesetz bei Reibungsvorgaengen
in Fluessigkeiten, Forschungsheft des VDI 131, 1913; F. M. White, Fluid Mechanics, 7th ed., chapter 6, for
4000 < Re < 1e5).  ``Re = 4 mdot / (pi d mu)`` is the same all along the bore (mdot and mu are), so is
``f``, and with ``rho u = mdot / A``, ``rho = p / (R T)``, ``p dp = -f R T mdot^2 dz / (2 d A^2)``
integrates to::

    p_a^2 - p_b^2 = K_t |mdot|^(7/4),   K_t = 0.316 (pi d mu / 4)^(1/4) 16 R T L / (pi^2 d^5)

and the laminar law is ``p_a^2 - p_b^2 = K_l mdot``, ``K_l = 256 mu L R T / (pi d^4)``.  The bore takes the
larger of the two drops for a flow (the larger friction factor: Blasius's exceeds ``64 / Re`` above
``Re = (64 / 0.316)^(4/3) = 1189``), a continuous law with a kink in its slope where the two meet, and its
inverse, the flow of a drop, is the smaller of the two flows, in closed form::

    mdot = (p_a^2 - p_b^2) min(1 / K_l, K_t^(-4/7) max(|p_a^2 - p_b^2|, D*)^(-3/7))

with ``D* = K_l (K_l / K_t)^(4/3)``, the drop where they meet: held at ``D*`` below it, the turbulent term
has a finite slope at zero flow, where the laminar one is taken (for an exact Jacobian there).  The
acceleration of the gas as it expands (the ``2 ln(p_a / p_b)`` of isothermal pipe flow beside ``f L /
d``) and entrance losses are left out.

Inertia: the gas in a length ``l`` of bore, accelerated by the pressure difference across it less the
resistance's drop, ``d mdot/dt = (A / l) (p_a - p_b - D(mdot) / (p_a + p_b))``, with ``D(mdot)`` the
squared-pressure drop above (:meth:`Bore.squared_drop_Pa2`): at a steady flow it gives the resistance's
own flow.

Capacitance: the bore's volume ``V = pi d^2 L / 4`` follows one of the chamber's laws
(:mod:`pamsim.elements.chamber`), with the bore's inner wall ``A = pi d L`` for the thermal law's heat.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..modeling.smath import fmax, fmin
from .chamber import IdealGas, IsothermalLaw, PolytropicLaw, ThermalLaw

BLASIUS_COEFFICIENT = 0.316
"""Blasius's smooth-pipe friction factor ``f = 0.316 Re^-1/4`` (Blasius 1913; White, Fluid Mechanics, ch. 6)."""

RESISTANCES = ("laminar", "turbulent")
"""The bore's resistance laws; the first is the default."""


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

    def laminar_coefficient(self, T_K, length_fraction=1.0):
        """``K_l`` [Pa^2 s/kg] of ``p_a^2 - p_b^2 = K_l mdot`` over ``length_fraction`` of the bore, ``256 mu l
        R T / (pi d^4)``."""
        return (256.0 * self.viscosity_Pa_s * self.length_m * length_fraction * self.R_J_per_kg_K * T_K
                / (math.pi * self.diameter_m ** 4))

    def turbulent_coefficient(self, T_K, length_fraction=1.0):
        """``K_t`` [Pa^2 (s/kg)^(7/4)] of ``p_a^2 - p_b^2 = K_t |mdot|^(7/4)`` (Blasius) over ``length_fraction``
        of the bore, ``0.316 (pi d mu / 4)^(1/4) 16 R T l / (pi^2 d^5)``."""
        d = self.diameter_m
        return (BLASIUS_COEFFICIENT * (math.pi * d * self.viscosity_Pa_s / 4.0) ** 0.25 * 16.0 * self.R_J_per_kg_K
                * T_K * self.length_m * length_fraction / (math.pi ** 2 * d ** 5))

    def turbulent_mass_flow_kg_s(self, p_a_Pa, p_b_Pa, T_K, length_fraction=1.0):
        """Mass flow [kg/s] from side a to side b through ``length_fraction`` of the bore under the larger of the
        laminar and Blasius drops: the smaller of the two laws' flows, in closed form (module docstring)."""
        drop = p_a_Pa * p_a_Pa - p_b_Pa * p_b_Pa
        K_l, K_t = self.laminar_coefficient(T_K, length_fraction), self.turbulent_coefficient(T_K, length_fraction)
        where_they_meet = K_l * (K_l / K_t) ** (4.0 / 3.0)
        turbulent = K_t ** (-4.0 / 7.0) * fmax(abs(drop), where_they_meet) ** (-3.0 / 7.0)
        return drop * fmin(1.0 / K_l, turbulent)

    def squared_drop_Pa2(self, mass_flow_kg_s, T_K, length_fraction=1.0, turbulent=False):
        """``p_a^2 - p_b^2`` [Pa^2] that drives ``mass_flow_kg_s`` through ``length_fraction`` of the bore at
        a steady flow: ``K_l mdot``, or with ``turbulent`` the larger of it and ``K_t |mdot|^(7/4)`` (the flow held
        at least where the two meet in the turbulent term, for a finite slope at zero flow)."""
        K_l = self.laminar_coefficient(T_K, length_fraction)
        if not turbulent:
            return K_l * mass_flow_kg_s
        K_t = self.turbulent_coefficient(T_K, length_fraction)
        where_they_meet = (K_l / K_t) ** (4.0 / 3.0)
        return mass_flow_kg_s * fmax(K_l, K_t * fmax(abs(mass_flow_kg_s), where_they_meet) ** 0.75)

    def flow_acceleration_kg_s2(self, mass_flow_kg_s, p_a_Pa, p_b_Pa, T_K, length_fraction=1.0, turbulent=False):
        """``d mdot/dt`` [kg/s^2] of the gas in ``length_fraction`` of the bore (length ``l``), its inertia:
        ``(A / l) (p_a - p_b - D(mdot) / (p_a + p_b))``, ``D`` the squared-pressure drop of
        :meth:`squared_drop_Pa2` (laminar, or with ``turbulent`` the larger of it and Blasius's)."""
        area = math.pi * self.diameter_m ** 2 / 4.0
        drop = self.squared_drop_Pa2(mass_flow_kg_s, T_K, length_fraction, turbulent) / (p_a_Pa + p_b_Pa)
        return area / (self.length_m * length_fraction) * (p_a_Pa - p_b_Pa - drop)

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
