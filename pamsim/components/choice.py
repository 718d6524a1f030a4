"""Choices made when a model runs, not when it is generated: one of several components by a parameter,
and the muscle's pressure from its chamber or from a signal.

An FMU lets its user pick a friction or damping law with a parameter after it is built.  Generated
code holds every law it may pick and selects one by the parameter's value (CasADi's ``if_else``,
which evaluates every branch: the laws are a few operations each).
"""

from __future__ import annotations

from typing import Mapping

from ..modeling import Component, Equations, Symbols, Var
from ..modeling.smath import if_else

SEPARATOR = "__"
"""Between an option's name and its parameter's in the parameter names of :class:`Selected`."""


def _choose(choice, options: list[tuple[int, dict]]) -> dict:
    """``{key: expression}`` taking, for each key, option ``k``'s where ``choice == k``."""
    out = {}
    for key in options[0][1]:
        value = options[-1][1][key]
        for k, values in reversed(options[:-1]):
            value = if_else(choice == k, values[key], value)
        out[key] = value
    return out


class Selected(Component):
    """One of ``options`` (components with the same ports, inputs, outputs and states, and no modes),
    chosen by the parameter ``choice`` (0 for the first).

    Its parameters are ``choice`` and every option's, named ``<option>__<parameter>``
    (``paper__D1_N_s_per_m``).  Its equations are option ``choice``'s; for any other value of
    ``choice``, the last option's.
    """

    def __init__(self, name: str, options: Mapping[str, Component], choice: int = 0):
        self.options = dict(options)
        first = next(iter(self.options.values()))
        for option, c in self.options.items():
            if c.modes is not None or c.n_indicators:
                raise ValueError(f"component {name!r}: option {option!r} has modes")
            for what in ("ports", "inputs", "outputs", "states"):
                if [v.name for v in getattr(c, what)] != [v.name for v in getattr(first, what)]:
                    raise ValueError(f"component {name!r}: option {option!r} has other {what} than the first")
        self.ports, self.inputs = first.ports, first.inputs
        self.outputs, self.states = first.outputs, first.states
        values = {"choice": float(choice)}
        for option, c in self.options.items():
            values.update({f"{option}{SEPARATOR}{k}": v for k, v in c.values.items()})
        super().__init__(name, values)

    def parameter_vars(self) -> tuple[Var, ...]:
        own = (Var("choice", "1", f"which law: {', '.join(f'{k} = {o}' for k, o in enumerate(self.options))}",
                   lower=0.0, upper=len(self.options) - 1.0),)
        return own + tuple(Var(f"{option}{SEPARATOR}{v.name}", v.unit, v.description, v.nominal, v.lower, v.upper,
                               v.lower_open, v.upper_open)
                           for option, c in self.options.items() for v in c.parameter_vars())

    def equations(self, s: Symbols) -> Equations:
        per_option = []
        for k, (option, c) in enumerate(self.options.items()):
            prefix = f"{option}{SEPARATOR}"
            own = {name[len(prefix):]: value for name, value in s.p.items() if name.startswith(prefix)}
            eq = c.equations(Symbols(own, s.x, s.u, s.port, external=s.external, tol=s.tol))
            per_option.append((k, eq))
        choice = s.p["choice"]
        pick = lambda attr: _choose(choice, [(k, getattr(eq, attr)) for k, eq in per_option])  # noqa: E731
        ports = {name: _choose(choice, [(k, eq.port[name]) for k, eq in per_option]) for name in per_option[0][1].port}
        return Equations(der=pick("der"), outputs=pick("outputs"), port=ports, initial=pick("initial"))

    def structure_key(self) -> tuple:
        return super().structure_key() + tuple((option, c.structure_key()) for option, c in self.options.items())


class PressureChoice(Component):
    """The muscle's pressure from its chamber (``prescribed`` 0) or from the input signal
    ``prescribed_gauge_Pa`` (1).

    While the pressure is prescribed, the chamber is shut off: its valve sees a zero command and its
    volume no motion, so its states stand still (a chamber that is not there).  Wire the chamber's
    ``v_m_s`` and the valve's ``command`` through ``v_chamber_m_s`` and ``command_out``.
    """

    parameters = (Var("prescribed", "1", "pressure source: 0 = the valve and chamber, 1 = the prescribed signal",
                      lower=0.0, upper=1.0),)
    inputs = (Var("chamber_gauge_Pa", "Pa", "the chamber's gauge pressure"),
              Var("prescribed_gauge_Pa", "Pa", "the prescribed gauge pressure"),
              Var("v_m_s", "m/s", "contraction velocity"), Var("command", "1", "valve command"))
    outputs = (Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"),
               Var("v_chamber_m_s", "m/s", "the contraction velocity the chamber's volume follows"),
               Var("command_out", "1", "the command the valve receives"))

    def equations(self, s: Symbols) -> Equations:
        on = s.p["prescribed"] == 1.0
        return Equations(outputs={"p_gauge_Pa": if_else(on, s.u["prescribed_gauge_Pa"], s.u["chamber_gauge_Pa"]),
                                  "v_chamber_m_s": if_else(on, 0.0, s.u["v_m_s"]),
                                  "command_out": if_else(on, 0.0, s.u["command"])})
