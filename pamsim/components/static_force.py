"""The muscle's static force F_static(x, p): a branch on the load's flange, driven by the pressure."""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var
from .element import ElementParameters

PROBE_POINTS = tuple((x, p) for x in (0.0, 0.002, 0.005, 0.01, 0.02, 0.04) for p in (0.0, 0.5e5, 1e5, 3e5, 6e5))
"""Contractions [m] and gauge pressures [Pa] at which a static force's symbolic form is checked."""


def _force_N(element, x_m, p_gauge_Pa):
    return element.force_N(x_m, p_gauge_Pa)


class MuscleStaticForce(ElementParameters, Component):
    """A static force as the dynamics apply it (:func:`pamsim.elements.muscle_force.dynamics_static_force`).

    An element written in operations that act on symbols (the closed-form models) becomes equations
    with its numbers as parameters; one that is not (a force table, a numerical solve) is called on
    floats as an external function (:attr:`pamsim.modeling.component.Symbols.external`), which runs
    in generated C too if it has a CasADi form (a spline table's B-spline), else in Python only.
    State ``W_muscle_J``: the muscle's work, integral of ``F v``.
    """

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    inputs = (Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"),)
    states = (Var("W_muscle_J", "J", "work done by the static force", 0.1),)
    outputs = (Var("F_static_N", "N", "static muscle force along x"),)

    def __init__(self, name: str, element):
        super().__init__(name, self.wrap(element, _force_N, PROBE_POINTS))

    def equations(self, s: Symbols) -> Equations:
        x, v = s.port["flange"]["x_m"], s.port["flange"]["v_m_s"]
        F = self.element_call(s, "force_N", x, s.u["p_gauge_Pa"])
        return Equations(der={"W_muscle_J": F * v}, outputs={"F_static_N": F}, port={"flange": {"F_N": F}})
