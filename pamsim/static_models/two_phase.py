"""The survey's two-phase miniature-muscle model (S-34), registry name ``mpam_two_phase``.

Phase 1 (the tube not yet touching the braided sleeve): the silicone tube is a
linear thick cylinder (Lame solution, survey eq. 62).  With the contraction
``x`` imposed, eq. (62)'s axial displacement ``u_z = -x`` fixes the end stress
``P_s`` and hence the axial load on the tube; because the free tube *lengthens*
under pressure, holding it at ``x >= 0`` takes a compressive load, so the phase-1
force is negative (the tube pushes) or zero.

Phase 2 (contact, survey eqs. 60 and 70-80 as rebuilt in the specification),
with the contraction imposed (``c3 = -x / l0``): the unknowns are ``c1``, ``c2``,
the braid angle ``theta``, the contact pressure ``P_o`` and the tube's end stress
``P_s``; the five equations are eq. (60) (three) and the braid kinematics
eq. (70) (two).  The braid's axial force ``F_nyl`` follows from ``P_o`` by eqs.
(78)-(79); its strands stretch by ``F_nyl / (m A_nyl E_nyl cos(theta))``
(eq. 72's strand law, which is where the nylon modulus enters), and the muscle's
pull is ``F = P_s A_sil + F_nyl - pi r_i^2 P - F_u`` (eq. 71 with ``F_sil =
P_s A_sil``).  The specification's split of eq. (74) is *not* imposed: with the
contraction fixed it would be a sixth equation for five unknowns (see
docs/static_models.md, "Two-phase miniature-muscle model").

:meth:`TwoPhaseTube.phase2_solutions` keeps the specification's own reduction at
a given pressure (contraction free, split of eq. 74), whose solutions all have a
tensile contact pressure for the survey's muscle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .base import brentq
from ..errors import InputError
from .base import Domain, StaticForce, StaticModelDomainError, StaticModelSpec, rated_pressure_Pa
from .sources import SURVEY

LOAD_TREATMENTS = ("neglected", "printed", "annulus")


def davis_min_angle_rad(strands: float, strand_radius_m: float, r_o_m: float) -> float:
    """Davis's smallest braid angle ``theta_min``, where the strands touch (survey eq. 10)."""
    return 0.5 * math.asin(strand_radius_m * strands / (math.pi * r_o_m))


def davis_factor(strands: float, strand_radius_m: float, r_o_m: float) -> float:
    """``sin^2(theta_min) cos^2(theta_min)`` (the contact fraction's numerator in survey eq. 79)."""
    tmin = davis_min_angle_rad(strands, strand_radius_m, r_o_m)
    return (math.sin(tmin) * math.cos(tmin)) ** 2


