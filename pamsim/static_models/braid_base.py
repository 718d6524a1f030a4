"""Common base of the models built on braid kinematics (Gaylord and its descendants)."""

from __future__ import annotations

from typing import Mapping


from .base import Domain, StaticForce, rated_pressure_Pa, brentq
from .geometry import Braid
from .real_math import sqrt

GEOMETRY = ("L0_m", "r0_m", "theta0_deg")
"""Rest length, braid radius at rest and rest braid angle from the axis: what every braid model needs."""
WALL = GEOMETRY + ("wall_thickness_m",)


class BraidModel(StaticForce):
    """A static model of a braided muscle: rest geometry, domain and a few constants.

    ``x_max_m`` is the largest valid contraction; by default the Gaylord
    kinematic limit (braid angle 54.7356 deg), past which an inextensible braid
    cannot shorten without the bladder pushing it.
    """

    name = ""

    def __init__(self, params: Mapping[str, float], variant: str = "default"):
        self.g = Braid.from_parameters(params)
        self.variant = variant
        self.L0 = self.g.L0
        self.b2 = self.g.b ** 2
        self.k_gaylord = 1.0 / (4.0 * 3.141592653589793 * self.g.N ** 2)
        self.domain = Domain(0.0, self.x_max_m(params), 0.0, rated_pressure_Pa(params))

    def x_max_m(self, params: Mapping[str, float]) -> float:
        """Largest contraction of the domain [m]; subclasses with a bladder may extend or shrink it."""
        return self.g.x_lock_m

    def gaylord_N(self, L, p):
        """Gaylord's ideal force [N] at length ``L`` [m]: ``p (3 L^2 - b^2) / (4 pi N^2)`` (Kothera eq. 2)."""
        return p * (3.0 * L * L - self.b2) * self.k_gaylord

    def sin_theta(self, L):
        """Sine of the braid angle from the axis at length ``L``: ``sqrt(1 - (L/b)^2)``."""
        return sqrt(1.0 - L * L / self.b2)


class BladderModel(BraidModel):
    """A braid model with a constant-volume bladder: the domain ends where the bladder fills the braid.

    With a nonzero ``tip_factor`` ``k`` the model is evaluated at a tip-corrected
    length ``L' = L - k (R(L) - R0)`` (Kothera eq. 24: ``k = 2``, explicit radius
    ``R(L)``; Hocking: ``k = 2 (pi/2 - 1)``), and the domain shrinks so that ``L'``
    stays valid.  Subclasses set ``tip_factor`` before calling ``__init__``.
    """

    tip_factor = 0.0

    def x_max_m(self, params):
        margin = 1e-9 * self.L0  # keeps the square root of the thickness formula real at the domain's end
        x_fill = self.g.x_fill_m() - margin
        if not self.tip_factor:
            return x_fill
        L_fill = self.L0 - x_fill
        return self.L0 - brentq(lambda L: self.tip_length_m(L) - L_fill, L_fill, self.L0, xtol=1e-15) - margin

    implicit_tips = False
    """Evaluate the tip radius at the corrected length, ``L' = L - k (R(L') - R0)`` (Kothera leaves it open)."""

    def tip_length_m(self, L):
        """Tip-corrected cylindrical length ``L - k (R(L) - R0)`` [m], or its implicit form.

        The implicit form is solved by fixed-point iteration from the explicit value;
        the map contracts by ``k |dR/dL|``, well below one inside the domain.
        """
        Lc = L - self.tip_factor * (self.g.radius_m(L) - self.g.r0)
        if self.implicit_tips:
            for _ in range(60):
                Lc = L - self.tip_factor * (self.g.radius_m(Lc) - self.g.r0)
        return Lc

    def effective_length_m(self, x_m):
        """Length at which the cylinder formulas are evaluated: ``L`` or the tip-corrected ``L'``."""
        L = self.L0 - x_m
        return self.tip_length_m(L) if self.tip_factor else L
