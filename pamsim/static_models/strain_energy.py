"""One strain-energy routine for every hyperelastic bladder term (Mooney-Rivlin, Ogden, neo-Hookean).

``elastic_force_N`` is ``F_elastic = -V_b dW/dL`` (static_models_spec.md sec. 1.9 and
sec. 9): the force the stretched bladder takes away from Gaylord's ideal force,
positive while the muscle contracts.  ``W`` is an object with ``grad(l1, l2,
l3)`` returning the partial derivatives of the strain energy density [Pa] with
respect to the three principal stretches; the stretches follow from the braid
kinematics with one of two definitions:

``"mean_radius"`` (Kothera eq. 11, Delson; variable wall thickness from constant
bladder volume): ``l1 = L/L0``, ``l2 = (R - t/2)/(R0 - t0/2)``, ``l3 = t/t0``.

``"thin"`` (Klute-Hannaford, Kothera eq. 7): ``l1 = L/L0``, ``l2 = R/R0``,
``l3 = 1/(l1 l2)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .geometry import Braid
from .real_math import power, sqrt

STRETCHES = ("mean_radius", "thin")


@dataclass(frozen=True)
class MooneyRivlin:
    """``W = C10 (I1 - 3) + C01 (I2 - 3)`` with ``I2 = l1^2 l2^2 + l2^2 l3^2 + l3^2 l1^2`` [Pa]."""

    C10_Pa: float
    C01_Pa: float

    def grad(self, l1, l2, l3):
        """Partial derivatives of ``W`` [Pa] with respect to the three principal stretches."""
        a, c = 2.0 * self.C10_Pa, 2.0 * self.C01_Pa
        s1, s2, s3 = l1 * l1, l2 * l2, l3 * l3
        return (a * l1 + c * l1 * (s2 + s3), a * l2 + c * l2 * (s3 + s1), a * l3 + c * l3 * (s1 + s2))


@dataclass(frozen=True)
class NeoHookean:
    """``W = (E/6) (I1 - 3)`` (Trivedi, survey eq. 23) [Pa]."""

    E_Pa: float

    def grad(self, l1, l2, l3):
        """Partial derivatives of ``W`` [Pa] with respect to the three principal stretches."""
        k = self.E_Pa / 3.0
        return (k * l1, k * l2, k * l3)


@dataclass(frozen=True)
class Ogden:
    """``W = sum_i (mu_i / alpha_i) (l1^alpha_i + l2^alpha_i + l3^alpha_i - 3)`` [Pa].

    ``terms`` is a tuple of ``(mu_i [Pa], alpha_i [-])``; terms with ``mu_i = 0``
    contribute nothing.
    """

    terms: tuple[tuple[float, float], ...]

    def grad(self, l1, l2, l3):
        """Partial derivatives of ``W`` [Pa] with respect to the three principal stretches."""
        g1 = g2 = g3 = 0.0
        for mu, alpha in self.terms:
            if mu == 0.0:
                continue
            e = alpha - 1.0
            g1 = g1 + mu * power(l1, e)
            g2 = g2 + mu * power(l2, e)
            g3 = g3 + mu * power(l3, e)
        return g1, g2, g3


def elastic_force_N(L, braid: Braid, energy, stretch: str = "mean_radius"):
    """Bladder force ``-V_b dW/dL`` [N] at length ``L`` [m] (positive while contracting).

    Parameters
    ----------
    L : float or array, current length [m].
    braid : rest geometry (``Vb``, ``t0``, ``b``, ``N`` ...).
    energy : strain energy with ``grad(l1, l2, l3)`` [Pa].
    stretch : ``"mean_radius"`` or ``"thin"`` (module docstring).
    """
    g = braid
    L0, R0, t0, Vb = g.L0, g.r0, g.t0, g.Vb
    k = 1.0 / (4.0 * math.pi ** 2 * g.N ** 2)
    R2 = (g.b * g.b - L * L) * k
    R = sqrt(R2)
    dR = -L * k / R
    l1 = L / L0
    if stretch == "thin":
        l2 = R / R0
        l3 = 1.0 / (l1 * l2)
        d2 = dR / R0
        d3 = -l3 * (1.0 / L + d2 / l2)
    else:
        s = sqrt(R2 - Vb / (math.pi * L))
        t = R - s
        ds = (R * dR + Vb / (2.0 * math.pi * L * L)) / s
        dt = dR - ds
        m0 = R0 - 0.5 * t0
        l2 = (R - 0.5 * t) / m0
        l3 = t / t0
        d2 = (dR - 0.5 * dt) / m0
        d3 = dt / t0
    w1, w2, w3 = energy.grad(l1, l2, l3)
    return -Vb * (w1 / L0 + w2 * d2 + w3 * d3)
