"""The static force as the dynamics apply it: a library model, tabulated if it
needs a numerical solve, held inside its domain where it has no value outside
it, with a negative force clipped at zero.

Every choice here is a scenario key (docs/scenarios.md): ``static_force``
(any model of :mod:`pamsim.static_models`), ``static_force_variant`` and
``static_force_negative``.
"""

from __future__ import annotations

from typing import Mapping

from ..static_models import get
from .force_clip import with_negative_force
from .force_domain import within_domain_if_needed
from .force_table import cache_key, tabulate


def dynamics_static_force(model: str, params: Mapping[str, float], x_range_m: tuple[float, float],
                          variant: str | None = None, negative: str = "clip", built=None):
    """Build library model ``model`` for ``params`` as the ODE evaluates it.

    Parameters
    ----------
    model : registry name.
    params : the muscle's parameters (with the dynamics' defaults).
    x_range_m : contractions the dynamics can reach (the stops) [m]; an implicit
        model is tabulated over this range (within its domain) and 0 .. the
        rated pressure.
    variant : the model's variant (None: its default).
    negative : ``"clip"`` or ``"keep"`` (:mod:`pamsim.elements.force_clip`).
    built : the library model already built from ``params`` and ``variant`` (built here if None).
    """
    spec = get(model)
    built = spec.build(params, variant) if built is None else built
    p_range = (0.0, params["rated_pressure_gauge_Pa"])
    if spec.kind == "implicit":
        built = tabulate(built, x_range_m, p_range, key=cache_key(model, variant, params))
    else:
        built = within_domain_if_needed(built, x_range_m, p_range)
    return with_negative_force(built, negative)
