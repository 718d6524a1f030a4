"""End stops: a lower stop at x = 0 and an upper stop at the braid-lock contraction.

Both are rigid unilateral contacts with a coefficient of restitution (0 by
default: perfectly inelastic).  They are handled as hybrid modes of the
simulator, so the contraction never passes them; the contact force is
reported in the results.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..core_table import MIN_REBOUND_SPEED_M_S
from ..static_models.geometry import Braid


@dataclass(frozen=True)
class EndStops:
    """Lower and upper stop positions [m] and restitution [-]."""

    x_low_m: float
    x_high_m: float
    restitution: float
    min_rebound_speed_m_s: float = MIN_REBOUND_SPEED_M_S

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "EndStops":
        # Braid lock at 54.7 deg (cos^2 = 1/3): L_lock = b / sqrt(3), MODEL_NOTES sec. 5.
        """Stops at zero contraction and at the braid lock of the muscle's geometry, with its
        ``stop_restitution``.
        """
        return cls(0.0, Braid.from_parameters(p).x_lock_m, p["stop_restitution"])
