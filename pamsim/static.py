"""Static analysis: the equilibrium contraction under a load, the friction band
around it, and the force capability (largest load held above the lower stop).
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from .elements.stops import EndStops


def _first_fall_through_zero(excess, x_max_m: float, n_grid: int = 400) -> float:
    """Smallest x in [0, x_max_m] where ``excess(x)`` falls through zero: 0 if it starts at or
    below zero, ``x_max_m`` if it never falls."""
    x = np.linspace(0.0, x_max_m, n_grid)
    g = excess(x)
    if g[0] <= 0.0:
        return 0.0
    falls = np.flatnonzero((g[:-1] > 0.0) & (g[1:] <= 0.0))
    if falls.size == 0:
        return float(x_max_m)
    i = int(falls[0])
    return _bisect_falling(excess, float(x[i]), float(x[i + 1]))


def _bisect_falling(excess, a: float, b: float, xtol: float = 1e-12) -> float:
    """Root of ``excess`` in [a, b] with ``excess(a) > 0 >= excess(b)``, by bisection to ``xtol``.

    Plain bisection rather than scipy's brentq: importing scipy.optimize costs
    several times the rest of ``pamsim static`` (the command must start fast),
    and about 30 halvings of one grid cell reach ``xtol``.
    """
    while b - a > xtol:
        mid = 0.5 * (a + b)
        if mid in (a, b):  # no float between them
            break
        if excess(mid) > 0.0:
            a = mid
        else:
            b = mid
    return 0.5 * (a + b)


def equilibrium_contraction_m(static_force, p_gauge_Pa: float, load_N: float, x_max_m: float) -> float:
    """Smallest contraction x in [0, x_max_m] where F_static(x, p) = load with F falling through it.

    Returns 0 when the muscle cannot lift the load off the lower stop, and
    ``x_max_m`` when it still pulls harder than the load there.
    """
    return _first_fall_through_zero(lambda x: static_force.force_N(x, p_gauge_Pa) - load_N, x_max_m)


def max_load_N(static_force, p_gauge_Pa: float, x_max_m: float, n_grid: int = 400) -> float:
    """Force capability: the largest static force over [0, x_max_m] (0 if it cannot pull at all).

    Pass the fitted range as ``x_max_m``: beyond it the polynomial is an
    extrapolation and its values say nothing about what the muscle can hold.
    """
    x = np.linspace(0.0, x_max_m, n_grid)
    return max(float(np.max(static_force.force_N(x, p_gauge_Pa))), 0.0)


def friction_band_m(static_force, friction, p_gauge_Pa: float, mass_kg: float, g_m_s2: float,
                    x_max_m: float) -> tuple[float, float]:
    """Contractions ``(x_lo, x_hi)`` between which a load at rest stays stuck.

    With F_static falling in x, the band runs from where F_static = W + F_c to
    where F_static = W - F_c.
    """
    W = mass_kg * g_m_s2

    def edge(sign: float) -> float:
        return _first_fall_through_zero(lambda x: static_force.force_N(x, p_gauge_Pa) - W
                                        - sign * friction.level_N(x, p_gauge_Pa, mass_kg), x_max_m)

    return edge(+1.0), edge(-1.0)


def static_report(params: Mapping[str, float], static_force, p_gauge_Pa: float, load_N: float,
                  stops: EndStops | None = None) -> dict:
    """The figures ``pamsim static`` prints.

    ``static_force`` is a library model (:mod:`pamsim.static_models`): its
    valid domain bounds the force capability (beyond it a fitted model
    extrapolates and says nothing about what the muscle can hold) and decides
    ``within_fit_range``.  ``stops`` are the muscle's end stops
    (:func:`pamsim.muscle_setup.end_stops`, or a scenario's ``build_model().stops``);
    without them the upper stop is the braid lock of ``params``' geometry, where
    pamsim put it before the stop became a choice.  ``on_stop`` is ``"upper"``
    or ``"lower"`` when the load rests on that stop, else None.
    """
    d = static_force.domain
    stops = EndStops.from_parameters(params) if stops is None else stops
    x_hi = stops.x_high_m
    x_eq = equilibrium_contraction_m(static_force, p_gauge_Pa, load_N, x_hi)
    on_stop = stop_at(static_force, p_gauge_Pa, load_N, x_eq, x_hi)
    note = ("held at the upper stop: the model still pulls harder than the load there, "
            "so no equilibrium lies before it") if on_stop == "upper" else ""
    return {"pressure_gauge_Pa": p_gauge_Pa, "load_N": load_N, "equilibrium_contraction_m": x_eq,
            "equilibrium_note": note, "on_stop": on_stop,
            "max_load_N": max_load_N(static_force, p_gauge_Pa, min(x_hi, d.x_max_m)), "lifts_load": x_eq > 0.0,
            "upper_stop_m": x_hi, "upper_stop_basis": stops.upper_basis,
            "within_fit_range": bool(d.x_min_m <= x_eq <= d.x_max_m and d.p_min_Pa <= p_gauge_Pa <= d.p_max_Pa)}


def stop_at(static_force, p_gauge_Pa: float, load_N: float, x_eq_m: float, x_high_m: float) -> str | None:
    """``"upper"`` or ``"lower"`` when the equilibrium ``x_eq_m`` of
    :func:`equilibrium_contraction_m` is a stop that holds the load, else None (a free equilibrium)."""
    if x_eq_m >= x_high_m and float(static_force.force_N(x_high_m, p_gauge_Pa)) > load_N:
        return "upper"
    if x_eq_m <= 0.0 and float(static_force.force_N(0.0, p_gauge_Pa)) < load_N:
        return "lower"
    return None
