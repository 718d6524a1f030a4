"""Coulomb friction: a branch on the load's flange whose level F_c(x, p, m) >= 0 the load's modes
turn into a force (against the motion when sliding, nothing while held: the load is then at rest and
friction holds whatever it must)."""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var
from ..modeling.smath import fmax
from .element import ElementParameters

PROBE_POINTS = tuple((x, p, m) for x in (0.0, 0.01, 0.04) for p in (0.0, 1e5, 4e5) for m in (0.5, 2.0, 8.0))
"""Contractions [m], gauge pressures [Pa] and load masses [kg] at which a law's symbolic form is checked."""


def equivalent_mass_kg(F_static_N, g_m_s2):
    """The load a muscle holds, as the load-dependent friction law reads it: the mass whose weight is its
    static force, ``max(F_static, 0) / g`` (pamsim's choice where the load is not a hanging mass)."""
    return fmax(F_static_N, 0.0) / g_m_s2


def _level_N(element, x_m, p_gauge_Pa, mass_kg):
    return element.level_N(x_m, p_gauge_Pa, mass_kg)


class CoulombFriction(ElementParameters, Component):
    """Any law of :mod:`pamsim.elements.friction`: force ``-direction F_c`` on the flange, with
    ``direction`` (+1 or -1 sliding, 0 held) from the load, and the level to the load (``level_N``)
    for its stick/slip decisions.

    State ``E_friction_J``: the energy it dissipates, integral of ``F_c |v|``.
    """

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    inputs = (Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"), Var("mass_kg", "kg", "load mass"),
              Var("direction", "1", "+1 or -1 while the load slides up or down, 0 while it is held"))
    states = (Var("E_friction_J", "J", "energy dissipated by Coulomb friction", 0.1),)
    outputs = (Var("level_N", "N", "Coulomb friction level"),)

    def __init__(self, name: str, element):
        super().__init__(name, self.wrap(element, _level_N, PROBE_POINTS))

    def equations(self, s: Symbols) -> Equations:
        u, flange = s.u, s.port["flange"]
        level = self.element_call(s, "level_N", flange["x_m"], u["p_gauge_Pa"], u["mass_kg"])
        return Equations(der={"E_friction_J": level * abs(flange["v_m_s"])}, outputs={"level_N": level},
                         port={"flange": {"F_N": -(u["direction"] * level)}})
