"""The muscle model as a python-control nonlinear I/O system.

The control model keeps the mechanical and chamber states of
:class:`~pamsim.model.MuscleModel` with a valve source and drops the four work
integrals, which are bookkeeping for the energy balance and feed nothing back.
The right-hand side is :meth:`MuscleModel.slip_rhs`: a sliding load whose
Coulomb friction is treated as one of the smooth laws of
:class:`FrictionTreatment`.  The stick/slip switching of the hybrid simulator
cannot be expressed as one smooth vector field; closed-loop checks on the
hybrid model use :mod:`pamsim.control.closed_loop` instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control as ct
import numpy as np

from ..elements.pressure_source import ValveChamberSource
from ..elements.pwm_average import AveragedPwmSource
from .choices import FRICTION_KINDS
from ..errors import InputError
from ..model import N_WORK, STATE_SCALES as _SCALES, MuscleModel

STATES = ("x_m", "v_m_s", "p_abs_Pa", "air_mass_kg")
"""State names of the control model (contraction, velocity, absolute chamber pressure, air mass)."""
INPUTS = ("valve_command", "supply_gauge_Pa", "F_ext_N")
"""Input names: valve command (dimensionless, -1 exhaust .. +1 supply), supply gauge pressure, external force."""
PWM_INPUTS = ("pwm_duty",) + INPUTS[1:]
"""Input names of the averaged PWM valve's model: its first input is the duty [1] in place of the command."""
OUTPUTS = ("contraction_m", "p_gauge_Pa", "F_tendon_N")
"""Output names: contraction, chamber gauge pressure, tendon force (static minus damping minus friction;
not the static force alone, which the simulator and the FMU call ``F_static_N``)."""

STATE_SCALES = tuple(_SCALES[n] for n in STATES)
"""Typical magnitude of each state (10 mm, 0.1 m/s, 1 bar, 10 mg), as the simulator's tolerances use."""
INPUT_SCALES = (1.0, 1e5, 1.0)
"""Typical magnitude of each input (full valve opening, 1 bar, 1 N)."""



@dataclass(frozen=True)
class FrictionTreatment:
    """How the Coulomb friction enters a smooth model.

    Parameters
    ----------
    kind : {"dropped", "regularised", "sliding"}
        ``dropped``: the Coulomb term is left out (it has no derivative at
        rest).  ``regularised``: the sign of the velocity is replaced by
        ``tanh(v / velocity_scale_m_s)``; at rest this acts as a viscous
        damper of ``F_c / velocity_scale_m_s``.  ``sliding``: the load slides
        in ``direction`` and the friction is ``direction * F_c(x, p)``,
        differentiable in x and p (valid for a moving load only).
    velocity_scale_m_s : float
        Velocity scale of the regularisation [m/s].
    direction : float
        +1 sliding up (contracting), -1 sliding down; used by ``sliding``.
    """

    kind: str = "dropped"
    velocity_scale_m_s: float = 1e-3
    direction: float = 1.0

    def __post_init__(self):
        if self.kind not in FRICTION_KINDS:
            raise InputError(f"friction treatment {self.kind!r}: choose from {', '.join(FRICTION_KINDS)}")
        if not (self.velocity_scale_m_s > 0 and math.isfinite(self.velocity_scale_m_s)):
            raise InputError(f"friction velocity scale {self.velocity_scale_m_s!r} m/s: must be positive")
        if self.direction not in (1.0, -1.0):
            raise InputError(f"sliding direction {self.direction!r}: must be +1 or -1")

    def coulomb_direction(self, v_m_s: float) -> float:
        """The factor that multiplies the Coulomb level in ``slip_rhs``."""
        if self.kind == "dropped":
            return 0.0
        if self.kind == "regularised":
            return math.tanh(v_m_s / self.velocity_scale_m_s)
        return self.direction

    def describe(self) -> str:
        """One line saying how the Coulomb friction enters the linearisation."""
        if self.kind == "dropped":
            return "Coulomb friction dropped (no linearisation at rest)"
        if self.kind == "regularised":
            return (f"Coulomb friction regularised as tanh(v / {self.velocity_scale_m_s * 1e3:g} mm/s): "
                    f"a viscous F_c / v_s at rest")
        return f"Coulomb friction linearised about sliding {'up' if self.direction > 0 else 'down'}"


