"""What the composed model needs of each element: one :class:`typing.Protocol` per kind.

An element is any object with these members (no base class to inherit).  Each
registry maps a scenario's choice to a builder with one signature,
``builder(params, options) -> element``: ``params`` is the muscle's
parameter mapping ``{name: value}`` (SI units, unit in the name) and
``options`` the scenario's ``[model]`` table of choices, from which a builder
reads the ones that concern it (``friction_negative_level`` for the
load-dependent friction, for example).

Every method works on Python floats (inside the right-hand side) and on numpy
arrays (when a trace's force breakdown is rebuilt).
"""

from __future__ import annotations

from typing import Callable, Mapping, Protocol, Sequence, TypeVar, runtime_checkable

ElementOptions = Mapping[str, str]
"""The scenario's ``[model]`` choices, passed to every element builder."""

NO_OPTIONS: ElementOptions = {}


@runtime_checkable
class StaticForce(Protocol):
    """Quasi-static muscle force F_static(x, p); positive contracts (lifts the load)."""

    name: str

    def force_N(self, x_m, p_gauge_Pa):
        """Static force [N] at contraction ``x_m`` [m] and gauge pressure ``p_gauge_Pa`` [Pa]."""


@runtime_checkable
class Friction(Protocol):
    """Coulomb friction level F_c >= 0 [N]; the simulator applies it against the motion."""

    name: str

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        """Magnitude of the Coulomb force [N] at contraction [m], gauge pressure [Pa] and load mass [kg]."""


@runtime_checkable
class Damping(Protocol):
    """Viscous damping force F_damp(v) [N], opposing the motion when positive; zero at v = 0."""

    name: str

    def force_N(self, v_m_s):
        """Damping force [N] at velocity ``v_m_s`` [m/s] (positive contracting)."""


@runtime_checkable
class PressureSource(Protocol):
    """Where the muscle's pressure comes from; owns its own states (``state_names``)."""

    name: str
    state_names: tuple[str, ...]

    def initial_state(self, x_m: float, p_gauge_Pa: float = 0.0) -> list[float]:
        """The source's states at rest at contraction ``x_m`` [m] and gauge pressure [Pa]."""

    def inputs(self, t_s) -> tuple:
        """The source's input signals at time ``t_s`` [s]."""

    def pressure_gauge_Pa(self, s: Sequence[float], inputs: tuple):
        """Gauge pressure [Pa] the mechanics see, from the source's states and inputs."""

    def pressure_trace_Pa(self, t_s, S):
        """Gauge pressure [Pa] along a trace: times ``t_s`` [s], states ``S`` of shape (n_states, n_times)."""

    def derivatives(self, s: Sequence[float], x_m: float, v_m_s: float, inputs: tuple) -> tuple:
        """Time derivatives of the source's states."""

    def outputs(self, t_s, S, x_m) -> dict:
        """Extra columns for a trace (states of shape (n_states, n_times))."""

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where an input jumps; the integrator restarts there."""

    @property
    def max_input_step_s(self) -> float:
        """Longest step [s] over which every input is monotonic."""


E = TypeVar("E")
Builder = Callable[[Mapping[str, float], ElementOptions], E]
"""``builder(params, options) -> element``: the one shape of every registry entry."""
