"""The muscle model: the elements composed into one hybrid ODE.

State vector ``y``::

    [x_m, v_m_s, *source states, W_muscle_J, E_friction_J, E_damping_J, W_external_J]

The last four are work integrals used for the energy balance.  The equation
of motion (paper eq. (12), MODEL_NOTES sec. 4), x > 0 contracting::

    m x'' = F_static(x, p) - F_damp(v) - F_c(x, p) sgn(v) - m g + F_ext(t)

The friction direction is not a sign function but a discrete mode
(:class:`Mode`); in the rest modes x and v are frozen and only the pressure
source evolves.
"""

from __future__ import annotations

from dataclasses import dataclass

import math

import numpy as np

from .components.hanging_load import LoadMode
from .elements.contracts import Damping, Friction, PressureSource, StaticForce
from .elements.load import HangingLoad
from .elements.stops import EndStops
from .signals import max_step_hint_s


Mode = LoadMode
"""Friction / contact mode of the load (the hanging-load component's own modes)."""


N_WORK = 4
WORK_NAMES = ("W_muscle_J", "E_friction_J", "E_damping_J", "W_external_J")
STATE_SCALES = {"x_m": 1e-2, "v_m_s": 1e-1, "p_abs_Pa": 1e5, "air_mass_kg": 1e-5}
"""Typical magnitude of each state of the motion and the valve source (10 mm, 0.1 m/s, 1 bar, 10 mg of
air): the simulator's absolute tolerances, the control model's scaling and the FMU's nominal values."""


@dataclass(frozen=True)
class FitRange:
    """Range on which the static polynomial was fitted [m, Pa]."""

    x_min_m: float
    x_max_m: float
    p_max_gauge_Pa: float


