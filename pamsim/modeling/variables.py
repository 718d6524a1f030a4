"""Declared variables and typed ports.

A port is a pair of across and through variables, in the manner of Modelica's connectors.  pamsim's
models are explicit ODEs, so each connection is causal: a port has a role, ``node`` or ``branch``.
The node (a moving body, a gas volume) owns the across variables and receives the sum of the through
variables of every branch connected to it; a branch (a force element, a valve) reads the across
variables and gives its through variables.  The assembly writes the sums; nothing else is written
by hand.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Var:
    """A named variable with its unit, meaning and nominal scale (the integrator's absolute scale), and
    for a parameter the range its value must lie in (``lower``/``upper``; ``*_open``: the bound excluded),
    which a scenario and an FMU check.

    ``conserved`` marks a state that connections move to and from other states (a volume's air mass): an
    integrator carries it with the states it exchanges with, under one rule, even where nothing reads it,
    so that their sum holds to rounding: it is never a quadrature
    (:meth:`pamsim.modeling.flat.FlatModel.quadratures`), which the native engine takes from its dense
    output by a rule that is not its steps'."""

    name: str
    unit: str
    description: str = ""
    nominal: float = 1.0
    lower: float = -math.inf
    upper: float = math.inf
    lower_open: bool = False
    upper_open: bool = False
    conserved: bool = False

    def violation(self, value: float) -> str | None:
        """Why ``value`` is outside the range, or None."""
        low = value <= self.lower if self.lower_open else value < self.lower
        high = value >= self.upper if self.upper_open else value > self.upper
        if not (low or high):
            return None
        if math.isinf(self.upper):
            return f"must be {'>' if self.lower_open else '>='} {self.lower:g}"
        if math.isinf(self.lower):
            return f"must be {'<' if self.upper_open else '<='} {self.upper:g}"
        return (f"must lie in {'(' if self.lower_open else '['}{self.lower:g}, {self.upper:g}"
                f"{')' if self.upper_open else ']'}")


def positive(name: str, unit: str, description: str) -> Var:
    """A parameter that must be above zero (a mass, a temperature, an absolute pressure)."""
    return Var(name, unit, description, lower=0.0, lower_open=True)


def non_negative(name: str, unit: str, description: str) -> Var:
    """A parameter that must not be negative (a stiffness, a distance from a stop, a margin)."""
    return Var(name, unit, description, lower=0.0)


@dataclass(frozen=True)
class PortKind:
    """A kind of connection: its across variables (equal at a node) and through variables (summed)."""

    name: str
    across: tuple[Var, ...]
    through: tuple[Var, ...]

    @property
    def variables(self) -> tuple[Var, ...]:
        """The across variables, then the through variables."""
        return self.across + self.through


TRANSLATIONAL = PortKind(
    "translational",
    across=(Var("x_m", "m", "position along the line of action (contraction for a muscle)"),
            Var("v_m_s", "m/s", "velocity along the line of action")),
    through=(Var("F_N", "N", "force on the node along the line of action"),))
"""A mechanical flange along one line: position and velocity, force."""

ROTATIONAL = PortKind(
    "rotational",
    across=(Var("theta_rad", "rad", "angle of the shaft"), Var("omega_rad_s", "rad/s", "angular velocity of the shaft")),
    through=(Var("tau_Nm", "N m", "torque on the shaft"),
             Var("tau_level_Nm", "N m", "Coulomb friction level the branch adds to the shaft's stick/slip decision")))
"""A mechanical shaft: angle and angular velocity; torque, and the friction level a branch brings (a
muscle's Coulomb friction acts on the joint it turns, and decides with the joint's own whether it sticks)."""

LINEAR = PortKind(
    "linear",
    across=(Var("x_m", "m", "position of the carriage along its guide"),
            Var("v_m_s", "m/s", "velocity of the carriage along its guide")),
    through=(Var("F_N", "N", "force on the carriage along its guide"),
             Var("F_level_N", "N", "Coulomb friction level the branch adds to the carriage's stick/slip decision")))
"""A guided carriage (a slider): position and velocity; force, and the friction level a branch brings, as
:data:`ROTATIONAL` for a shaft."""

PNEUMATIC = PortKind(
    "pneumatic",
    across=(Var("p_abs_Pa", "Pa", "absolute pressure of the volume"),
            Var("T_K", "K", "gas temperature of the volume")),
    through=(Var("mdot_kg_s", "kg/s", "mass flow into the volume"),
             Var("flow_work_W", "W", "flow work the stream brings in, R T_in mdot (its enthalpy is cp/R of it)")))
"""A gas port: pressure and temperature; mass flow and the flow work it carries."""

SIGNAL = PortKind("signal", across=(), through=())
"""Plain inputs and outputs connect one to one; this kind only names them in messages."""

ROLES = ("node", "branch")


@dataclass(frozen=True)
class Port:
    """A component's port: a name, a kind and a role (``node`` or ``branch``).

    A node port left unconnected receives no through flow (a body on which nothing pulls, a closed
    volume) only if ``optional``; a branch port must always be connected, or it has nothing to read.
    """

    name: str
    kind: PortKind
    role: str
    optional: bool = False

    def __post_init__(self):
        if self.role not in ROLES:
            raise ValueError(f"port {self.name!r}: role must be one of {ROLES}, not {self.role!r}")
