"""Linearisation of the muscle model about an operating point.

The Jacobians are exact: CasADi's derivatives of the components' own expressions
(:mod:`pamsim.control.exact`).  A model with an element that has no symbolic form (a
tabulated or implicit static model) falls back to central differences of
:class:`~pamsim.control.system.MusclePlant` (the model's own right-hand side) with one
Richardson extrapolation step, the step of each variable scaled by its typical magnitude
(``STATE_SCALES``); :attr:`LinearModel.jacobian_method` says which.  python-control's own
``linearize`` uses a forward difference with one absolute step of 1e-6 for every
variable, which is 1e-11 of a pressure in Pa and 10 % of an air mass in kg; hence this
module.

Three non-smooth points are handled explicitly:

* Coulomb friction, by the :class:`~pamsim.control.system.FrictionTreatment`.
* A scenario's hysteresis (Maxwell-slip elements' stick/slip, Bouc-Wen's ``|v|``), held in the stick
  state and on the branch of the operating point (:mod:`pamsim.control.loop_point`).
* The valve command at 0, where the 3/3 valve switches from the exhaust
  orifice to the supply orifice: the flow is continuous but its slope jumps
  from the venting to the filling conductance.  ``valve_slope`` picks
  ``mean`` (the central difference: the average of the two slopes, which is
  also the describing-function gain of the kink for a symmetric command),
  ``fill`` or ``vent`` (one-sided).  At a saturated command (``|u| = 1``) the
  one-sided difference into the valve's range is used.

Near a pressure ratio of 1 (chamber at supply pressure with the valve open)
the valve's own laminar branch makes the flow linear in the pressure drop, so
the pressure has a finite time constant instead of the infinite slope of the
ISO 6358 subsonic law; the Jacobian simply differentiates that branch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import control as ct
import numpy as np

from ..assemblies.stick_state import LoopPoint
from ..errors import InputError
from ..model import MuscleModel
from .choices import VALVE_SLOPES
from .exact import control_functions, exact_jacobians, held_line_states, line_states
from .line_rest import held_line_pressures
from .loop_point import hold_hysteresis
from .operating_point import OperatingPoint
from .system import INPUT_SCALES, INPUTS, OUTPUTS, STATE_SCALES, STATES, FrictionTreatment, MusclePlant, input_names

RELATIVE_STEP = 1e-5
"""Finite-difference step as a fraction of each variable's typical magnitude."""


def _derivative(f, z0: np.ndarray, i: int, h: float, side: int) -> np.ndarray:
    """d f / d z_i at z0 by a Richardson-extrapolated difference: central (side 0) or one-sided (+1/-1)."""
    def diff(step):
        zp, zm = z0.copy(), z0.copy()
        if side == 0:
            zp[i] += step
            zm[i] -= step
            return (f(zp) - f(zm)) / (2.0 * step)
        zp[i] += side * step
        return (f(zp) - f(zm)) / (side * step)

    d1, d2 = diff(h), diff(0.5 * h)
    # Central: error ~ h^2, so (4 d(h/2) - d(h)) / 3; one-sided: error ~ h, so 2 d(h/2) - d(h).
    return (4.0 * d2 - d1) / 3.0 if side == 0 else 2.0 * d2 - d1