@dataclass(frozen=True)
class MuscleModel:
    """The composed model.  Every element is swappable: any object meeting its
    :mod:`pamsim.elements.contracts` protocol will do."""

    static_force: StaticForce
    friction: Friction
    damping: Damping
    load: HangingLoad
    stops: EndStops
    source: PressureSource
    fit_range: FitRange

    @property
    def n_source(self) -> int:
        """Number of the pressure source's states."""
        return len(self.source.state_names)

    @property
    def state_names(self) -> tuple[str, ...]:
        """Names of the state vector: contraction, velocity, the source's states, the work integrals."""
        return ("x_m", "v_m_s") + tuple(self.source.state_names) + WORK_NAMES

    def initial_state(self, x0_m: float = 0.0, p0_gauge_Pa: float | None = None) -> np.ndarray:
        """At rest at ``x0_m``; the source's own initial pressure unless ``p0_gauge_Pa`` is given."""
        source = self.source.initial_state(x0_m) if p0_gauge_Pa is None else self.source.initial_state(x0_m, p0_gauge_Pa)
        return np.array([x0_m, 0.0] + source + [0.0] * N_WORK)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where an input of the source or the load jumps; the integrator restarts there."""
        return tuple(self.source.breakpoints) + tuple(self.load.breakpoints)

    @property
    def max_input_step_s(self) -> float:
        """Longest step over which every input is monotonic (a measured trace's sample spacing)."""
        return min(getattr(self.source, "max_input_step_s", math.inf),
                   max_step_hint_s(self.load.external_force_N))

    def rest_forces(self, t: float, y) -> tuple[float, float]:
        """Net force at zero velocity (static - weight + external) and the Coulomb level [N]."""
        return self.rest_forces_with_inputs(y, self.source.inputs(t), self.load.external_N(t))

    def rest_forces_with_inputs(self, y, source_inputs, F_ext_N) -> tuple[float, float]:
        """``(net force [N], Coulomb level [N])`` at rest in state ``y``, with the source's inputs and the
        external force ``F_ext_N`` given.
        """
        y = y.tolist()  # Python floats: scalar arithmetic on numpy scalars is several times slower
        x = y[0]
        p = self.source.pressure_gauge_Pa(y[2:2 + self.n_source], source_inputs)
        net = self.static_force.force_N(x, p) - self.load.weight_N + F_ext_N
        return float(net), float(self.friction.level_N(x, p, self.load.mass_kg))

    def rhs(self, t: float, y, mode: Mode) -> np.ndarray:
        """Time derivative of ``y`` in ``mode``, with the inputs taken from the signals."""
        if mode == Mode.SLIP_UP or mode == Mode.SLIP_DOWN:
            return self.slip_rhs(y, float(mode), self.source.inputs(t), self.load.external_N(t))
        return self.held_rhs(y, self.source.inputs(t))

    def slip_rhs(self, y, friction_direction: float, source_inputs, F_ext_N) -> np.ndarray:
        """Derivatives of a moving load with explicit inputs.

        The Coulomb level is applied as ``-friction_direction * F_c``: +1 or -1
        for sliding up or down, 0 to drop it, or a smooth ``tanh(v / v_s)`` for
        a regularised model (used by linearisation).
        """
        y = y.tolist()  # Python floats: scalar arithmetic on numpy scalars is several times slower
        x, v = y[0], y[1]
        s = y[2:2 + self.n_source]
        p = self.source.pressure_gauge_Pa(s, source_inputs)
        F_s = self.static_force.force_N(x, p)
        F_c = self.friction.level_N(x, p, self.load.mass_kg)
        F_d = self.damping.force_N(v)
        a = (F_s - F_d - friction_direction * F_c - self.load.weight_N + F_ext_N) / self.load.mass_kg
        return np.array([v, a, *self.source.derivatives(s, x, v, source_inputs),
                         F_s * v, F_c * abs(v), F_d * v, F_ext_N * v], dtype=float)

    def held_rhs(self, y, source_inputs) -> np.ndarray:
        """Derivatives of a load held still (stuck or on a stop): only the source evolves."""
        y = y.tolist()
        s = y[2:2 + self.n_source]
        return np.array([0.0, 0.0, *self.source.derivatives(s, y[0], 0.0, source_inputs), 0.0, 0.0, 0.0, 0.0])

    def pressure_trace_Pa(self, t, Y) -> np.ndarray:
        """Gauge pressure [Pa] the mechanics see at times ``t`` of a trace ``Y`` (one column per time)."""
        return self.source.pressure_trace_Pa(t, Y[2:2 + self.n_source])

    def breakdown(self, t, Y, modes) -> dict[str, np.ndarray]:
        """Force components [N] along x (positive contracts) and source outputs for a trace.

        ``Y`` has one column per time.  In a rest mode the friction and stop
        reactions are whatever holds the load still.
        """
        x, v = Y[0], Y[1]
        S = Y[2:2 + self.n_source]
        p = self.pressure_trace_Pa(t, Y)
        F_s = np.asarray(self.static_force.force_N(x, p), dtype=float)
        F_c = np.asarray(self.friction.level_N(x, p, self.load.mass_kg), dtype=float) + 0.0 * t
        F_e = np.asarray(self.load.external_N(t), dtype=float) + 0.0 * t
        F_g = np.full_like(t, -self.load.weight_N)
        net = F_s + F_g + F_e
        slip = np.abs(modes) == 1
        stick = modes == Mode.STICK
        low = modes == Mode.STOP_LOW
        high = modes == Mode.STOP_HIGH
        friction = np.where(slip, -modes * F_c, 0.0)
        # Held still: friction takes what it can, the stop the rest (pressing into it).
        held_by_friction = stick | (low & (net > 0)) | (high & (net < 0))
        friction = np.where(held_by_friction, -net, friction)
        stop = np.where((low & (net <= 0)) | (high & (net >= 0)), -net, 0.0)
        damping = np.where(slip, -np.asarray(self.damping.force_N(v), dtype=float), 0.0)
        out = {"p_gauge_Pa": p, "F_static_N": F_s, "F_friction_N": friction, "F_damping_N": damping,
               "F_gravity_N": F_g, "F_external_N": F_e, "F_stop_N": stop, "F_coulomb_level_N": F_c}
        out.update(self.source.outputs(t, S, x))
        return out
