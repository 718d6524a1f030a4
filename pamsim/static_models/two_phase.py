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

Phase 2 (braid contact), survey eqs. (60) and (70)-(80) as rebuilt in the
specification, is reduced here to one equation in the braid angle
(:meth:`TwoPhaseTube.phase2_solutions`): the outer radius follows from the angle
(eq. 70), the contact area from eq. (79), and the contact pressure ``P_o`` and end
stress ``P_s = F_sil/A_sil`` are linear in the total end force ``F_e``, which eq.
(70)'s axial condition then fixes.  For the survey's muscle every solution has a
tensile (negative) contact pressure, and there is none at the survey's test
pressures, so the two-phase model is not in the registry as a force model (see
docs/static_models.md).
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

    def phase2_solutions(self, p_gauge_Pa: float, strands: float, strand_radius_m: float, E_nylon_Pa: float,
                         cone_length_m: float, c1_sign: float = -1.0, n_scan: int = 4000) -> list[dict]:
        """Every braid angle solving the phase-2 equations at ``p_gauge_Pa`` (scan + ``brentq``).

        Returns dicts with ``theta_deg``, ``contraction_m`` (``-c3 l0``), ``F_e_N`` (total end
        force) and ``P_o_Pa`` (contact pressure, positive when the braid presses on the tube).
        ``c1_sign = -1`` is the specification's corrected sign of ``P_o r_o^2`` in ``c1``; ``+1``
        the printed one.
        """
        L1, L2 = self.lame
        ro, ri, l0, th0 = self.r_o, self.r_i, self.l0, self.theta0
        D = ro ** 2 - ri ** 2
        A_sil = math.pi * D
        r_b = ro + self.gap
        k = 1.0 / (L2 * (3 * L1 + 2 * L2))
        nyl = strands * math.pi * strand_radius_m ** 2 * E_nylon_Pa
        f_nyl = nyl / (nyl + math.cos(th0) * A_sil * self.E)  # share of F_e carried by the braid, eq. (74)
        tmin = 0.5 * math.asin(strand_radius_m * strands / (math.pi * ro))  # Davis, survey eq. (10)
        davis = (math.sin(tmin) * math.cos(tmin)) ** 2
        P = p_gauge_Pa

        def state(th):
            c3 = math.cos(th) / math.cos(th0) - 1.0
            r = ro * math.sin(th) / math.sin(th0)
            sc = (math.sin(th) * math.cos(th)) ** 2
            S = davis / sc * 2 * math.pi * r * (l0 - 2 * cone_length_m) * (1 + c3) \
                + 2 * math.pi * (r_b + r) * cone_length_m * (1 + c3)
            po = f_nyl * (l0 / r_b) * math.tan(th) * math.tan(th0) / S  # eqs. (78)-(80), per newton of F_e
            ps = (1.0 - f_nyl) / A_sil
            F_e = (c3 + k * L1 * P * ri ** 2 / D) / (k * L1 * (po * ro ** 2 / D + ps * (L1 + L2) / L1))
            Po, Ps = po * F_e, ps * F_e
            c2 = ri ** 2 * ro ** 2 * (P - Po) / (2 * L2 * D)
            c1 = (L1 + 2 * L2) * k / 2 * ((P * ri ** 2 + c1_sign * Po * ro ** 2) / D - Ps * L1 / (L1 + 2 * L2))
            return c1 + c2 / ro ** 2 - (math.sin(th) / math.sin(th0) - 1.0), c3, F_e, Po

        lo, hi = max(1e-6, th0 - 0.3), math.radians(89.0)
        grid = [lo + (hi - lo) * i / n_scan for i in range(n_scan + 1)]
        values = [state(t)[0] for t in grid]
        out = []
        for a, b, fa, fb in zip(grid, grid[1:], values, values[1:]):
            if fa * fb < 0.0:
                th = brentq(lambda t: state(t)[0], a, b, xtol=1e-14)
                _, c3, F_e, Po = state(th)
                out.append({"theta_deg": math.degrees(th), "contraction_m": -c3 * l0, "F_e_N": F_e, "P_o_Pa": Po})
        return out
