"""The contract every static force model follows: spec, built model, domain.

A *spec* (:class:`StaticModelSpec`) describes a model family member: its name,
its kind, its source and the muscle parameters it needs.  ``spec.build(params)``
returns a *built model* (a :class:`StaticForce`) whose ``force_N(x_m,
p_gauge_Pa)`` is the raw axial pulling force [N] (positive contracts the
muscle, may be negative) at contraction ``x_m = L0 - L`` [m] and gauge
pressure [Pa].  ``force_N`` does no checking, so that the ODE's inner loop pays
nothing for it; ``evaluate_N`` checks the valid domain first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Callable, Mapping

import numpy as np

from ..errors import InputError
from ..table_checks import did_you_mean  # noqa: F401 -- importable here, as it was

def brentq(*args, **kwargs):
    """``scipy.optimize.brentq``, imported on first use: ``pamsim static`` starts without scipy.optimize."""
    from scipy.optimize import brentq as _brentq

    return _brentq(*args, **kwargs)


KINDS = ("closed-form", "implicit", "table")
"""closed-form: F(x, p) is an explicit formula; implicit: it needs a scalar root
or a small nonlinear solve; table: it interpolates measured or tabulated data."""


class StaticModelDomainError(InputError):
    """A point outside a static model's valid region, or a model that does not apply."""


@dataclass(frozen=True)
class Domain:
    """Valid region of a static model: contraction [m] and gauge pressure [Pa], bounds included."""

    x_min_m: float
    x_max_m: float
    p_min_Pa: float
    p_max_Pa: float

    def violation(self, x_m, p_gauge_Pa) -> str | None:
        """Why some point of ``(x_m, p_gauge_Pa)`` lies outside the domain, or None."""
        x = np.asarray(x_m, dtype=float)
        p = np.asarray(p_gauge_Pa, dtype=float)
        for name, v, lo, hi, unit in (("x_m", x, self.x_min_m, self.x_max_m, "m"),
                                      ("p_gauge_Pa", p, self.p_min_Pa, self.p_max_Pa, "Pa")):
            bad = ~np.isfinite(v) | (v < lo) | (v > hi)
            if np.any(bad):
                first = float(v[bad].flat[0]) if v.ndim else float(v)
                return f"{name} = {first:g} lies outside [{lo:g}, {hi:g}] {unit}"
        return None


class StaticForce:
    """Base class of a built static force model.

    Subclasses set ``name`` and ``domain`` and implement ``force_N``; the other
    methods are shared.
    """

    name: str = ""
    domain: Domain = Domain(0.0, 0.0, 0.0, 0.0)

    def force_N(self, x_m, p_gauge_Pa):  # pragma: no cover - every model overrides it
        """Raw pulling force [N] at contraction ``x_m`` [m] and gauge pressure [Pa]; no checks."""
        raise NotImplementedError

    def evaluate_N(self, x_m, p_gauge_Pa):
        """``force_N`` after checking that every point lies in :attr:`domain`.

        Raises
        ------
        StaticModelDomainError
            Naming the offending value and the domain.
        """
        why = self.domain.violation(x_m, p_gauge_Pa)
        if why:
            raise StaticModelDomainError(f"static model {self.name!r}: {why} (the model's valid domain)")
        return self.force_N(x_m, p_gauge_Pa)

    def blocked_force_N(self, p_gauge_Pa):
        """Force [N] at zero contraction (the blocked force); ``p_gauge_Pa`` a float or an array."""
        return self.force_N(np.zeros_like(p_gauge_Pa, dtype=float) if np.ndim(p_gauge_Pa) else 0.0, p_gauge_Pa)

    def stiffness_N_per_m(self, x_m, p_gauge_Pa, h_m: float = 1e-7):
        """Axial stiffness ``-dF/dx`` [N/m] by a central difference of step ``h_m`` (no domain check)."""
        return (self.force_N(x_m - h_m, p_gauge_Pa) - self.force_N(x_m + h_m, p_gauge_Pa)) / (2.0 * h_m)

    def free_contraction_m(self, p_gauge_Pa: float, load_N: float = 0.0, n_scan: int = 200) -> float:
        """Contraction [m] at which the force equals ``load_N`` (static equilibrium).

        The domain is scanned from ``max(x_min_m, 0)`` (the muscle at rest or,
        for a domain that starts above zero, its low end) for the first fall of
        ``force_N - load_N`` through zero, which is then refined by ``brentq``.
        Returns that start when the muscle cannot lift the load there, and
        ``nan`` when the force stays above the load over the whole domain.
        """
        p = float(p_gauge_Pa)
        lo = max(self.domain.x_min_m, 0.0) if self.domain.x_max_m > 0.0 else self.domain.x_min_m
        xs = np.linspace(lo, self.domain.x_max_m, n_scan + 1)
        g = np.asarray(self.force_N(xs, p), dtype=float) - load_N
        # Round-off: Gaylord's force is exactly zero at the kinematic limit (the domain's end).
        g[np.abs(g) <= 1e-12 * np.max(np.abs(g))] = 0.0
        if g[0] <= 0.0:
            return float(xs[0])
        below = np.nonzero(g <= 0.0)[0]
        if below.size == 0:
            return math.nan
        i = int(below[0])
        if g[i] == 0.0:
            return float(xs[i])
        return float(brentq(lambda x: float(self.force_N(x, p)) - load_N, xs[i - 1], xs[i], xtol=1e-12, rtol=1e-12))


Builder = Callable[[Mapping[str, float], str], StaticForce]


@dataclass(frozen=True)
class StaticModelSpec:
    """One library model: what it needs and how to build it.

    Attributes
    ----------
    name : registry name (snake_case).
    kind : "closed-form", "implicit" or "table".
    source : citation with equation number.
    parameters : required muscle parameter names.
    optional : name -> default for optional parameters (provenance of each default
        in ``docs/static_models.md``).
    variants : selectable forms; the first is the default ("corrected" where the
        printed form is wrong, "printed" reproduces the paper literally).
    summary : one line on what the model is.
    """

    name: str
    kind: str
    source: str
    parameters: tuple[str, ...]
    builder: Builder = field(repr=False)
    optional: Mapping[str, float] = field(default_factory=dict)
    variants: tuple[str, ...] = ("default",)
    summary: str = ""

    def missing(self, params: Mapping[str, float]) -> list[str]:
        """Required parameter names absent from ``params``."""
        return [k for k in self.parameters if k not in params]

    def build(self, params: Mapping[str, float], variant: str | None = None) -> StaticForce:
        """Build the model for a muscle's parameters.

        Raises
        ------
        InputError
            If a required parameter is missing or the variant is unknown.
        """
        missing = self.missing(params)
        if missing:
            raise InputError(f"static model {self.name!r} needs parameter(s) {', '.join(missing)}, "
                             "which the muscle does not give")
        variant = self.variants[0] if variant is None else variant
        if variant not in self.variants:
            raise InputError(f"static model {self.name!r}: variant = {variant!r}: unknown "
                             f"(choose from {', '.join(self.variants)})")
        merged = dict(self.optional)
        # Values are numbers, except file paths such as force_map_file.
        merged.update({k: v if isinstance(v, (str, Path)) else float(v) for k, v in params.items()})
        return self.builder(MappingProxyType(merged), variant)


def rated_pressure_Pa(params: Mapping[str, float]) -> float:
    """Highest gauge pressure of a model's domain: the muscle's rating, else unbounded."""
    return float(params.get("rated_pressure_gauge_Pa", math.inf))
