"""End stops: a lower stop at x = 0 and an upper stop where the muscle can shorten no further.

Both are rigid unilateral contacts with a coefficient of restitution (0 by
default: perfectly inelastic).  They are handled as hybrid modes of the
simulator, so the contraction never passes them; the contact force is
reported in the results.

Where the upper stop stands is a choice (:data:`UPPER_STOPS`; muscle file
``[upper_stop] at``, scenario ``[model] upper_stop``, ``pamsim static
--upper-stop``; docs/model.md sec. 5).  The braid-lock angle 54.7 deg, where
the ideal force vanishes, is no lock: a model with a wall or an elastic
bladder holds loads beyond it (MODEL_NOTES sec. 5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from ..core_table import MIN_REBOUND_SPEED_M_S
from ..parameter_schema import UPPER_BASES, UPPER_STOP_DEFAULT, UPPER_STOPS
from ..static_models.geometry import Braid

__all__ = ["EndStops", "UPPER_BASES", "UPPER_STOP_DEFAULT", "UPPER_STOPS", "fibre_width_m", "upper_stop_m"]


@dataclass(frozen=True)
class EndStops:
    """Lower and upper stop positions [m], restitution [-], and what placed the upper stop
    (``upper_basis``: ``"jam"``, ``"domain_end"`` or ``"braid_lock"``)."""

    x_low_m: float
    x_high_m: float
    restitution: float
    min_rebound_speed_m_s: float = MIN_REBOUND_SPEED_M_S
    upper_basis: str = "braid_lock"

    @classmethod
    def from_parameters(cls, p: Mapping[str, float]) -> "EndStops":
        """Stops at zero contraction and at the braid lock of the muscle's geometry, with its
        ``stop_restitution`` (the ``braid_lock`` choice, without a static model).
        """
        return cls(0.0, Braid.from_parameters(p).x_lock_m, p["stop_restitution"])

    @classmethod
    def for_model(cls, p: Mapping[str, float], domain_x_max_m: float, at: str = UPPER_STOP_DEFAULT) -> "EndStops":
        """Stops at zero contraction and where choice ``at`` (:data:`UPPER_STOPS`) puts the upper stop, for
        a muscle's parameters ``p`` and a static model whose domain ends at ``domain_x_max_m`` [m].

        Raises
        ------
        ValueError
            For an unknown choice, a jam angle asked of a muscle without fibre data, or fibres that
            could not move (:meth:`pamsim.static_models.geometry.Braid.x_jam_m`).
        """
        x_high, basis = upper_stop_m(p, domain_x_max_m, at)
        return cls(0.0, x_high, p["stop_restitution"], upper_basis=basis)


def fibre_width_m(p: Mapping[str, float]) -> tuple[float, str] | None:
    """``(width [m], key)`` of one braid fibre on the braid's surface: ``fibre_width_m``, else the diameter of a
    round strand, twice ``fibre_radius_m``; None if the muscle gives neither."""
    for key, factor in (("fibre_width_m", 1.0), ("fibre_radius_m", 2.0)):
        if key in p:
            return factor * p[key], key
    return None


def _x_jam_m(braid: Braid, p: Mapping[str, float], width: tuple[float, str] | None) -> float:
    """The jam contraction of ``braid`` [m] with the muscle's fibres; a ValueError names the keys it comes from."""
    if width is None or "n_fibres" not in p:
        raise ValueError("a jam angle needs the fibre count n_fibres and the fibre width fibre_width_m "
                         "(or a round strand's fibre_radius_m), which the muscle does not give")
    try:
        return braid.x_jam_m(width[0], p["n_fibres"])
    except ValueError as exc:
        raise ValueError(f"{width[1]} = {p[width[1]]:g} with n_fibres = {p['n_fibres']:g}: {exc}") from None


def upper_stop_m(p: Mapping[str, float], domain_x_max_m: float, at: str) -> tuple[float, str]:
    """``(contraction [m], basis)`` of the upper stop that choice ``at`` gives (see :meth:`EndStops.for_model`)."""
    if at not in UPPER_STOPS:
        raise ValueError(f"unknown upper stop choice (choose from {', '.join(UPPER_STOPS)})")
    braid = Braid.from_parameters(p)
    width = fibre_width_m(p)
    if at == "auto":
        at = "jam" if width is not None and "n_fibres" in p else "domain_end"
    if at == "braid_lock":
        return braid.x_lock_m, "braid_lock"
    # Past its domain's end a model has no value (a bladder that would fill the braid) or no validity.
    end = domain_x_max_m if math.isfinite(domain_x_max_m) and 0.0 < domain_x_max_m < braid.L0 else None
    if at == "domain_end":
        return (end, "domain_end") if end is not None else (braid.x_lock_m, "braid_lock")
    x_jam = _x_jam_m(braid, p, width)
    return (end, "domain_end") if end is not None and end < x_jam else (x_jam, "jam")
