"""Braid and bladder geometry shared by the physical models.

Conventions (static_models_spec.md sec. 1): ``theta`` is the braid angle from the
muscle axis; the fibre length ``b`` and number of turns ``N`` follow from the
rest length ``L0``, the braid radius at rest ``r0`` and ``theta0``:
``L = b cos(theta)``, ``2 pi r N = b sin(theta)``.  The bladder volume
``V_b = pi L0 (r0^2 - ri0^2)`` is constant (incompressible rubber).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from ..core_table import BRAID_LOCK_SEC2
from ..modeling import smath
from .base import brentq
from .real_math import sqrt



@dataclass(frozen=True)
class Braid:
    """Rest geometry of a braided muscle, SI units.

    Attributes
    ----------
    L0 : rest length [m].  r0 : braid (= bladder outer) radius at rest [m].
    theta0 : rest braid angle from the axis [rad].  t0 : bladder wall thickness at rest [m]
    (0 when the muscle gives none).  b : fibre length [m].  N : turns of one fibre [-].
    Vb : bladder wall volume [m^3].
    """

    L0: float
    r0: float
    theta0: float
    t0: float
    b: float
    N: float
    Vb: float

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "Braid":
        """The braid of a muscle's ``L0_m``, ``r0_m``, ``theta0_deg`` and ``wall_thickness_m`` (0 if not given)."""
        L0, r0 = p["L0_m"], p["r0_m"]
        # smath: the same numbers on floats, and the geometry on symbols for generated code that derives it.
        theta0 = smath.radians(p["theta0_deg"])
        t0 = p.get("wall_thickness_m", 0.0)
        b = L0 / smath.cos(theta0)
        N = b * smath.sin(theta0) / (2.0 * math.pi * r0)
        Vb = math.pi * L0 * (r0 ** 2 - (r0 - t0) ** 2)
        return cls(L0, r0, theta0, t0, b, N, Vb)

    @property
    def ri0(self) -> float:
        """Bladder inner radius at rest [m]."""
        return self.r0 - self.t0

    @property
    def gaylord_area_m2(self) -> float:
        """``b^2 / (4 pi N^2)``: Gaylord's force per pressure is this times ``3 cos^2(theta) - 1``."""
        return self.b ** 2 / (4.0 * math.pi * self.N ** 2)

    @property
    def x_lock_m(self) -> float:
        """Contraction at the Gaylord kinematic limit, where ``3 cos^2(theta) = 1``."""
        return self.L0 - self.b / smath.sqrt(BRAID_LOCK_SEC2)

    def x_jam_m(self, fibre_width_m: float, n_fibres: float) -> float:
        """Contraction [m] at the braid's jam angle, where neighbouring fibres of one helix touch.

        ``n_fibres`` fibres in all, half of them in each helix sense, each ``fibre_width_m`` wide on the
        braid's surface.  At braid angle ``theta`` the radius is ``r = r_max sin(theta)`` with
        ``r_max = b / (2 pi N)``, and the gap between neighbours of one sense, measured square to them, is
        ``4 pi r cos(theta) / n - w``; it closes where ``sin(2 theta) = n w / (2 pi r_max)``.  Of the two
        roots the one above 45 deg is where a shortening braid jams (the one below is Davis' ``theta_min``,
        MPAM survey eq. 10, where a lengthening braid jams).

        Raises
        ------
        ValueError
            If the fibres are so wide or so many that they would touch at the rest angle already, or at
            every angle.
        """
        cover = n_fibres * fibre_width_m * self.N / self.b  # n w / (2 pi r_max)
        if cover >= 1.0:
            raise ValueError("the fibres would cover the braid at every angle: the braid could not move")
        half = 0.5 * math.asin(cover)
        if not half <= self.theta0 <= 0.5 * math.pi - half:
            raise ValueError(f"the fibres would touch at the rest braid angle {math.degrees(self.theta0):g} deg "
                             f"(they fit only between {math.degrees(half):.4g} and {90.0 - math.degrees(half):.4g} deg)")
        return self.L0 - self.b * math.cos(0.5 * math.pi - half)

    @property
    def q1(self) -> float:
        """``3 / tan^2(theta0)``, the first constant of Gaylord's normalised law."""
        return 3.0 / math.tan(self.theta0) ** 2

    @property
    def q2(self) -> float:
        """``1 / sin^2(theta0)``, the second constant of Gaylord's normalised law."""
        return 1.0 / math.sin(self.theta0) ** 2

    def radius_m(self, L):
        """Braid radius [m] at length ``L`` [m]: ``sqrt(b^2 - L^2) / (2 pi N)``."""
        return sqrt(self.b * self.b - L * L) / (2.0 * math.pi * self.N)

    def thickness_m(self, L, R=None):
        """Wall thickness [m] at length ``L`` from constant bladder volume (Kothera eq. 16)."""
        R = self.radius_m(L) if R is None else R
        return R - sqrt(R * R - self.Vb / (math.pi * L))

    def x_fill_m(self) -> float:
        """Contraction [m] at which a constant-volume bladder fills the braid (``R^2 = V_b/(pi L)``).

        Beyond it the wall-thickness formula has no real value.  Without a
        bladder nothing fills the braid and ``L0`` (zero length) is returned.
        """
        if self.Vb <= 0.0:
            return self.L0
        def g(L):
            return self.radius_m(L) ** 2 - self.Vb / (math.pi * L)
        L_lo = 1e-9 * self.L0
        L_peak = self.b / math.sqrt(BRAID_LOCK_SEC2)  # R^2 L is largest here, so g's root lies below it
        if g(L_peak) <= 0.0:
            return 0.0
        if g(L_lo) >= 0.0:
            # A wall so thin (a fit passes through such walls) that it would fill the braid only at
            # a length below L_lo: as without a bladder, nothing fills it over any real stroke.
            return self.L0
        return self.L0 - brentq(g, L_lo, L_peak, xtol=1e-15)