def require_valve_source(model: MuscleModel) -> None:
    """Raise :class:`InputError` for a ``model`` whose pressure is not fed by a valve: a control model's input
    is the valve's command."""
    if not isinstance(model.source, ValveChamberSource):
        raise InputError(f"pressure.source = {getattr(model.source, 'name', type(model.source).__name__)!r}: control "
                         "models need a valve source (pressure.source = 'valve'): their input is the valve's command")


class MusclePlant:
    """The state equations of a :class:`MuscleModel` with a valve source, with explicit inputs.

    Parameters
    ----------
    model : MuscleModel
        A model whose ``source`` is a :class:`ValveChamberSource`.

    Raises
    ------
    InputError
        If the model is driven by a prescribed pressure (it has no valve input).
    """

    def __init__(self, model: MuscleModel):
        require_valve_source(model)
        self.model = model
        self._zeros = np.zeros(N_WORK)

    @property
    def source(self) -> ValveChamberSource:
        """The model's valve-and-chamber pressure source."""
        return self.model.source

    def rhs(self, x, u, friction: FrictionTreatment) -> np.ndarray:
        """dx/dt of the four control states for inputs ``u = (valve_command, supply_gauge_Pa, F_ext_N)``."""
        y = np.concatenate([np.asarray(x, dtype=float), self._zeros])
        dy = self.model.slip_rhs(y, friction.coulomb_direction(float(y[1])), (u[0], u[1]), u[2])
        return dy[:len(STATES)]

    def output(self, x, u, friction: FrictionTreatment) -> np.ndarray:
        """(contraction [m], gauge pressure [Pa], muscle force on the load [N]).

        The muscle force is static force minus damping minus friction, taken
        from the equation of motion as ``m a + W - F_ext`` so that it uses the
        model's own force laws: it is what a load cell in the tendon reads.
        """
        a = self.rhs(x, u, friction)[1]
        load = self.model.load
        p_gauge = self.source.pressure_gauge_Pa(np.asarray(x[2:4], dtype=float), (u[0], u[1]))
        return np.array([x[0], p_gauge, load.mass_kg * a + load.weight_N - u[2]], dtype=float)


def muscle_nlsys(model: MuscleModel, friction: FrictionTreatment | None = None,
                 name: str = "muscle") -> ct.NonlinearIOSystem:
    """The muscle as a :func:`control.nlsys` with named states, inputs and outputs.

    Parameters
    ----------
    model : MuscleModel
        Built by :meth:`pamsim.Scenario.build_model` (valve source).
    friction : FrictionTreatment, optional
        Default: regularised with a 1 mm/s velocity scale, the closest smooth
        stand-in for the hybrid stick/slip model.
    name : str
        System name for python-control interconnections.

    Returns
    -------
    control.NonlinearIOSystem
        Update and output functions with the ``(t, x, u, params)`` signature.
        ``params`` may hold ``friction`` (a :class:`FrictionTreatment`) to
        change the treatment per call, as python-control passes it through.
    """
    plant = MusclePlant(model)
    default = friction or FrictionTreatment("regularised", 1e-3)

    def update(t, x, u, params):
        return plant.rhs(x, u, params.get("friction", default))

    def output(t, x, u, params):
        return plant.output(x, u, params.get("friction", default))

    return ct.nlsys(update, output, states=list(STATES), inputs=list(INPUTS), outputs=list(OUTPUTS),
                    name=name, params={"friction": default})


def input_names(model: MuscleModel) -> tuple[str, ...]:
    """The control model's input names: :data:`PWM_INPUTS` for the averaged PWM valve, else :data:`INPUTS`."""
    return PWM_INPUTS if isinstance(model.source, AveragedPwmSource) else INPUTS
