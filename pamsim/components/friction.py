"""The Coulomb friction level F_c(x, p, m) >= 0; the load's modes decide its direction."""

from __future__ import annotations

from ..modeling import Component, Equations, Symbols, Var
from .element import ElementParameters, element_parameters


class CoulombFriction(ElementParameters, Component):
    """Any law of :mod:`pamsim.elements.friction`: its level goes to the load (``level_N``).

    State ``E_friction_J``: the energy it dissipates, integral of ``F_c |v|``.
    """

    inputs = (Var("x_m", "m", "contraction"), Var("v_m_s", "m/s", "contraction velocity"),
              Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"), Var("mass_kg", "kg", "load mass"))
    states = (Var("E_friction_J", "J", "energy dissipated by Coulomb friction", 0.1),)
    outputs = (Var("level_N", "N", "Coulomb friction level"),)

    def __init__(self, name: str, element):
        self.element = element
        super().__init__(name, element_parameters(element))

    def equations(self, s: Symbols) -> Equations:
        u = s.u
        level = self.symbolic_element(s.p).level_N(u["x_m"], u["p_gauge_Pa"], u["mass_kg"])
        return Equations(der={"E_friction_J": level * abs(u["v_m_s"])}, outputs={"level_N": level})
