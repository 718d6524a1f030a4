"""A static model that has no value outside its valid domain, held at the domain's edge.

The dynamics can reach contractions from 0 to the braid-lock stop and gauge
pressures from 0 to the rating.  A model that stays finite there beyond its
domain (the polynomial past its fitted range) is extrapolated, and the run is
flagged as out of range.  A model that has no value there (a logarithm of the
pressure at 0 gauge, a square root past its own contraction limit) is evaluated
at the nearest point of its domain instead (a pamsim choice, docs/model.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .force_clip import WrappedStaticForce

_PROBE = 21


@dataclass(frozen=True)
class DomainClampedForce(WrappedStaticForce):
    """``inner.force_N`` at ``(x, p)`` moved into ``[x_lo, x_hi] x [p_lo, p_hi]`` [m, Pa]."""

    inner: object
    x_lo: float
    x_hi: float
    p_lo: float
    p_hi: float

    def force_N(self, x_m, p_gauge_Pa):
        """Force [N] at the nearest point of the domain to ``(x_m, p_gauge_Pa)``."""
        if type(x_m) is float and type(p_gauge_Pa) is float:
            x = min(max(x_m, self.x_lo), self.x_hi)
            p = min(max(p_gauge_Pa, self.p_lo), self.p_hi)
            return self.inner.force_N(x, p)
        return self.inner.force_N(np.clip(x_m, self.x_lo, self.x_hi), np.clip(p_gauge_Pa, self.p_lo, self.p_hi))


def _finite(model, x: float, p: float) -> bool:
    try:
        return math.isfinite(float(model.force_N(x, p)))
    except (ValueError, ZeroDivisionError, OverflowError):
        return False


def within_domain_if_needed(model, x_range_m: tuple[float, float], p_range_Pa: tuple[float, float]):
    """``model`` itself if it is finite over the reachable region, else it clamped to its domain."""
    try:
        return _within_domain_cached(model, tuple(x_range_m), tuple(p_range_Pa))
    except TypeError:  # a model that cannot be hashed (it holds arrays): decided afresh
        return _within_domain(model, x_range_m, p_range_Pa)


@lru_cache(maxsize=256)
def _within_domain_cached(model, x_range_m: tuple[float, float], p_range_Pa: tuple[float, float]):
    # Models are immutable values: a sweep that builds the same model thousands of times probes it once.
    return _within_domain(model, x_range_m, p_range_Pa)


def _within_domain(model, x_range_m, p_range_Pa):
    # Point by point, as the dynamics evaluate it: a model's array form may guard what its scalar form does not.
    xs = np.linspace(x_range_m[0], x_range_m[1], _PROBE)
    ps = np.linspace(p_range_Pa[0], p_range_Pa[1], _PROBE)
    if all(_finite(model, float(x), float(p)) for x in xs for p in ps):
        return model
    d = model.domain
    return DomainClampedForce(model, d.x_min_m, d.x_max_m, d.p_min_Pa, d.p_max_Pa)