def contact_area_m2(davis: float, theta: float, r_m: float, r_b_m: float, l0_m: float, cone_m: float,
                    c3: float) -> float:
    """Survey eq. (79): braid-tube contact area, Davis's fraction of the cylinder plus the full conical ends."""
    sc = (math.sin(theta) * math.cos(theta)) ** 2
    return (davis / sc * 2 * math.pi * r_m * (l0_m - 2 * cone_m) * (1 + c3)
            + 2 * math.pi * (r_b_m + r_m) * cone_m * (1 + c3))


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
        """The tube of a muscle's radii, length, braid angle, sleeve gap and bladder material."""
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

    def displacements_m(self, p_gauge_Pa: float, P_s_Pa: float) -> tuple[float, float]:
        """Survey eq. (62) for end stress ``P_s_Pa``: radial displacement of the tube's outer surface and
        axial end displacement [m] (positive = the muscle lengthens)."""
        L1, L2 = self.lame
        D = self.r_o ** 2 - self.r_i ** 2
        k = 1.0 / (L2 * (3 * L1 + 2 * L2))
        u_r = self.r_o * k * (2 * (L1 + L2) * self.r_i ** 2 / D * p_gauge_Pa - L1 / 2 * P_s_Pa)
        u_z = L1 * self.l0 * k * (-p_gauge_Pa * self.r_i ** 2 / D + P_s_Pa * (L1 + L2) / L1)
        return u_r, u_z

    def end_stress_for_contraction_Pa(self, p_gauge_Pa: float, x_m: float) -> float:
        """The end stress ``P_s`` at which eq. (62)'s axial displacement is ``-x_m`` (contraction imposed)."""
        L1, L2 = self.lame
        D = self.r_o ** 2 - self.r_i ** 2
        k = 1.0 / (L2 * (3 * L1 + 2 * L2))
        return (-x_m / (self.l0 * k) + L1 * p_gauge_Pa * self.r_i ** 2 / D) / (L1 + L2)

    def phase1_displacements_m(self, p_gauge_Pa: float, load_N: float = 0.0, load: str = "neglected") -> tuple[float, float]:
        """Survey eq. (62) under an axial load: ``(u_r, u_z)`` [m] (positive ``u_z`` = the muscle lengthens)."""
        return self.displacements_m(p_gauge_Pa, self.end_stress_Pa(p_gauge_Pa, load_N, load))

    def sleeve_gap_m(self, u_r_m: float, c3: float) -> float:
        """Survey eq. (68): tube radius minus sleeve radius for tube displacement ``u_r_m`` and axial strain ``c3``.

        Raises
        ------
        InputError
            When ``c3`` lies beyond the braid's kinematic limit (no sleeve radius exists).
        """
        c = math.cos(self.theta0) * (1 + c3)
        if c >= 1.0:
            raise InputError(f"two-phase model: the tube's axial strain {c3:.3g} lies beyond the braid's kinematic limit")
        r_b = self.r_o + self.gap
        return u_r_m - self.gap - r_b * (math.sqrt(1 - c * c) / math.sin(self.theta0) - 1)

    def contact_gap_m(self, p_gauge_Pa: float, load_N: float = 0.0, load: str = "neglected") -> float:
        """Survey eq. (69) rebuilt: tube radius minus sleeve radius (zero at the inflection pressure).

        Raises
        ------
        InputError
            When the tube is stretched past the braid's kinematic limit (no sleeve radius exists).
        """
        u_r, u_z = self.phase1_displacements_m(p_gauge_Pa, load_N, load)
        try:
            return self.sleeve_gap_m(u_r, u_z / self.l0)
        except InputError as e:
            raise InputError(f"two-phase model: load = {load!r}: at {p_gauge_Pa:g} Pa: {e}") from None

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

    def constants(self, P: float, P_o: float, P_s: float, c1_sign: float = -1.0) -> tuple[float, float, float]:
        """Survey eq. (60): ``(c1, c2, c3)`` for inner, outer and end pressures [Pa]; ``c1_sign`` is the sign
        of ``P_o r_o^2`` in ``c1`` (-1 the specification's correction, +1 as printed)."""
        L1, L2 = self.lame
        ro, ri = self.r_o, self.r_i
        D = ro ** 2 - ri ** 2
        k = 1.0 / (L2 * (3 * L1 + 2 * L2))
        c1 = (L1 + 2 * L2) * k / 2 * ((P * ri ** 2 + c1_sign * P_o * ro ** 2) / D - P_s * L1 / (L1 + 2 * L2))
        c2 = ri ** 2 * ro ** 2 * (P - P_o) / (2 * L2 * D)
        c3 = L1 * k * ((-P * ri ** 2 + P_o * ro ** 2) / D + P_s * (L1 + L2) / L1)
        return c1, c2, c3

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
        davis = davis_factor(strands, strand_radius_m, ro)
        P = p_gauge_Pa

        def state(th):
            c3 = math.cos(th) / math.cos(th0) - 1.0
            r = ro * math.sin(th) / math.sin(th0)
            S = contact_area_m2(davis, th, r, r_b, l0, cone_length_m, c3)
            po = f_nyl * (l0 / r_b) * math.tan(th) * math.tan(th0) / S  # eqs. (78)-(80), per newton of F_e
            ps = (1.0 - f_nyl) / A_sil
            F_e = (c3 + k * L1 * P * ri ** 2 / D) / (k * L1 * (po * ro ** 2 / D + ps * (L1 + L2) / L1))
            Po, Ps = po * F_e, ps * F_e
            c1, c2, _ = self.constants(P, Po, Ps, c1_sign)
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


