"""Static (quasi-static) force of the muscle, F_static(x, p).

Positive force contracts the muscle (lifts the load).  Other static models
plug in by meeting :class:`pamsim.elements.contracts.StaticForce`; the registry
``STATIC_FORCE_MODELS`` maps a scenario's ``static_force`` key to a builder.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..constants import PA_PER_BAR
from .contracts import NO_OPTIONS, Builder, ElementOptions, StaticForce


@dataclass(frozen=True)
class Acra2012Polynomial:
    """Paper eq. (3)/(11): ``(K1 x^2 + K2 x + C1) P + S1 x^2 + S2 x + S3``, P in bar."""

    K1_N_per_bar_m2: float
    K2_N_per_bar_m: float
    C1_N_per_bar: float
    S1_N_per_m2: float
    S2_N_per_m: float
    S3_N: float
    name: str = "acra2012_polynomial"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> "Acra2012Polynomial":
        return cls(p["K1_N_per_bar_m2"], p["K2_N_per_bar_m"], p["C1_N_per_bar"],
                   p["S1_N_per_m2"], p["S2_N_per_m"], p["S3_N"])

    def force_N(self, x_m, p_gauge_Pa):
        p_bar = p_gauge_Pa / PA_PER_BAR
        return (((self.K1_N_per_bar_m2 * x_m + self.K2_N_per_bar_m) * x_m + self.C1_N_per_bar) * p_bar
                + (self.S1_N_per_m2 * x_m + self.S2_N_per_m) * x_m + self.S3_N)


STATIC_FORCE_MODELS: dict[str, Builder[StaticForce]] = {
    "acra2012_polynomial": Acra2012Polynomial.from_parameters,
}
