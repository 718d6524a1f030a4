"""What a rigid gas volume added to the rig shares (a reservoir, a tube's bore): its law, chosen by name,
the law's parameters with their defaults, and the rates of its two states.

The physics is the chamber's (:mod:`pamsim.elements.chamber`): the volume's element is one of the
chamber's laws over a rigid geometry, and these functions only call it.
"""

from __future__ import annotations

from ..elements.chamber import CHAMBER_LAWS
from ..modeling import Var, non_negative, positive

LAWS = CHAMBER_LAWS
"""The laws a rigid volume's gas may follow; the first (``isothermal``) is the default."""

LAW_PARAMETERS = {
    "polytropic": (positive("polytropic_index", "1", "polytropic index of the gas"),),
    "isothermal": (positive("T_wall_K", "K", "wall temperature the gas is held at"),),
    "thermal": (positive("T_wall_K", "K", "wall temperature"),
                non_negative("h_W_per_m2_K", "W/(m^2 K)", "heat transfer coefficient of the wall"),
                Var("heat_capacity_ratio", "1", "c_p / c_v of the gas", lower=1.0, upper=5.0 / 3.0,
                    lower_open=True)),
}
"""``{law: its parameters}``, as the muscle's ``[chamber]`` table takes them."""

COMMON_PARAMETERS = (
    positive("p_atm_Pa", "Pa", "ambient pressure"),
    non_negative("initial_gauge_Pa", "Pa", "gauge pressure at the start"),
    positive("T_initial_K", "K", "gas temperature at the start (the polytropic law's; the others start at "
             "their wall's)"),
)
"""The component's own parameters of every rigid volume, besides its element's (its geometry, its law's
and its gas constant)."""

GAS_CONSTANT = positive("R_J_per_kg_K", "J/(kg K)", "specific gas constant")

DEFAULTS = {
    "polytropic_index": 1.0,      # the muscle's own default (isothermal, pamsim.parameters.DYNAMICS_DEFAULTS)
    "T_wall_K": 293.15,           # room temperature, the chamber's default (pamsim.parameters.CHAMBER_DEFAULTS)
    "h_W_per_m2_K": 15.7,         # the chamber's default: laminar heat transfer in a 6 mm tube (docs/pneumatics.md)
    "heat_capacity_ratio": 1.4,   # dry air near 20 C, c_p / c_v = 1005 / 718
    "p_atm_Pa": 101325.0,         # standard atmosphere
    "initial_gauge_Pa": 0.0,      # at ambient pressure: vented
    "T_initial_K": 293.15,        # room temperature
    "R_J_per_kg_K": 287.05,       # dry air
}
"""Defaults of the keys above; each one is the muscle's chamber's, whose sources
``pamsim.parameters`` gives."""

PROBE = tuple((p, m, mdot, fw) for p in (1.2e5, 4e5) for m in (2e-6, 3e-5) for mdot in (-1e-4, 0.0, 2e-4)
              for fw in (-5.0, 0.0, 17.0))
"""Points ``(p, m, mdot, flow work)`` at which a volume's element must give on symbols what it gives on floats."""


def law_parameters(law: str) -> tuple[Var, ...]:
    """The scenario keys of the law ``law`` and of every rigid volume."""
    return LAW_PARAMETERS[law] + (GAS_CONSTANT,) + COMMON_PARAMETERS


def pressure_rate(element, p, m, mdot, flow_work):
    """``dp/dt`` [Pa/s] of the rigid volume ``element`` at pressure ``p`` and air mass ``m``, for the summed
    inflow ``mdot`` and its flow work (the chamber's law, its volume held)."""
    return element.pressure_rate_of_flows_Pa_s(p, element.volume_m3(0.0), 0.0, mdot, flow_work, m, 0.0)


def start(element, s):
    """``(p0, m0)``: the volume's absolute pressure and air mass at the start, from its
    ``initial_gauge_Pa`` and the law's starting temperature (its wall's, or ``T_initial_K``)."""
    p0 = s.p["p_atm_Pa"] + s.p["initial_gauge_Pa"]
    return p0, element.air_mass_kg(p0, element.volume_m3(0.0), element.start_temperature_K(s.p["T_initial_K"]))


def checked_law(law: str) -> str:
    """``law`` if it is one of :data:`LAWS`, else ``ValueError`` naming the choices."""
    if law not in LAWS:
        raise ValueError(f"unknown law {law!r} (one of {', '.join(LAWS)})")
    return law



def held_state(component, p_abs_Pa: float, element=None) -> dict[str, float]:
    """The states of the rigid volume ``component`` at rest at the absolute pressure ``p_abs_Pa``: that
    pressure, and the air mass it holds there at its law's starting temperature (its wall's, or
    ``T_initial_K``; at rest the thermal gas stands at its wall's).  ``element``: the volume's, if not the
    component's own (a tube's cell)."""
    element = element if element is not None else component.element
    T = element.start_temperature_K(component.values["T_initial_K"])
    return {"p_abs_Pa": float(p_abs_Pa), "air_mass_kg": float(element.air_mass_kg(p_abs_Pa, element.volume_m3(0.0), T))}
