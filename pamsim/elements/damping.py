"""Viscous damping force F_damp(v) [N], opposing the motion when positive.

Every law here is zero at v = 0, which the stick/slip logic relies on.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from ..modeling.smath import sqrt
from .contracts import NO_OPTIONS, Builder, Damping, ElementOptions


@dataclass(frozen=True)
class PaperDamping:
    """Literal reading of paper eq. (8): ``D1 v + D2 v |v|`` (MODEL_NOTES sec. 3).

    With the paper's D1 < 0 this adds energy below ``|v| = -D1/D2``; the work
    balance in the results reports it.
    """

    D1_N_s_per_m: float
    D2_N_s2_per_m2: float
    name: str = "paper"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> "PaperDamping":
        """The paper's damping with D1 and D2 of the muscle's parameters."""
        return cls(p["D1_N_s_per_m"], p["D2_N_s2_per_m2"])

    def force_N(self, v_m_s):
        """Damping force [N]: ``(D1 + D2 |v|) v``."""
        return (self.D1_N_s_per_m + self.D2_N_s2_per_m2 * abs(v_m_s)) * v_m_s

    def velocity_m_s(self, F_N):
        """The velocity [m/s] at which the force is ``F_N``: the root of ``D2 v|v| + D1 v = F`` of the
        sign of ``F``, ``2 F / (D1 + sqrt(D1^2 + 4 D2 |F|))`` (the form without cancellation).  Unique
        only for ``D1 > 0``, ``D2 >= 0`` (:func:`increasing`)."""
        D1, D2 = self.D1_N_s_per_m, self.D2_N_s2_per_m2
        return 2.0 * F_N / (D1 + sqrt(D1 * D1 + 4.0 * D2 * abs(F_N)))


@dataclass(frozen=True)
class LinearDamping:
    """``c v`` with ``c = |D1|``: a dissipative alternative to the paper reading."""

    c_N_s_per_m: float
    name: str = "linear"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> "LinearDamping":
        """Linear damping with ``c = |D1|`` of the muscle's parameters."""
        return cls(abs(p["D1_N_s_per_m"]))

    def force_N(self, v_m_s):
        """Damping force [N]: ``c v``."""
        return self.c_N_s_per_m * v_m_s

    def velocity_m_s(self, F_N):
        """The velocity [m/s] at which the force is ``F_N``: ``F / c``."""
        return F_N / self.c_N_s_per_m


@dataclass(frozen=True)
class NoDamping:
    """No viscous damping."""

    name: str = "none"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float], options: ElementOptions = NO_OPTIONS) -> "NoDamping":
        """No damping; the parameters are not read."""
        return cls()

    def force_N(self, v_m_s):
        """Zero, of the shape of ``v_m_s``."""
        return 0.0 * v_m_s


def increasing(damping) -> bool:
    """Whether ``damping``'s force grows strictly with velocity through zero, so that a force gives one
    velocity (:meth:`PaperDamping.velocity_m_s`): what a massless muscle end needs (its velocity is the one
    at which damping takes the force that friction and the tendon leave).  The paper's ``D1 < 0`` is not:
    its force falls with speed below ``|D1| / D2``."""
    if isinstance(damping, PaperDamping):
        return damping.D1_N_s_per_m > 0.0 and damping.D2_N_s2_per_m2 >= 0.0
    if isinstance(damping, LinearDamping):
        return damping.c_N_s_per_m > 0.0
    return False


DAMPING_MODELS: dict[str, Builder[Damping]] = {
    "paper": PaperDamping.from_parameters,
    "linear": LinearDamping.from_parameters,
    "none": NoDamping.from_parameters,
}
