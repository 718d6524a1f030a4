"""Angle tracking at a commanded stiffness: a joint's muscles driven by a sampled controller.

The pressures of the two muscles set the joint's angle through the difference of their pulls and its
stiffness through their sum.  The controller inverts the static map for both at once (feedforward):
for the reference angle ``theta_r`` and the commanded stiffness ``k_r`` it takes the pressures at which
the link rests at ``theta_r`` with stiffness ``k_r`` (:class:`FeedforwardMap`, solved by Newton's method
on :class:`pamsim.joints.static.JointStatics` at a grid of angles, interpolated between them).  A PID
on the angle error adds a differential pressure (the flexor's up and the extensor's down by the same
amount, which for a symmetric pair moves the stiffness little: the two muscles' stiffness slopes nearly
cancel), with gains placed on the linear model at the
reference's start (:func:`pamsim.joints.linear.linearize_joint`): three closed-loop poles at
``-bandwidth``.  The muscles' pressures are the controller's outputs, held over each sample (pressure-
regulated muscles: pamsim's choice, the valves' dynamics left out).  The run is the python backend's
exact stick/slip integration, advanced sample by sample (:class:`pamsim.simulator.SteppedRun`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..assemblies.joint import at_prescribed_pressure, joint_assembly
from ..errors import InputError
from ..signals import PiecewiseConstant
from ..simulator import GeneratedCode, HybridRun, SteppedRun
from .scenario import JointScenario
from .simulate import ENERGY_SCALE_J
from .static import JointStatics

BAR = 1e5


@dataclass(frozen=True)
class AngleReference:
    """The angle to track [rad]: steps (``steps_time_s``, ``steps_angle_rad``, from 0 rad), then from
    ``sine_start_s`` a sinusoid of ``sine_amplitude_rad`` and ``sine_frequency_Hz`` about the last step's
    angle (none if its amplitude is 0)."""

    steps_time_s: tuple[float, ...]
    steps_angle_rad: tuple[float, ...]
    sine_start_s: float = math.inf
    sine_amplitude_rad: float = 0.0
    sine_frequency_Hz: float = 0.0

    def __call__(self, t_s: float) -> float:
        steps = PiecewiseConstant((0.0, *self.steps_time_s), (0.0, *self.steps_angle_rad))
        theta = float(steps(t_s))
        if t_s >= self.sine_start_s:
            theta += self.sine_amplitude_rad * math.sin(2 * math.pi * self.sine_frequency_Hz * (t_s - self.sine_start_s))
        return theta

    def span_rad(self) -> tuple[float, float]:
        """The smallest and largest angle the reference asks for."""
        last = self.steps_angle_rad[-1] if self.steps_angle_rad else 0.0
        values = [0.0, *self.steps_angle_rad, last - self.sine_amplitude_rad, last + self.sine_amplitude_rad]
        return min(values), max(values)


class FeedforwardMap:
    """The pressures at which a two-muscle joint rests at an angle with a given stiffness, tabulated over
    the angles ``grid_rad`` (Newton's method on the statics) and interpolated linearly between them.

    Raises
    ------
    InputError
        When no pressures within ``[0, p_max_Pa]`` give the stiffness at an angle of the grid.
    """

    def __init__(self, statics: JointStatics, k_Nm_per_rad: float, grid_rad, p_max_Pa: float):
        self.grid_rad = np.asarray(grid_rad, dtype=float)
        self.k_Nm_per_rad = k_Nm_per_rad
        guess = np.array([2.0 * BAR, 2.0 * BAR])
        rows = []
        for theta in self.grid_rad:
            guess = _solve(statics, theta, k_Nm_per_rad, guess, p_max_Pa)
            rows.append(guess)
        self.p_Pa = np.array(rows)

    def __call__(self, theta_rad: float) -> np.ndarray:
        """The two pressures [Pa] at ``theta_rad``."""
        return np.array([np.interp(theta_rad, self.grid_rad, self.p_Pa[:, j]) for j in range(2)])


def _residual(statics: JointStatics, theta: float, k: float, p) -> np.ndarray:
    return np.array([statics.net_torque_Nm(theta, p), statics.stiffness_Nm_per_rad(theta, p) - k])


def _solve(statics: JointStatics, theta: float, k: float, p0, p_max_Pa: float) -> np.ndarray:
    """Newton's method for the pressures where the net torque at rest is zero at ``theta`` and the
    stiffness is ``k``, with finite-difference derivatives (a step of 10 Pa)."""
    p = np.array(p0, dtype=float)
    for _ in range(30):
        r = _residual(statics, theta, k, p)
        if abs(r[0]) < 1e-12 and abs(r[1]) < 1e-10 * max(k, 1e-9):
            return p
        J = np.column_stack([(_residual(statics, theta, k, p + d) - r) / 10.0 for d in np.eye(2) * 10.0])
        try:
            step = np.linalg.solve(J, r)
        except np.linalg.LinAlgError:
            # A muscle's pressure clipped at zero on an elastic tendon: its tendon hangs slack and neither
            # residual moves with that pressure.  The least-squares step moves the other pressure.
            step = np.linalg.lstsq(J, r, rcond=None)[0]
        p = np.clip(p - step, 0.0, p_max_Pa)
    raise InputError(f"no pressures within [0, {p_max_Pa / BAR:g}] bar hold the link at {theta:.4g} rad with "
                     f"that stiffness")


@dataclass(frozen=True)
class Gains:
    """PID gains on the angle error, as torques: ``Kp`` [N m/rad], ``Ki`` [N m/(rad s)], ``Kd`` [N m s/rad]."""

    Kp: float
    Ki: float
    Kd: float


def design_gains(scenario: JointScenario, p_Pa, bandwidth_rad_s: float) -> Gains:
    """PID gains that put the three closed-loop poles of the linear model about the equilibrium at the
    pressures ``p_Pa`` at ``-bandwidth_rad_s``: ``J s^3 + (Kd - c) s^2 + (k + Kp) s + Ki = J (s + w)^3``,
    with ``J`` the inertia, ``k`` the static stiffness and ``c`` the linear model's own damping term (A[1, 1] J).
    On rigid tendons ``k`` is ``-A[1, 0] J``; on elastic ones it takes the muscles' ends at rest, as their
    poles (thousands of 1/s) lie far beyond any bandwidth asked of the link; ``-A[1, 0] J`` would hold them
    still."""
    from .linear import linearize_joint

    lm = linearize_joint(scenario, list(p_Pa))
    J, w = scenario.joint["inertia_kg_m2"], bandwidth_rad_s
    k, c = lm.k0_Nm_per_rad, float(lm.A[1, 1] * J)
    if 3 * J * w * w < k:  # the poles would need a negative Kp: the muscles alone are stiffer than that
        raise InputError(f"{scenario.origin}: controller.bandwidth_rad_s = {w:g}: the joint's own stiffness, "
                         f"{k:.4g} N m/rad, puts its poles beyond it; give at least {np.sqrt(k / (3 * J)):.4g} rad/s")
    return Gains(Kp=3 * J * w * w - k, Ki=J * w ** 3, Kd=3 * J * w + c)


@dataclass
class ClosedLoopJoint:
    """A closed-loop joint run: per sample, the time, angle, angular velocity, reference, the two
    pressures, the stiffness at rest at the angle and pressures (:class:`JointStatics`), and the mode."""

    t_s: np.ndarray
    theta_rad: np.ndarray
    omega_rad_s: np.ndarray
    reference_rad: np.ndarray
    p_Pa: np.ndarray
    k_Nm_per_rad: np.ndarray
    mode: np.ndarray
    gains: Gains
    k_target_Nm_per_rad: float

    def columns(self, names: tuple[str, str]) -> dict[str, np.ndarray]:
        """The run's columns by name (``names``: the two muscles, in the scenario's order)."""
        return {"t_s": self.t_s, "theta_rad": self.theta_rad, "omega_rad_s": self.omega_rad_s,
                "reference_rad": self.reference_rad, f"{names[0]}.p_gauge_Pa": self.p_Pa[:, 0],
                f"{names[1]}.p_gauge_Pa": self.p_Pa[:, 1], "k_Nm_per_rad": self.k_Nm_per_rad, "mode": self.mode}

    def rms(self, start_s: float, end_s: float) -> tuple[float, float]:
        """RMS of the angle error [rad] and of the stiffness error [N m/rad] over ``[start_s, end_s)``."""
        window = (self.t_s >= start_s) & (self.t_s < end_s)
        e = self.theta_rad[window] - self.reference_rad[window]
        dk = self.k_Nm_per_rad[window] - self.k_target_Nm_per_rad
        return float(np.sqrt(np.mean(e * e))), float(np.sqrt(np.mean(dk * dk)))


def metrics(run: ClosedLoopJoint, reference: AngleReference, settle_s: float, end_s: float) -> dict[str, float]:
    """The angle's RMS error over the settled part of the steps (from ``settle_s`` after each step to the
    next change of the reference), over the sinusoid, and the stiffness's RMS error over the whole run."""
    edges = [*reference.steps_time_s, min(reference.sine_start_s, end_s)]
    settled = [(a + settle_s, b) for a, b in zip(edges[:-1], edges[1:]) if a + settle_s < b]
    out = {}
    if settled:
        window = np.zeros(run.t_s.size, dtype=bool)
        for a, b in settled:
            window |= (run.t_s >= a) & (run.t_s < b)
        e = run.theta_rad[window] - run.reference_rad[window]
        out["step_angle_rms_rad"] = float(np.sqrt(np.mean(e * e)))
    if reference.sine_amplitude_rad > 0 and reference.sine_start_s < end_s:
        out["sine_angle_rms_rad"] = run.rms(reference.sine_start_s, end_s + 1.0)[0]
    out["stiffness_rms_Nm_per_rad"] = run.rms(0.0, end_s + 1.0)[1]
    return out