def jacobians(plant: MusclePlant, op: OperatingPoint, friction: FrictionTreatment,
              valve_slope: str = "mean") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A, B, C, D of the four-state model at ``op`` (see the module notes on the kinks)."""
    if valve_slope not in VALVE_SLOPES:
        raise InputError(f"valve slope {valve_slope!r}: choose from {', '.join(VALVE_SLOPES)}")
    x0 = np.asarray(op.states, dtype=float)
    u0 = np.asarray(op.inputs, dtype=float)
    nx, nu = len(STATES), len(INPUTS)

    def fx(x):
        return np.concatenate([plant.rhs(x, u0, friction), plant.output(x, u0, friction)])

    def fu(u):
        return np.concatenate([plant.rhs(x0, u, friction), plant.output(x0, u, friction)])

    J_x = np.column_stack([_derivative(fx, x0, i, RELATIVE_STEP * _state_step_scale(i, friction), 0)
                           for i in range(nx)])
    J_u = np.column_stack([_derivative(fu, u0, j, RELATIVE_STEP * INPUT_SCALES[j], _input_side(j, u0[j], valve_slope))
                           for j in range(nu)])
    return J_x[:nx], J_u[:nx], J_x[nx:], J_u[nx:]


def _state_step_scale(i: int, friction: FrictionTreatment) -> float:
    # A regularised friction varies on the velocity scale v_s, which may be far below 0.1 m/s.
    if STATES[i] == "v_m_s" and friction.kind == "regularised":
        return min(STATE_SCALES[i], friction.velocity_scale_m_s)
    return STATE_SCALES[i]


def _input_side(j: int, value: float, valve_slope: str) -> int:
    if INPUTS[j] != "valve_command":
        return 0
    if value >= 1.0:
        return -1
    if value <= -1.0:
        return 1
    if value == 0.0:
        return {"mean": 0, "fill": 1, "vent": -1}[valve_slope]
    return 0


@dataclass(frozen=True)
class MechanicalMode:
    """The pole pair of the load's motion: natural frequency [rad/s], damping ratio, poles."""

    omega_n_rad_s: float
    damping_ratio: float
    poles: tuple[complex, complex]

    @property
    def natural_frequency_Hz(self) -> float:
        """Undamped natural frequency [Hz]."""
        return self.omega_n_rad_s / (2.0 * math.pi)


@dataclass(frozen=True)
class LinearModel:
    """A linearisation: the state-space system, where it was taken and how.

    ``sys`` keeps the state, input and output names of
    :mod:`pamsim.control.system`; ``dropped_states`` lists states removed
    because nothing depends on them (see :func:`linearize`).
    """

    sys: ct.StateSpace
    op: OperatingPoint
    friction: FrictionTreatment
    valve_slope: str
    residual: np.ndarray
    dropped_states: tuple[str, ...]
    jacobian_method: str = "exact"
    """``exact`` (CasADi's derivatives of the generated expressions) or ``central differences``."""
    hysteresis: LoopPoint | None = None
    """The branch and stick states a scenario's hysteresis was linearised in (:mod:`.loop_point`)."""

    @property
    def valve_input(self) -> str:
        """The valve's input: ``valve_command``, or ``pwm_duty`` for the averaged PWM valve."""
        return self.sys.input_labels[0]

    def mechanical_mode(self) -> MechanicalMode:
        """The two poles with the largest participation of the velocity state.

        Participation factors ``|w_k v_k|`` (left and right eigenvectors with
        ``w^T v = 1``) pick the load's pole pair even when the regularised
        friction makes it overdamped (two real poles).  The left eigenvectors are
        LAPACK's own, not the inverse of the right ones: sticking hysteresis
        elements add a repeated pole at 0 (their deflections move with the
        contraction), whose right eigenvectors LAPACK may return parallel.
        """
        from scipy.linalg import eig

        A = self.sys.A
        lam, left, right = eig(A, left=True, right=True)
        k_v = list(self.sys.state_labels).index("v_m_s")
        scale = np.einsum("ik,ik->k", left.conj(), right)  # w_k^H v_k: 0 for a defective pole, which takes no part
        with np.errstate(divide="ignore", invalid="ignore"):
            participation = np.nan_to_num(np.abs(left[k_v, :].conj() * right[k_v, :] / scale))
        i, j = np.argsort(participation)[-2:]
        p1, p2 = complex(lam[i]), complex(lam[j])
        prod = (p1 * p2).real
        omega = math.sqrt(abs(prod))
        zeta = -(p1 + p2).real / (2.0 * omega) if omega > 0 else math.nan
        return MechanicalMode(omega, zeta, tuple(sorted((p1, p2), key=lambda p: p.imag)))

    def gain_at_zero(self, input_name: str | None = None,
                     output_name: str = "contraction_m") -> tuple[float | None, float]:
        """(DC gain, integrator gain) of one channel (``input_name`` None: the valve's input).

        If the channel contains a free integrator (the closed valve integrates
        the command into air mass) the DC gain is infinite and returned as
        None; the integrator gain ``lim_{s->0} s G(s)`` is then the steady
        rate of the output per unit input.  Both come from ``G`` evaluated at
        two small real ``s`` and extrapolated (``G(s) = K_i / s + G_0 + O(s)``).
        """
        g = self.sys[output_name, input_name or self.valve_input]
        scale = max(self.mechanical_mode().omega_n_rad_s, 1.0)
        eps = 1e-7 * scale
        a = eps * float(np.real(g(eps)))
        b = 2.0 * eps * float(np.real(g(2.0 * eps)))
        k_int = 2.0 * a - b
        g0 = (b - a) / eps
        # A free integrator shows as k_int well above what the O(eps) remainder of G0 could leave there.
        if abs(k_int) > 1e-6 * (abs(g0) * scale + abs(k_int)) and abs(k_int) > 0.0:
            return None, k_int
        return g0, 0.0

    def bode(self, input_name: str, output_name: str, omega_rad_s: np.ndarray) -> dict[str, list[float]]:
        """Bode data of one channel: frequency [Hz], magnitude [output unit per input unit], phase [deg].

        The phase is unwrapped along the grid (no 360 deg jumps between neighbouring frequencies).
        """
        resp = ct.frequency_response(self.sys[output_name, input_name], omega_rad_s)
        phase = np.unwrap(np.atleast_1d(np.squeeze(resp.phase)))
        return {"frequency_Hz": [float(w / (2 * math.pi)) for w in omega_rad_s],
                "magnitude": [float(m) for m in np.atleast_1d(np.squeeze(resp.magnitude))],
                "phase_deg": [float(np.degrees(ph)) for ph in phase]}

    def frequency_grid_rad_s(self, n: int = 200) -> np.ndarray:
        """Logarithmic grid two decades either side of the mechanical mode."""
        w = self.mechanical_mode().omega_n_rad_s or 1.0
        return np.logspace(math.log10(w) - 2.0, math.log10(w) + 2.0, n)


