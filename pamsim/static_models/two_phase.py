"""The survey's two-phase miniature-muscle model (S-34): phase 1 and the inflection pressure.

Phase 1 (gauge pressure below the inflection pressure ``Pbar``): the silicone
tube inflates freely as a linear thick cylinder (Lame solution, survey eq. 62)
until its outer surface touches the braided sleeve across the gap ``delta``;
``Pbar`` is the root of survey eq. (69), rebuilt (``-Pbar r_i^2/(r_o^2 - r_i^2)``
for the printed ``-Pbar^2/(...)``).

The axial load enters phase 1 through the end stress ``P_sil``; the survey
divides the load by the bore area ``pi r_i^2`` (``load="printed"``), which with the
survey's 0.05 N and E = 0.35 MPa stretches the tube past the braid's kinematic
limit, so eq. (69) has no root.  ``load="annulus"`` divides by the wall area
(the tube is in contact at zero pressure); ``load="neglected"`` (default) leaves
the load to the braid, the only reading with a plausible ``Pbar``.

Phase 2 (braid contact) is not implemented: its equations (survey eqs. 60, 70-80,
rebuilt as in the specification) have no solution with a compressive contact
pressure for the survey's muscle (see docs/static_models.md), so the two-phase
model is not in the registry as a force model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from scipy.optimize import brentq

from ..errors import InputError

LOAD_TREATMENTS = ("neglected", "printed", "annulus")


@dataclass(frozen=True)
class TwoPhaseTube:
    """Silicone tube and sleeve of a miniature muscle (SI units).

    ``r_o``, ``r_i``: tube radii; ``l0``: length; ``theta0``: braid angle from the
    axis [rad]; ``gap``: tube-sleeve gap; ``E``, ``nu``: silicone modulus and
    Poisson ratio.
    """

    r_o: float
    r_i: float
    l0: float
    theta0: float
    gap: float
    E: float
    nu: float

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "TwoPhaseTube":
        return cls(p["r0_m"], p["ri0_m"], p["L0_m"], math.radians(p["theta0_deg"]), p["sleeve_gap_m"],
                   p["E_bladder_Pa"], p["nu_bladder"])

    @property
    def lame(self) -> tuple[float, float]:
        """Lame parameters ``(Lambda1, Lambda2)`` [Pa]."""
        E, nu = self.E, self.nu
        return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))

    def end_stress_Pa(self, p_gauge_Pa: float, load_N: float, load: str = "neglected") -> float:
        """Axial end stress ``P_s`` on the tube: the end-cap pressure plus the load's share."""
        D = self.r_o ** 2 - self.r_i ** 2
        area = {"neglected": math.inf, "printed": math.pi * self.r_i ** 2, "annulus": math.pi * D}[load]
        return p_gauge_Pa * self.r_i ** 2 / D + load_N / area

    def phase1_displacements_m(self, p_gauge_Pa: float, load_N: float = 0.0, load: str = "neglected") -> tuple[float, float]:
        """Survey eq. (62): radial displacement of the tube's outer surface and axial end displacement [m]
        (positive = the muscle lengthens)."""
        L1, L2 = self.lame
        D = self.r_o ** 2 - self.r_i ** 2
        k = 1.0 / (L2 * (3 * L1 + 2 * L2))
        Ps = self.end_stress_Pa(p_gauge_Pa, load_N, load)
        u_r = self.r_o * k * (2 * (L1 + L2) * self.r_i ** 2 / D * p_gauge_Pa - L1 / 2 * Ps)
        u_z = L1 * self.l0 * k * (-p_gauge_Pa * self.r_i ** 2 / D + Ps * (L1 + L2) / L1)
        return u_r, u_z

    def contact_gap_m(self, p_gauge_Pa: float, load_N: float = 0.0, load: str = "neglected") -> float:
        """Survey eq. (69) rebuilt: tube radius minus sleeve radius (zero at the inflection pressure).

        Raises
        ------
        InputError
            When the tube is stretched past the braid's kinematic limit (no sleeve radius exists).
        """
        u_r, u_z = self.phase1_displacements_m(p_gauge_Pa, load_N, load)
        c = math.cos(self.theta0) * (1 + u_z / self.l0)
        if c >= 1.0:
            raise InputError(f"two-phase model: load = {load!r}: the tube's axial strain {u_z / self.l0:.3g} at "
                             f"{p_gauge_Pa:g} Pa lies beyond the braid's kinematic limit")
        r_b = self.r_o + self.gap
        return u_r - self.gap - r_b * (math.sqrt(1 - c * c) / math.sin(self.theta0) - 1)

    def inflection_pressure_Pa(self, load_N: float = 0.0, load: str = "neglected", p_max_Pa: float = 1e7) -> float:
        """Gauge pressure at which the tube touches the sleeve (end of phase 1), by ``brentq``.

        Raises
        ------
        InputError
            If the tube touches the sleeve already at zero pressure, or never below ``p_max_Pa``,
            or the load stretches it past the kinematic limit.
        """
        if load not in LOAD_TREATMENTS:
            raise InputError(f"two-phase model: load = {load!r}: unknown (choose from {', '.join(LOAD_TREATMENTS)})")
        g0 = self.contact_gap_m(0.0, load_N, load)
        if g0 >= 0.0:
            raise InputError(f"two-phase model: load = {load!r}: the tube touches the sleeve at zero pressure "
                             f"(gap {g0:g} m): no inflection pressure")
        if self.contact_gap_m(p_max_Pa, load_N, load) < 0.0:
            raise InputError(f"two-phase model: no contact below {p_max_Pa:g} Pa")
        return brentq(lambda p: self.contact_gap_m(p, load_N, load), 0.0, p_max_Pa, xtol=1e-6)