SPEC_OF = {"step_angle_rms_max_rad": "step_angle_rms_rad", "sine_angle_rms_max_rad": "sine_angle_rms_rad",
           "stiffness_rms_max_Nm_per_rad": "stiffness_rms_Nm_per_rad"}
"""Each ``[controller.spec]`` bound and the metric it bounds."""


def spec_failures(measured: dict[str, float], spec: dict[str, float]) -> list[str]:
    """The items of ``spec`` that ``measured`` misses, one line each (a metric the run lacks is missed)."""
    out = []
    for key, bound in spec.items():
        value = measured.get(SPEC_OF[key])
        if value is None or not value <= bound:
            out.append(f"{SPEC_OF[key]} = {value if value is None else f'{value:.4g}'} (spec <= {bound:g})")
    return out


def controller_of(scenario: JointScenario) -> "AngleStiffnessController":
    """The controller the scenario's ``[controller]`` table describes."""
    c = scenario.controller
    reference = AngleReference(c["steps_time_s"], c["steps_angle_rad"], c["sine_start_s"], c["sine_amplitude_rad"],
                               c["sine_frequency_Hz"])
    return AngleStiffnessController(scenario, reference, c["stiffness_Nm_per_rad"], c["sample_rate_Hz"],
                                    c["bandwidth_rad_s"])


