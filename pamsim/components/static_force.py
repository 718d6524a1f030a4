"""The muscle's static force F_static(x, p): a branch on the load's flange, driven by the pressure."""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var
from ..modeling.component import quiet_numpy_on_symbols
from .element import ElementParameters, element_parameters, structure_key

_TRACES: dict = {}


class MuscleStaticForce(ElementParameters, Component):
    """A static force as the dynamics apply it (:func:`pamsim.elements.muscle_force.dynamics_static_force`).

    An element written in operations that act on symbols (the closed-form models) becomes equations
    with its numbers as parameters; one that is not (a force table, a numerical solve) is called on
    floats as an external function (:attr:`pamsim.modeling.component.Symbols.external`), which runs
    in Python only.  State ``W_muscle_J``: the muscle's work, integral of ``F v``.
    """

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    inputs = (Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"),)
    states = (Var("W_muscle_J", "J", "work done by the static force", 0.1),)
    outputs = (Var("F_static_N", "N", "static muscle force along x"),)

    def __init__(self, name: str, element):
        self.element = element
        key = structure_key(element)
        if key not in _TRACES:  # whether an element traces depends on its form, not on its numbers
            _TRACES[key] = _traces(element)
        self.traces = _TRACES[key]
        super().__init__(name, element_parameters(element) if self.traces else {})

    def parameter_vars(self):
        return super().parameter_vars() if self.traces else ()

    def structure_key(self) -> tuple:
        # An element called on floats is part of the generated code: its numbers are too.
        return super().structure_key() + (() if self.traces else (structure_key(self.element, baked=True),))

    def equations(self, s: Symbols) -> Equations:
        x, v = s.port["flange"]["x_m"], s.port["flange"]["v_m_s"]
        if self.traces:
            F = self.symbolic_element(s.p).force_N(x, s.u["p_gauge_Pa"])
        else:
            F = s.external("force_N", self.element.force_N, x, s.u["p_gauge_Pa"])
        return Equations(der={"W_muscle_J": F * v}, outputs={"F_static_N": F}, port={"flange": {"F_N": F}})


PROBE_X_M = (0.0, 0.002, 0.005, 0.01, 0.02, 0.04)
PROBE_P_PA = (0.0, 0.5e5, 1e5, 3e5, 6e5)


def _traces(element) -> bool:
    """Whether ``force_N`` gives on symbols the value it gives on floats: not for a table lookup, a
    numerical solve, or a :mod:`math` call (which turns a symbol into NaN without a word).  Compared
    wherever the float value is finite, at a grid of contractions and pressures."""
    import casadi as ca

    x, p = ca.SX.sym("x"), ca.SX.sym("p")
    try:
        with quiet_numpy_on_symbols(), warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)  # a table's array path, probed with a symbol
            fn = ca.Function("F", [x, p], [ca.SX(element.force_N(x, p))])
    except Exception:
        return False
    for xv in PROBE_X_M:
        for pv in PROBE_P_PA:
            try:
                want = element.force_N(xv, pv)
            except (ValueError, ZeroDivisionError, OverflowError):
                continue  # no value here on floats: nothing to compare
            if isinstance(want, complex) or not math.isfinite(want):
                continue
            got = float(fn(xv, pv))
            if not abs(got - want) <= 1e-9 * max(1.0, abs(want)):
                return False
    return True