def linearize(model: MuscleModel, op: OperatingPoint, friction: FrictionTreatment | None = None,
              valve_slope: str = "mean", drop_unobservable_air_mass: bool = True, added: tuple = ()) -> LinearModel:
    """Linearise ``model`` about ``op``.

    Parameters
    ----------
    model : MuscleModel
        A model with a valve source.
    op : OperatingPoint
        From :mod:`pamsim.control.operating_point`.
    friction : FrictionTreatment, optional
        Default ``dropped``.  ``sliding`` needs a moving load (its direction
        is taken from the sign of the velocity at ``op``).
    valve_slope : {"mean", "fill", "vent"}
        Slope of the valve at command 0 (see the module notes).  The averaged PWM valve's input is the
        duty, whose slope at 0 is always taken into its range (``fill``).
    drop_unobservable_air_mass : bool
        The air mass feeds back only through the gas temperature of venting
        air; where its column of A and C is zero (closed or filling valve, or
        the chamber at supply pressure) it is an unobservable integrator and
        is dropped, which leaves every transfer function unchanged.
    added : tuple of AddedComponent, optional
        Components a scenario adds to the rig (``Scenario.added_components``): forces on the load and
        work integrals, linearised exactly with the rig (no difference quotients for them).  A
        ``[hysteresis]`` model among them is held in the stick state of ``op``
        (:func:`~pamsim.control.loop_point.hold_hysteresis`); ``LinearModel.hysteresis`` says which.

    Returns
    -------
    LinearModel
        With ``sys`` a :class:`control.StateSpace` named like the nonlinear system.

    Raises
    ------
    InputError
        For ``sliding`` at a load at rest, an unknown choice, or an added component with states of its
        own or without exact derivatives.
    """
    friction = friction or FrictionTreatment("dropped")
    v0 = float(op.states[1])
    if friction.kind == "sliding":
        if v0 == 0.0:
            raise InputError("friction 'sliding' needs a moving load; at rest Coulomb friction has no "
                             "linearisation (use 'dropped' or 'regularised')")
        friction = FrictionTreatment("sliding", friction.velocity_scale_m_s, math.copysign(1.0, v0))
    plant = MusclePlant(model)
    if valve_slope not in VALVE_SLOPES:
        raise InputError(f"valve slope {valve_slope!r}: choose from {', '.join(VALVE_SLOPES)}")
    added, op, loop = hold_hysteresis(model, op, added)
    lines = line_states(model, added)
    x0 = _state_vector(model, op, added, lines)
    op = _with_line_states(op, lines, x0)
    # Beyond the composed model's four states (added components, a spool): only the exact derivatives have them.
    beyond_rig = bool(added or lines)
    if input_names(model) != INPUTS:  # the duty: its derivative at 0 is the one into its range [0, 1]
        valve_slope = "fill"
    try:
        A, B, C, D = exact_jacobians(model, x0, op.inputs, friction, valve_slope, added)
        method = "exact"
    except NotImplementedError as exc:  # an element called on floats
        if beyond_rig:
            raise InputError(f"pamsim linearize with added components needs exact derivatives: {exc}") from None
        A, B, C, D = jacobians(plant, op, friction, valve_slope)
        method = "central differences"
    residual = (plant.rhs(op.states, op.inputs, friction) if not beyond_rig
                else np.asarray(control_functions(model, friction, added)[0](x0, op.inputs)[0]).ravel())
    names = list(STATES) + [name for name, _ in lines]
    scales = np.asarray(list(STATE_SCALES) + [nominal for _, nominal in lines])
    keep, dropped = _kept_states(A, C, names, scales) if drop_unobservable_air_mass else (list(range(len(names))), [])
    sys = ct.ss(A[np.ix_(keep, keep)], B[keep], C[:, keep], D, states=[names[k] for k in keep],
                inputs=list(input_names(model)), outputs=list(OUTPUTS), name="muscle_linear")
    dropped = tuple(dropped) + (loop.dropped if loop else ())
    return LinearModel(sys, op, friction, valve_slope, residual, dropped, method, loop)