class AngleStiffnessController:
    """The controller of a two-muscle joint scenario (module docstring): ``reference`` the angle to track,
    ``k_Nm_per_rad`` the stiffness to hold, sampled at ``sample_rate_Hz``, its PID's poles at
    ``-bandwidth_rad_s``; pressures within ``[0, the muscles' rating]``.

    Raises
    ------
    InputError
        A joint without exactly two muscles, one with a side other than the other's opposite, or a
        stiffness the muscles cannot give over the reference's angles.
    """

    def __init__(self, scenario: JointScenario, reference: AngleReference, k_Nm_per_rad: float,
                 sample_rate_Hz: float, bandwidth_rad_s: float):
        sides = [t["side"] for t, _ in scenario.muscles]
        if sorted(sides) != [-1.0, 1.0]:
            raise InputError(f"{scenario.origin}: controller: an angle and stiffness controller drives two muscles "
                             f"on opposite sides, not {len(sides)} with sides {sides}")
        self.scenario, self.reference = scenario, reference
        self.k_Nm_per_rad, self.dt_s = k_Nm_per_rad, 1.0 / sample_rate_Hz
        self.p_max_Pa = min(sc.parameters["rated_pressure_gauge_Pa"] for _, sc in scenario.muscles)
        self.statics = JointStatics(scenario)
        lo, hi = reference.span_rad()
        margin = 0.05 * (hi - lo) + 1e-3
        try:
            self.feedforward = FeedforwardMap(self.statics, k_Nm_per_rad, np.linspace(lo - margin, hi + margin, 25),
                                              self.p_max_Pa)
        except InputError as exc:
            raise InputError(f"{scenario.origin}: controller.stiffness_Nm_per_rad = {k_Nm_per_rad:g}: {exc} (the "
                             f"reference spans {lo:.4g} to {hi:.4g} rad)") from None
        self.gains = design_gains(scenario, self.feedforward(reference(0.0)), bandwidth_rad_s)
        self._flexor = sides.index(1.0)

    def pressures(self, t_s: float, theta_rad: float, omega_rad_s: float, integral: float) -> np.ndarray:
        """The two pressures [Pa] at ``t_s`` for the measured angle and velocity and the error's integral."""
        theta_r = self.reference(t_s)
        p = self.feedforward(theta_r)
        g = self.gains
        torque = g.Kp * (theta_r - theta_rad) + g.Ki * integral - g.Kd * omega_rad_s
        # the differential pressure that gives this torque at rest, the flexor's up and the extensor's down
        dtau = _torque_slopes(self.statics, theta_r, p)
        sign = np.where(np.arange(2) == self._flexor, 1.0, -1.0)
        delta = torque / max(float(np.dot(dtau, sign)), 1e-12)
        return np.clip(p + delta * sign, 0.0, self.p_max_Pa)

    def run(self, backend: str = "python") -> ClosedLoopJoint:
        """The closed loop over the scenario's duration: the plant on the python backend (``solve_ivp``,
        exact stick/slip), the native one (the generic engine, advanced a sample at a time) or its FMU in
        co-simulation (``fmu-cs``).

        Raises
        ------
        InputError
            A backend other than those three.
        """
        if backend not in STEPPERS:
            raise InputError(f"{self.scenario.origin}: backend {backend!r}: the joint's controller runs on "
                             f"{' and '.join(STEPPERS)}")
        held = np.zeros(2)
        stepper = STEPPERS[backend](self.scenario, held)
        theta_at = stepper.state_names.index("joint.theta_rad")
        omega_at = stepper.state_names.index("joint.omega_rad_s")
        n = int(round(self.scenario.duration_s / self.dt_s))
        rows, integral = [], 0.0
        for k in range(n + 1):
            t = k * self.dt_s
            theta, omega = float(stepper.y[theta_at]), float(stepper.y[omega_at])
            held[:] = self.pressures(t, theta, omega, integral)
            rows.append((t, theta, omega, self.reference(t), *held, self.statics.stiffness_Nm_per_rad(theta, held),
                         int(stepper.mode)))
            if np.all((held > 0.0) & (held < self.p_max_Pa)):  # no wind-up while a pressure is at its bound
                integral += (self.reference(t) - theta) * self.dt_s
            if k < n:
                stepper.advance((k + 1) * self.dt_s)
        a = np.array(rows)
        return ClosedLoopJoint(a[:, 0], a[:, 1], a[:, 2], a[:, 3], a[:, 4:6], a[:, 6], a[:, 7].astype(int),
                               self.gains, self.k_Nm_per_rad)


