"""ACRA 2012 polynomial static force of the Shadow 6 mm x 300 mm muscle (model A-2).

``F = (K1 x^2 + K2 x + C1) P + S1 x^2 + S2 x + S3`` with ``x = L0 - L`` in metres
and ``P`` in bar gauge (the paper's units; converted at this edge).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from ..constants import PA_PER_BAR
from .base import Domain, StaticForce, StaticModelSpec
from .sources import ACRA2012

SOURCE = ACRA2012 + " eqs. (3) and (11)"
COEFFICIENTS = ("K1_N_per_bar_m2", "K2_N_per_bar_m", "C1_N_per_bar", "S1_N_per_m2", "S2_N_per_m", "S3_N")


@dataclass(frozen=True)
class Acra2012Polynomial(StaticForce):
    """Paper eq. (3)/(11): ``(K1 x^2 + K2 x + C1) P + S1 x^2 + S2 x + S3``, P in bar.

    The domain is the fitted region (``fit_x_min_m`` .. ``fit_x_max_m``, 0 ..
    ``fit_p_max_Pa``) when the parameters give it, else unbounded.
    """

    K1_N_per_bar_m2: float
    K2_N_per_bar_m: float
    C1_N_per_bar: float
    S1_N_per_m2: float
    S2_N_per_m: float
    S3_N: float
    domain: Domain = Domain(-math.inf, math.inf, 0.0, math.inf)
    name: str = "acra2012_polynomial"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: Mapping[str, str] | None = None) -> "Acra2012Polynomial":
        """Build from a parameter mapping; ``options`` (the scenario's model choices) is not used."""
        domain = Domain(p.get("fit_x_min_m", -math.inf), p.get("fit_x_max_m", math.inf),
                        0.0, p.get("fit_p_max_Pa", math.inf))
        return cls(*(p[k] for k in COEFFICIENTS), domain=domain)

    def force_N(self, x_m, p_gauge_Pa):
        p_bar = p_gauge_Pa / PA_PER_BAR
        return (((self.K1_N_per_bar_m2 * x_m + self.K2_N_per_bar_m) * x_m + self.C1_N_per_bar) * p_bar
                + (self.S1_N_per_m2 * x_m + self.S2_N_per_m) * x_m + self.S3_N)


SPECS = (
    StaticModelSpec(
        name="acra2012_polynomial", kind="closed-form", source=SOURCE, parameters=COEFFICIENTS,
        builder=lambda p, variant: Acra2012Polynomial.from_parameters(p),
        summary="fitted quadratic polynomial in contraction, linear in pressure (Shadow 6 mm x 300 mm)"),
)