def _with_line_states(op: OperatingPoint, lines: tuple, x0: np.ndarray) -> OperatingPoint:
    """``op`` with where a held line rests (the states after the rig's four in ``x0``), for the report."""
    if op.kind != "held_pressure" or not lines:
        return op
    rest = {name: float(value) for (name, _), value in zip(lines, x0[4:])}
    return replace(op, line_states={**rest, **op.line_states})


def _kept_states(A: np.ndarray, C: np.ndarray, names: list, scales: np.ndarray) -> tuple[list, list]:
    """``(indices kept, names dropped)``: every air mass (the chamber's, a line volume's) that feeds nothing
    back is dropped."""
    keep, dropped = list(range(len(names))), []
    for k in [k for k, n in enumerate(names) if n.split(".")[-1].endswith("air_mass_kg")]:
        if _uncoupled(A, C, scales, k, keep):
            keep.remove(k)
            dropped.append(names[k])
    return keep, dropped


def _uncoupled(A: np.ndarray, C: np.ndarray, scales: np.ndarray, k: int, keep: list) -> bool:
    """Whether state ``k`` (an air mass) feeds nothing back: its column of A (but its own entry) and of C is
    zero beside the rest of the kept states' A, compared in scaled variables so that kg and Pa columns are
    commensurable."""
    scaled_A = A * scales[None, :] / scales[:, None]
    others = [i for i in keep if i != k]
    coupling = np.max(np.abs(scaled_A[others, k])) + np.max(np.abs(C[:, k])) * scales[k]
    return bool(coupling <= 1e-9 * np.max(np.abs(scaled_A[np.ix_(others, others)])))


def _state_vector(model, op: OperatingPoint, added: tuple, lines: tuple) -> np.ndarray:
    """The rig's four states at ``op``, then the states of the components added to it (``lines``): the
    operating point's own (a run's), or the components at rest at the chamber's pressure where the valve is
    open on its supply (every volume of the line there, no flow), or, the valve closed on a held contraction,
    each volume at the pressure its resistances join it to (:mod:`pamsim.control.line_rest`)."""
    if not lines:
        return np.asarray(op.states, dtype=float)
    # A spool at rest stands at its command; a run's operating point has its own (op.line_states).
    known = {f"valve.{k}": v for k, v in model.source.held_spool(op.inputs[0]).items()} if any(
        name.startswith("valve.") for name, _ in lines) else {}
    known.update(op.line_states)
    if all(name in known for name, _ in lines):
        extra = np.array([known[name] for name, _ in lines], dtype=float)
    elif op.kind == "open_valve":
        extra = held_line_states(model, added, float(op.states[2]), known)
    elif op.kind == "held_pressure":
        extra = held_line_states(model, added, held_line_pressures(added, float(op.states[2]), float(op.inputs[1])),
                                 known)
    else:
        unknown = ", ".join(n for n, _ in lines if n not in known)
        raise InputError(f"operating point {op.kind!r}: a supply line ({unknown}) is linearised at the open "
                         "valve's equilibrium, at a held contraction or at a time of its run (--at-time)")
    return np.concatenate([np.asarray(op.states, dtype=float), extra])