def _torque_slopes(statics: JointStatics, theta: float, p) -> np.ndarray:
    """d tau / d p of each muscle's pressure at rest [N m/Pa] (central differences, 10 Pa)."""
    out = []
    for d in np.eye(2) * 10.0:
        out.append((statics.net_torque_Nm(theta, p + d) - statics.net_torque_Nm(theta, p - d)) / 20.0)
    return np.array(out)


def _pressure_assembly(scenario: JointScenario):
    """The joint with each muscle's pressure a model input."""
    muscles = tuple(at_prescribed_pressure(m) for m in scenario.joint_muscles())
    return joint_assembly(scenario.joint_values(), muscles, scenario.joint["g_m_s2"], name=scenario.name)


class _EngineStepper:
    """The joint on the native engine, advanced by its caller with the pressures ``held`` holds (the
    interface of :class:`pamsim.simulator.SteppedRun` that :meth:`AngleStiffnessController.run` uses)."""

    def __init__(self, scenario: JointScenario, held: np.ndarray):
        from ..native.backend import native_rtol, stiff_switch
        from ..native.engine import engine_library

        assembly = _pressure_assembly(scenario)
        self.session = engine_library(assembly).session()
        self.state_names = tuple(self.session.library.names["states"])
        self.held, self.external = held, scenario.external_torque
        opts = scenario.solver
        self.session.reset(assembly.parameter_values(), self._inputs(0.0), native_rtol(opts),
                           opts.max_step_s if math.isfinite(opts.max_step_s) else 0.1, 1_000_000, stiff_switch(opts))

    def _inputs(self, t: float) -> list[float]:
        return [*map(float, self.held), float(self.external(t))]

    @property
    def y(self) -> np.ndarray:
        return self.session.states

    @property
    def mode(self) -> int:
        return self.session.mode

    def advance(self, t_end_s: float) -> None:
        self.session.advance(self._inputs(self.session.time_s), t_end_s)


