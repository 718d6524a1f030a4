"""Coulomb friction level F_c >= 0 [N]; the simulator applies it against the motion.

``level_N(x_m, p_gauge_Pa, mass_kg)`` is the magnitude; its sign and the
stick/slip logic belong to the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..constants import PA_PER_BAR
from .contracts import NO_OPTIONS, Builder, ElementOptions, Friction

NEGATIVE_LEVEL_CHOICES = ("clamp", "abs")


@dataclass(frozen=True)
class LoadDependentCoulomb:
    """Paper eq. (5)-(7): ``(P + phi)(N2 x^2 + N1 x + N0)`` with ``phi = -m``, P in bar, m in kg.

    For heavy loads at low pressure ``P - m`` is negative, which would make the
    friction push the motion.  ``negative_level`` decides (a pamsim choice,
    docs/model.md): ``"clamp"`` (default) sets the level to zero there,
    ``"abs"`` uses its magnitude.
    """

    N2_N_per_bar_m2: float
    N1_N_per_bar_m: float
    N0_N_per_bar: float
    phi_bar_per_kg: float
    negative_level: str = "clamp"
    name: str = "load_dependent"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> "LoadDependentCoulomb":
        """Build from the parameters; ``options["friction_negative_level"]`` picks the treatment (default clamp)."""
        negative_level = options.get("friction_negative_level", "clamp")
        if negative_level not in NEGATIVE_LEVEL_CHOICES:
            raise ValueError(f"negative_level must be one of {NEGATIVE_LEVEL_CHOICES}, not {negative_level!r}")
        return cls(p["N2_N_per_bar_m2"], p["N1_N_per_bar_m"], p["N0_N_per_bar"], p["phi_bar_per_kg"], negative_level)

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        """Friction level [N] at contraction, gauge pressure and load mass; a negative level is clipped to 0
        or taken as its magnitude, by ``negative_level``.
        """
        level = ((p_gauge_Pa / PA_PER_BAR - self.phi_bar_per_kg * mass_kg)
                 * ((self.N2_N_per_bar_m2 * x_m + self.N1_N_per_bar_m) * x_m + self.N0_N_per_bar))
        if self.negative_level == "abs":
            return abs(level)
        return 0.5 * (level + abs(level))  # max(level, 0) for floats and arrays alike


@dataclass(frozen=True)
class ConstantCoulomb:
    """The paper's comparison model: a constant level (2.5 N, after Chou and Hannaford)."""

    level_constant_N: float
    name: str = "constant"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> "ConstantCoulomb":
        """A constant level of ``coulomb_constant_N`` of the muscle's parameters."""
        return cls(p["coulomb_constant_N"])

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        """The constant level [N], of the shape of ``x_m``."""
        return self.level_constant_N + 0.0 * x_m


@dataclass(frozen=True)
class NoCoulomb:
    """No Coulomb friction (used to isolate damping, or for linearisation checks)."""

    name: str = "none"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> "NoCoulomb":
        """No Coulomb friction; the parameters are not read."""
        return cls()

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        """Zero, of the shape of ``x_m``."""
        return 0.0 * x_m


FRICTION_MODELS: dict[str, Builder[Friction]] = {
    "load_dependent": LoadDependentCoulomb.from_parameters,
    "constant": ConstantCoulomb.from_parameters,
    "none": NoCoulomb.from_parameters,
}
