"""The hanging load: a mass under gravity plus an optional external force.

The external force is positive along the contraction (it helps the muscle
lift); a downward pull is negative.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class HangingLoad:
    """A hanging mass [kg] (holder included) and an extra force ``external_force_N(t)``."""

    mass_kg: float
    g_m_s2: float
    external_force_N: Callable | None = None

    @property
    def weight_N(self) -> float:
        """Weight of the load [N]: mass times gravity."""
        return self.mass_kg * self.g_m_s2

    def external_N(self, t_s):
        """External force [N] on the load at ``t_s`` [s] (zero without one)."""
        if self.external_force_N is None:
            return 0.0 * t_s
        return self.external_force_N(t_s)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where the external force jumps."""
        return getattr(self.external_force_N, "breakpoints", ())