class _FmuStepper:
    """The joint's FMU in co-simulation (fmpy, FMI 2.0), stepped by its caller with the pressures ``held``
    holds set as its inputs (``input_source = importer``) before each step; its own Dormand-Prince 5(4)
    at the scenario's ``rtol``."""

    def __init__(self, scenario: JointScenario, held: np.ndarray):
        import shutil
        import weakref

        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        from ..fmu.build import build_spec, temp_fmu
        from .fmu import joint_fmu_spec

        spec = joint_fmu_spec(scenario)
        path = temp_fmu(spec.token, f"{spec.identifier}_fmi2.fmu", lambda out: build_spec(out, spec))
        md = read_model_description(str(path))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        unzipped = extract(str(path))
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                             instanceName="joint")
        self._cleanup = weakref.finalize(self, shutil.rmtree, unzipped, True)
        self.state_names = tuple(spec.states)
        self._states = [vr[n] for n in spec.states]
        self._inputs_vr = [vr[n] for n in spec.inputs]
        self._mode = [vr["joint.mode"]]
        self.held, self.external, self.t = held, scenario.external_torque, 0.0
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0, stopTime=scenario.duration_s)
        self.fmu.setInteger([vr["input_source"]], [0])
        self.fmu.setReal([vr["cs_relative_tolerance"]], [scenario.solver.rtol])
        self.fmu.setReal(self._inputs_vr, self._inputs(0.0))
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def _inputs(self, t: float) -> list[float]:
        return [*map(float, self.held), float(self.external(t))]

    @property
    def y(self) -> np.ndarray:
        return np.array(self.fmu.getReal(self._states))

    @property
    def mode(self) -> int:
        return int(self.fmu.getInteger(self._mode)[0])

    def advance(self, t_end_s: float) -> None:
        self.fmu.setReal(self._inputs_vr, self._inputs(self.t))
        self.fmu.doStep(currentCommunicationPoint=self.t, communicationStepSize=t_end_s - self.t)
        self.t = t_end_s


def _stepper(scenario: JointScenario, held: np.ndarray) -> SteppedRun:
    """A stepped python run of the joint with each muscle's pressure the value ``held`` holds."""
    assembly = _pressure_assembly(scenario)
    external = scenario.external_torque

    def inputs(t):
        return [*held, external(t)]

    nominal = [ENERGY_SCALE_J if v.unit == "J" else v.nominal for v in assembly.flatten().states]
    gen = GeneratedCode(assembly, "joint", inputs, nominal)
    return SteppedRun.of(HybridRun(gen, scenario.duration_s, scenario.solver, (), math.inf, None))


STEPPERS = {"python": _stepper, "native": _EngineStepper, "fmu-cs": _FmuStepper}
"""How the controller's plant runs, by backend."""
