"""Coulomb friction level F_c >= 0 [N]; the simulator applies it against the motion.

``level_N(x_m, p_gauge_Pa, mass_kg)`` is the magnitude; its sign and the
stick/slip logic belong to the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

from ..constants import PA_PER_BAR


@dataclass(frozen=True)
class LoadDependentCoulomb:
    """Paper eq. (5)-(7): ``(P + phi)(N2 x^2 + N1 x + N0)`` with ``phi = -m``, P in bar, m in kg.

    For heavy loads at low pressure ``P - m`` is negative, which would make the
    friction push the motion; pamsim clamps the level at zero (docs/model.md).
    """

    N2_N_per_bar_m2: float
    N1_N_per_bar_m: float
    N0_N_per_bar: float
    phi_bar_per_kg: float
    name: str = "load_dependent"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "LoadDependentCoulomb":
        return cls(p["N2_N_per_bar_m2"], p["N1_N_per_bar_m"], p["N0_N_per_bar"], p["phi_bar_per_kg"])

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        level = ((p_gauge_Pa / PA_PER_BAR - self.phi_bar_per_kg * mass_kg)
                 * ((self.N2_N_per_bar_m2 * x_m + self.N1_N_per_bar_m) * x_m + self.N0_N_per_bar))
        return 0.5 * (level + abs(level))  # max(level, 0) for floats and arrays alike


@dataclass(frozen=True)
class ConstantCoulomb:
    """The paper's comparison model: a constant level (2.5 N, after Chou and Hannaford)."""

    level_constant_N: float
    name: str = "constant"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "ConstantCoulomb":
        return cls(p["coulomb_constant_N"])

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        return self.level_constant_N + 0.0 * x_m


@dataclass(frozen=True)
class NoCoulomb:
    """No Coulomb friction (used to isolate damping, or for linearisation checks)."""

    name: str = "none"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "NoCoulomb":
        return cls()

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        return 0.0 * x_m


FRICTION_MODELS: dict[str, Callable[[Mapping[str, float]], object]] = {
    "load_dependent": LoadDependentCoulomb.from_parameters,
    "constant": ConstantCoulomb.from_parameters,
    "none": NoCoulomb.from_parameters,
}
