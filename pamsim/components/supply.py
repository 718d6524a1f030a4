"""A regulated supply: a pneumatic node held at the regulator's output pressure.

The regulator's set pressure is an input (a scenario wires it to the rig's ``supply_pressure_gauge_Pa``,
the ``[pressure]`` table's supply).  Its output pressure is either the set pressure itself (``response =
"ideal"``) or follows it with a first-order lag ``tau_s`` (``"first_order"``)::

    dp/dt = (p_atm + p_set - p) / tau

It delivers whatever flow the branches connected to it draw (no flow limit: the volume and the
resistance after it, a reservoir and a tube, limit the flow).
"""

from __future__ import annotations

from ..modeling import PNEUMATIC, Component, Equations, Port, Symbols, Var, non_negative, positive

RESPONSES = ("ideal", "first_order")
"""The regulator's responses; the first is the default."""

DEFAULTS = {"p_atm_Pa": 101325.0,    # standard atmosphere
            "T_supply_K": 293.15,    # room temperature, the muscle's supply default (pamsim.parameters)
            "initial_gauge_Pa": 0.0}  # the regulator's output vented at the start: a step from 0
"""Defaults of the keys a scenario may leave out."""

COMMON = (positive("p_atm_Pa", "Pa", "ambient pressure"), positive("T_supply_K", "K", "temperature of the air supplied"))
LAG = (positive("tau_s", "s", "time constant of the regulator's output pressure"),
       non_negative("initial_gauge_Pa", "Pa", "the regulator's output pressure at the start (gauge)"))


class RegulatedSupply(Component):
    """A supply node at the regulator's output pressure: the set pressure (``response = "ideal"``) or a
    first-order lag behind it (``"first_order"``, state ``p_abs_Pa``).

    State ``delivered_mass_kg``: the air mass it has given the branches connected to it (the integral of
    its output ``mass_flow_kg_s``), for a mass balance of what it feeds.
    """

    ports = (Port("port", PNEUMATIC, "node", optional=True),)
    inputs = (Var("p_set_gauge_Pa", "Pa", "the regulator's set pressure (gauge)"),)
    outputs = (Var("p_gauge_Pa", "Pa", "output gauge pressure"), Var("p_abs_Pa", "Pa", "output absolute pressure"),
               Var("mass_flow_kg_s", "kg/s", "mass flow delivered to the branches"))
    choices = {"response": RESPONSES}
    defaults = DEFAULTS

    def __init__(self, name: str, values, response: str = RESPONSES[0]):
        if response not in RESPONSES:
            raise ValueError(f"unknown response {response!r} (one of {', '.join(RESPONSES)})")
        self.response = response
        self.parameters = self.scenario_parameters({"response": response})
        lag = (Var("p_abs_Pa", "Pa", "the regulator's output pressure", 1e5),) if response == "first_order" else ()
        self.states = lag + (Var("delivered_mass_kg", "kg", "air mass delivered since the start", 1e-5),)
        values = {**DEFAULTS, **values}
        super().__init__(name, {v.name: float(values[v.name]) for v in self.parameters})

    @classmethod
    def scenario_parameters(cls, options) -> tuple[Var, ...]:
        """The keys a ``[[component]]`` table of this type takes, for its ``options`` (its response)."""
        return COMMON + (LAG if options.get("response", RESPONSES[0]) == "first_order" else ())

    def structure_key(self) -> tuple:
        """The class and the response."""
        return super().structure_key() + (self.response,)

    def held_state(self, p_abs_Pa: float) -> dict[str, float]:
        """Its states at rest with its output at the absolute pressure ``p_abs_Pa`` (an operating point of a
        line): the first-order regulator's output there, nothing delivered."""
        held = {"delivered_mass_kg": 0.0}
        if self.response == "first_order":
            held["p_abs_Pa"] = float(p_abs_Pa)
        return held

    def equations(self, s: Symbols) -> Equations:
        p_atm, flow = s.p["p_atm_Pa"], s.port["port"]
        target = p_atm + s.u["p_set_gauge_Pa"]
        der = {"delivered_mass_kg": -flow["mdot_kg_s"]}
        initial = {"delivered_mass_kg": 0.0}
        if self.response == "first_order":
            p = s.x["p_abs_Pa"]
            der["p_abs_Pa"] = (target - p) / s.p["tau_s"]
            initial["p_abs_Pa"] = p_atm + s.p["initial_gauge_Pa"]
        else:
            p = target
        return Equations(der=der, initial=initial,
                         outputs={"p_gauge_Pa": p - p_atm, "p_abs_Pa": p, "mass_flow_kg_s": -flow["mdot_kg_s"]},
                         port={"port": {"p_abs_Pa": p, "T_K": s.p["T_supply_K"]}})