# ----------------------------------------------------------------- the registry model
VARIANTS = ("corrected", "printed")
"""``corrected``: the specification's repairs (sign of ``P_o r_o^2`` in eq. 60's ``c1``;
eq. 78's ``tan(theta)`` and the current radius ``r`` in eq. 79; the radial contact
condition with the gap, eq. 68; the phase-1 load over the wall area).  ``printed``:
the survey as printed (``+P_o r_o^2``; eq. 80's ``sin^2(theta)/cos(theta)`` and the
displacement ``c1 r_o + c2/r_o`` in place of the radius; eq. 70 without the gap;
eq. 69's load over the bore area ``pi r_i^2``)."""

P_CAP_DEFAULT_PA = 1.0e6
"""Upper end of the pressure scan that sets the domain when the muscle has no rating
(assumed: above the survey's highest test pressure, 827 kPa)."""

NO_CONTACT = "no compressive-contact solution of the phase-2 equations"


@dataclass(frozen=True)
class Phase2State:
    """A solution of the phase-2 system at imposed contraction (SI units, angles in rad)."""

    c1: float
    c2: float
    c3: float
    theta: float
    P_o_Pa: float
    P_s_Pa: float
    F_nyl_N: float
    strand_strain: float
    force_N: float


class TwoPhaseForce(StaticForce):
    """``mpam_two_phase``: survey S-34, force at imposed contraction (see the module docstring)."""

    name = "mpam_two_phase"

    def __init__(self, params, variant: str = "corrected"):
        self.tube = TwoPhaseTube.from_parameters(params)
        self.variant = variant
        self.printed = variant == "printed"
        t = self.tube
        self.D = t.r_o ** 2 - t.r_i ** 2
        self.A_sil = math.pi * self.D
        self.r_b = t.r_o + t.gap
        self.m = params["n_fibres"]
        self.strand_stiffness_N = self.m * math.pi * params["fibre_radius_m"] ** 2 * params["E_nylon_Pa"]
        self.cone = params["end_cone_length_m"]
        self.F_u = params["two_phase_F_u_N"]
        self.davis = davis_factor(self.m, params["fibre_radius_m"], t.r_o)
        tmin = davis_min_angle_rad(self.m, params["fibre_radius_m"], t.r_o)
        self.load_area = math.pi * t.r_i ** 2 if self.printed else self.A_sil
        # The braid jams when its strands touch, at 90 deg - theta_min (Davis, survey eq. 10); the tube
        # may carry the muscle past Gaylord's 54.7 deg (the survey's Fig. 19 "slightly overshoots").
        self.theta_jam = math.pi / 2 - tmin
        x_max = t.l0 * (1.0 - math.cos(self.theta_jam) / math.cos(t.theta0))
        p_cap = rated_pressure_Pa(params)
        self.p_cap_Pa = p_cap if math.isfinite(p_cap) else P_CAP_DEFAULT_PA
        self.domain = Domain(0.0, x_max, 0.0, self.p_cap_Pa)
        self.domain = Domain(0.0, x_max, 0.0, self._largest_physical_pressure_Pa())

    def braid_force_N(self, theta: float, c1: float, c2: float, c3: float, P_o: float) -> float:
        """Axial braid force ``F_nyl`` whose radial pull (eq. 78) over the contact area (eq. 79) is ``P_o``."""
        t = self.tube
        u_r = c1 * t.r_o + c2 / t.r_o
        r = u_r if self.printed else t.r_o + u_r
        S = contact_area_m2(self.davis, theta, r, self.r_b, t.l0, self.cone, c3)
        g = math.sin(theta) ** 2 / math.cos(theta) if self.printed else math.tan(theta)
        return P_o * S / ((t.l0 / self.r_b) * g * math.tan(t.theta0))

    def residuals(self, x_m: float, P: float, c1, c2, theta, P_o, P_s) -> list[float]:
        """The five phase-2 equations at contraction ``x_m`` (dimensionless; zero at a solution)."""
        t = self.tube
        c3 = -x_m / t.l0
        e1, e2, e3 = self.tube.constants(P, P_o, P_s, 1.0 if self.printed else -1.0)
        F_nyl = self.braid_force_N(theta, c1, c2, c3, P_o)
        stretch = 1.0 + F_nyl / (self.strand_stiffness_N * math.cos(theta))
        if self.printed:  # eq. (70): no gap
            radial = c1 + c2 / t.r_o ** 2 - (stretch * math.sin(theta) / math.sin(t.theta0) - 1.0)
        else:  # eq. (68): the tube's surface meets the sleeve across the gap
            radial = (c1 * t.r_o + c2 / t.r_o - t.gap
                      - self.r_b * (stretch * math.sin(theta) / math.sin(t.theta0) - 1.0)) / t.r_o
        return [c1 - e1, (c2 - e2) / t.r_o ** 2, c3 - e3, radial,
                1.0 + c3 - stretch * math.cos(theta) / math.cos(t.theta0)]

    def phase2_state(self, x_m: float, p_gauge_Pa: float) -> Phase2State | None:
        """Solve the phase-2 system at imposed contraction with ``scipy.optimize.root`` (hybr).

        Initial guess: the inextensible braid (``theta`` from eq. 70 with ``c3 = -x/l0``)
        and ``P_o = P``, ``P_s = 0``; fallbacks: the survey's zero start
        (``c = 0``, ``theta = theta0``, loads zero), then Levenberg-Marquardt from the
        first guess.  Returns None when no start converges (residuals above 1e-10).
        """
        t, P = self.tube, float(p_gauge_Pa)
        scale = max(abs(P), 1e4)  # unknown pressures are solved in units of the supply pressure
        c3 = -x_m / t.l0
        th_in = math.acos(min(1.0, math.cos(t.theta0) * (1.0 + c3)))

        def fun(z):
            return self.residuals(x_m, P, z[0], z[1], z[2], z[3] * scale, z[4] * scale)

        starts = (("hybr", [0.0, 0.0, th_in, P / scale, 0.0]), ("hybr", [0.0, 0.0, t.theta0, 0.0, 0.0]),
                  ("lm", [0.0, 0.0, th_in, P / scale, 0.0]))
        for method, z0 in starts:
            from scipy.optimize import root  # on first use: pamsim static starts without scipy.optimize

            sol = root(fun, z0, method=method, tol=1e-14)
            if np.all(np.isfinite(sol.x)) and max(abs(v) for v in fun(sol.x)) < 1e-10:
                c1, c2, th, po, ps = sol.x
                P_o, P_s = po * scale, ps * scale
                F_nyl = self.braid_force_N(th, c1, c2, c3, P_o)
                F = P_s * self.A_sil + F_nyl - math.pi * t.r_i ** 2 * P - self.F_u
                return Phase2State(c1, c2, c3, th, P_o, P_s, F_nyl,
                                   F_nyl / (self.strand_stiffness_N * math.cos(th)), F)
        return None

    def phase1_force_N(self, x_m: float, p_gauge_Pa: float) -> float:
        """Eq. (62) with ``u_z = -x``: the axial load that holds the free tube at contraction ``x``."""
        P_s = self.tube.end_stress_for_contraction_Pa(p_gauge_Pa, x_m)
        return (P_s - p_gauge_Pa * self.tube.r_i ** 2 / self.D) * self.load_area - self.F_u

    def in_contact(self, x_m: float, p_gauge_Pa: float) -> bool:
        """Whether the phase-1 tube at contraction ``x`` would reach the sleeve (eq. 68 > 0): phase 2."""
        t = self.tube
        u_r, _ = t.displacements_m(p_gauge_Pa, t.end_stress_for_contraction_Pa(p_gauge_Pa, x_m))
        return t.sleeve_gap_m(u_r, -x_m / t.l0) > 0.0

    def _force_scalar(self, x_m: float, p_gauge_Pa: float) -> float:
        if not self.in_contact(x_m, p_gauge_Pa):
            return self.phase1_force_N(x_m, p_gauge_Pa)
        state = self.phase2_state(x_m, p_gauge_Pa)
        if state is None or state.P_o_Pa < 0.0:
            return math.nan
        return state.force_N

    def force_N(self, x_m, p_gauge_Pa):
        """Pull [N] at contraction ``x_m`` [m] and gauge pressure [Pa]; NaN where phase 2 has no
        compressive-contact solution.  One nonlinear solve per point (arrays are looped)."""
        if np.ndim(x_m) == 0 and np.ndim(p_gauge_Pa) == 0:
            return self._force_scalar(float(x_m), float(p_gauge_Pa))
        x, p = np.broadcast_arrays(np.asarray(x_m, dtype=float), np.asarray(p_gauge_Pa, dtype=float))
        return np.array([self._force_scalar(a, b) for a, b in zip(x.flat, p.flat)]).reshape(x.shape)

    def evaluate_N(self, x_m, p_gauge_Pa):
        """``force_N`` after the domain check; also raises where no physical phase-2 solution exists."""
        F = super().evaluate_N(x_m, p_gauge_Pa)
        bad = ~np.isfinite(np.asarray(F, dtype=float))
        if np.any(bad):
            x, p = np.broadcast_arrays(np.asarray(x_m, dtype=float), np.asarray(p_gauge_Pa, dtype=float))
            raise StaticModelDomainError(f"static model {self.name!r}: x_m = {float(x[bad].flat[0]):g}, "
                                         f"p_gauge_Pa = {float(p[bad].flat[0]):g}: {NO_CONTACT}")
        return F

    def _row_is_physical(self, p_gauge_Pa: float, xs) -> bool:
        return all(math.isfinite(self._force_scalar(x, p_gauge_Pa)) for x in xs)

    def _largest_physical_pressure_Pa(self, n_x: int = 9, n_p: int = 33, n_bisect: int = 12) -> float:
        """Largest pressure up to which every contraction of an ``n_x`` grid has a force, by a scan
        of ``n_p`` pressures from 0 to the rating (or :data:`P_CAP_DEFAULT_PA`) and bisection."""
        xs = np.linspace(self.domain.x_min_m, self.domain.x_max_m, n_x)
        ps = np.linspace(0.0, self.p_cap_Pa, n_p)
        good = 0.0
        for p in ps:
            if not self._row_is_physical(p, xs):
                bad = p
                break
            good = p
        else:
            return self.p_cap_Pa
        for _ in range(n_bisect):
            mid = 0.5 * (good + bad)
            good, bad = (mid, bad) if self._row_is_physical(mid, xs) else (good, mid)
        return float(good)


def _build(params, variant):
    return TwoPhaseForce(params, variant)


SPECS = (
    StaticModelSpec("mpam_two_phase", "implicit",
                    f"two-phase miniature-muscle model: {SURVEY} eqs. (58)-(80): phase 1 eq. (62), "
                    "phase 2 eqs. (60), (70), (72), (78), (79), solved at imposed contraction",
                    ("L0_m", "r0_m", "ri0_m", "theta0_deg", "sleeve_gap_m", "E_bladder_Pa", "nu_bladder",
                     "n_fibres", "fibre_radius_m", "end_cone_length_m", "E_nylon_Pa"),
                    _build, optional={"two_phase_F_u_N": 0.0}, variants=VARIANTS,
                    summary="linear thick tube, free (phase 1) then in contact with an extensible braid (phase 2)"),
)
