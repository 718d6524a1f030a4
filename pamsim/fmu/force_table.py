"""A static force F(x, p) tabulated for the FMU.

Any static model reaches the FMU the same way: :func:`tabulate` samples its ``force_N(x_m,
p_gauge_Pa)`` over a domain into the one table scheme of pamsim
(:mod:`pamsim.elements.force_table`): the bicubic interpolating spline of the samples on a grid
that starts uniform (:data:`DEFAULT_POINTS`) and is refined where the spline misses the model,
held at the grid's edges, never extrapolated.  The same knots and coefficients are evaluated by
SciPy in Python and, as a CasADi B-spline, in the FMU's generated C.

An FMU built with a table picks it with ``static_force_model = table``; its travel is bounded by
the table's contraction range, and an FMU built without one refuses that choice at initialisation.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from ..elements import force_table as spline_tables
from ..errors import InputError
from ..static_models.base import Domain

DEFAULT_POINTS = (spline_tables.N_X, spline_tables.N_P)
"""Grid nodes (x, p) the table starts from: 64 x 32 cells, refined where the spline misses the model
(:data:`pamsim.elements.force_table.REFINE_TOL`)."""


@dataclass(frozen=True, eq=False)
class ForceTable:
    """A static model's table over contraction ``x_min_m`` .. ``x_max_m`` and gauge pressure ``p_min_Pa`` ..
    ``p_max_Pa``: its ``force_N`` is the interpolating spline, held at the edges (``spline``)."""

    model_name: str
    x_min_m: float
    x_max_m: float
    p_min_Pa: float
    p_max_Pa: float
    spline: spline_tables.TabulatedStaticForce = field(repr=False)

    @property
    def name(self) -> str:
        """The tabulated model's name."""
        return self.model_name

    @property
    def shape(self) -> tuple[int, int]:
        """Grid nodes along the contraction and along the pressure."""
        return len(self.spline.x_grid_m), len(self.spline.p_grid_Pa)

    def force_N(self, x_m, p_gauge_Pa):
        """The table's force [N] at ``(x_m, p_gauge_Pa)``, held inside the grid (floats, arrays or CasADi MX)."""
        return self.spline.force_N(x_m, p_gauge_Pa)

    def code_key(self) -> tuple:
        """What code generated from the table depends on (:func:`pamsim.components.element.structure_key`)."""
        return ("force_table", self.model_name, self.spline._surface.code_key())

    def digest(self) -> str:
        """A hash of the table: the model's name, the grid and the values (the FMU's token and build cache)."""
        h = hashlib.sha256(self.model_name.encode())
        for a in (self.spline.x_grid_m, self.spline.p_grid_Pa, self.spline.F_N):
            h.update(np.ascontiguousarray(a, dtype=float).tobytes())
        return h.hexdigest()


@dataclass(frozen=True)
class _Over:
    """A model seen over the domain it is tabulated on (its own ``domain`` may be wider or missing)."""

    model: object
    name: str
    domain: Domain

    def force_N(self, x_m, p_gauge_Pa):
        return self.model.force_N(x_m, p_gauge_Pa)


def tabulate(static_force, x_range_m: tuple[float, float], p_range_Pa: tuple[float, float],
             points: tuple[int, int] = DEFAULT_POINTS, model_name: str | None = None, refine: bool = True) -> ForceTable:
    """Tabulate ``static_force.force_N`` over ``x_range_m`` x ``p_range_Pa`` (the module's scheme; ``refine``
    False keeps the ``points`` grid as it is).

    Raises
    ------
    InputError
        An empty or non-finite domain, fewer than 2 x 2 nodes, or a model that gives a non-finite
        force in its domain.
    """
    name = model_name or getattr(static_force, "name", type(static_force).__name__)
    (x0, x1), (p0, p1) = (map(float, x_range_m)), (map(float, p_range_Pa))
    if not (np.isfinite([x0, x1, p0, p1]).all() and x1 > x0 and p1 > p0):
        raise InputError(f"static model {name!r}: cannot tabulate over x {x0:g}..{x1:g} m, p {p0:g}..{p1:g} Pa "
                         "(an empty or unbounded domain)")
    nx, n_p = points
    if nx < 2 or n_p < 2:
        raise InputError(f"static model {name!r}: a force table needs at least 2 x 2 nodes, not {nx} x {n_p}")
    over = _Over(static_force, name, Domain(x0, x1, p0, p1))
    try:
        spline = spline_tables.tabulate(over, (x0, x1), (p0, p1), nx, n_p,
                                        refine_tol=spline_tables.REFINE_TOL if refine else None)
    except ValueError:
        raise InputError(f"static model {name!r}: non-finite force in its domain "
                         f"(x {x0:g}..{x1:g} m, p {p0:g}..{p1:g} Pa); it cannot be tabulated") from None
    return ForceTable(name, x0, x1, p0, p1, spline)
