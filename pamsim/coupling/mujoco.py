"""pamsim muscles driving the actuators of a MuJoCo model.

Each muscle is the muscle-only model (:mod:`pamsim.assemblies.muscle_only`: its static force, friction,
damping and pressure source, length and lengthening velocity in, force out) on the native engine, one
:class:`~pamsim.native.engine.EngineSession` per muscle.  It pulls on a MuJoCo tendon through a
``general`` actuator of gain 1: before each MuJoCo step, :meth:`MujocoMuscles.step` reads each tendon's
length and velocity, advances each muscle's pneumatics over the step with them held, and writes minus
the muscle's tension (a tendon only pulls) as the actuator's control; then MuJoCo steps.  The force a
muscle applies over a step is the one its pneumatics reach at the step's end, from the length at its
start: an explicit coupling, first order in the time step, as MuJoCo's own integration is.

MuJoCo is an optional dependency: ``pip install 'pamsim[mujoco]'``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ..assemblies.muscle_only import muscle_only_assembly
from ..errors import InputError
from ..native.engine import engine_library

MAX_INTERNAL_STEPS = 100_000
"""The most integrator steps a muscle takes in one MuJoCo step."""


@dataclass
class CoupledMuscle:
    """One pamsim muscle on one MuJoCo actuator.

    ``name``: the muscle's name; ``scenario``: a one-muscle :class:`pamsim.scenario.Scenario` giving its
    muscle, static force model, friction and damping laws and pressure source (its load and stops are not
    used); ``actuator``: the name of the MuJoCo ``general`` actuator (gain 1) on its tendon;
    ``length_offset_m``: the muscle's length minus the tendon's (MuJoCo's fixed tendon length is its
    coefficients times the joint angles); ``pressure_inputs``: the pressure source's inputs at a time
    (default: the scenario's signals), replaceable by a controller's.
    """

    name: str
    scenario: Any
    actuator: str
    length_offset_m: float
    pressure_inputs: Callable[[float], Sequence[float]] | None = None
    _session: Any = field(default=None, repr=False)
    _inputs: np.ndarray = field(default=None, repr=False)
    _force_at: int = field(default=0, repr=False)
    _n_pressure: int = field(default=0, repr=False)


class MujocoMuscles:
    """pamsim muscles driving a MuJoCo model's actuators, advanced a MuJoCo step at a time.

    Parameters
    ----------
    model, data : mujoco.MjModel, mujoco.MjData
        The MuJoCo model and its data.
    muscles : sequence of CoupledMuscle
        The muscles and their actuators.
    rtol : float
        Relative tolerance of each muscle's integrator.

    Raises
    ------
    InputError
        A muscle's actuator missing from the model, or not on a tendon; two muscles with one name.
    """

    def __init__(self, model, data, muscles: Sequence[CoupledMuscle], rtol: float = 1e-6):
        import mujoco

        self.model, self.data, self.muscles = model, data, list(muscles)
        names = [m.name for m in self.muscles]
        if len(set(names)) != len(names):
            raise InputError(f"muscles {names}: a name is given twice")
        self._actuator, self._tendon = [], []
        for m in self.muscles:
            a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, m.actuator)
            if a < 0:
                raise InputError(f"muscle {m.name!r}: actuator = {m.actuator!r}: the MuJoCo model has no such actuator")
            if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_TENDON:
                raise InputError(f"muscle {m.name!r}: actuator = {m.actuator!r}: it does not act on a tendon")
            self._actuator.append(a)
            self._tendon.append(int(model.actuator_trnid[a, 0]))
            self._start(m, rtol)

    def _start(self, m: CoupledMuscle, rtol: float) -> None:
        sc = m.scenario
        model = sc.build_model()
        assembly = muscle_only_assembly(model, sc.parameters["L0_m"], sc.parameters["g_m_s2"], sc.initial_pressure_gauge_Pa)
        library = engine_library(assembly)
        m._session = library.session()
        names = library.names
        m._n_pressure = len(names["inputs"]) - 2  # then length_m, lengthening_velocity_m_s
        m._force_at = names["outputs"].index("motion.F_N")
        if m.pressure_inputs is None:
            m.pressure_inputs = model.source.inputs
        m._inputs = np.zeros(len(names["inputs"]))
        self._fill(m, self.muscles.index(m))
        m._session.reset(assembly.parameter_values(), m._inputs, rtol, 1e-3, MAX_INTERNAL_STEPS)

    def _fill(self, m: CoupledMuscle, k: int) -> None:
        """The muscle's inputs now: its pressure inputs, then its length and lengthening velocity."""
        d = self.data
        m._inputs[:m._n_pressure] = [float(v) for v in m.pressure_inputs(float(d.time))]
        m._inputs[m._n_pressure] = m.length_offset_m + d.ten_length[self._tendon[k]]
        m._inputs[m._n_pressure + 1] = d.ten_velocity[self._tendon[k]]

    def step(self) -> None:
        """Advance every muscle over the next MuJoCo step and set its actuator's control; call
        ``mujoco.mj_step`` after it (or use :meth:`mj_step`)."""
        t_end = float(self.data.time) + float(self.model.opt.timestep)
        for k, m in enumerate(self.muscles):
            self._fill(m, k)
            m._session.step(m._inputs, t_end)
            self.data.ctrl[self._actuator[k]] = -max(float(m._session.outputs[m._force_at]), 0.0)

    def mj_step(self) -> None:
        """:meth:`step`, then one MuJoCo step."""
        import mujoco

        self.step()
        mujoco.mj_step(self.model, self.data)

    def tension_N(self, name: str) -> float:
        """The tension muscle ``name`` applies over the current step [N]."""
        k = next(i for i, m in enumerate(self.muscles) if m.name == name)
        return -float(self.data.ctrl[self._actuator[k]])

    def outputs(self, name: str) -> dict[str, float]:
        """Every output of muscle ``name``'s model at the end of its last step, by name
        (``chamber.p_gauge_Pa``, ``motion.F_N``...)."""
        m = next(m for m in self.muscles if m.name == name)
        return dict(zip(m._session.library.names["outputs"], m._session.outputs.tolist()))


def joint_mjcf(scenario, timestep_s: float = 1e-3) -> str:
    """The MuJoCo model (MJCF text) of a joint scenario's link: a hinge with the link's inertia about it,
    its weight (hanging down at angle zero), the bearing's viscous friction and the limits, and per
    muscle a fixed tendon of coefficient ``-side radius`` (its length falls as the muscle contracts) and
    a ``general`` actuator of gain 1 named after the muscle.  The bearing's Coulomb friction becomes the
    hinge's ``frictionloss``, MuJoCo's soft friction constraint, and the limits its soft limits: close to
    pamsim's exact stick/slip and stops, not equal to them.

    Raises
    ------
    InputError
        A joint whose link does not hang down at angle zero, whose inertia is not above its mass's
        ``m l^2`` about the hinge, with a muscle on a lever, or a slider scenario.
    """
    if scenario.body.name != "joint":
        raise InputError(f"{scenario.origin}: joint_mjcf writes a hinge; this scenario's muscles move a "
                         f"{scenario.body.name}")
    j = scenario.joint
    for t, _ in scenario.muscles:
        if t["lever"] is not None:
            raise InputError(f"{scenario.origin}: muscle {t['name']!r}: attachment = 'lever': joint_mjcf writes "
                             "pulleys (fixed tendons); write a spatial tendon for a lever into your own MuJoCo model")
    m, l, J = j["link_mass_kg"], j["com_distance_m"], j["inertia_kg_m2"]
    for key, ok in (("theta_down_rad", j["theta_down_rad"] == 0.0), ("inertia_kg_m2", J > m * l * l)):
        if not ok:
            raise InputError(f"{scenario.origin}: joint.{key} = {j[key]!r}: the MuJoCo model takes a link hanging "
                             "down at angle zero, and an inertia above m l^2 (its centre of mass's share)")
    own = J - m * l * l  # about the centre of mass
    tendons = "\n".join(f'    <fixed name="{t["name"]}_tendon"><joint joint="hinge" coef="{-t["side"] * t["radius_m"]!r}"/></fixed>'
                        for t, _ in scenario.muscles)
    actuators = "\n".join(f'    <general name="{t["name"]}" tendon="{t["name"]}_tendon" gainprm="1" ctrllimited="false"/>'
                          for t, _ in scenario.muscles)
    return f"""<mujoco model="{scenario.name}">
  <compiler angle="radian"/>
  <option timestep="{timestep_s!r}" gravity="0 0 {-j['g_m_s2']!r}"/>
  <worldbody>
    <body name="link">
      <joint name="hinge" type="hinge" axis="0 1 0" damping="{j['b_Nm_s_per_rad']!r}"
             frictionloss="{j['tau_coulomb_Nm']!r}"
             range="{j['theta_min_rad']!r} {j['theta_max_rad']!r}" limited="true"/>
      <inertial pos="0 0 {-l!r}" mass="{max(m, 1e-9)!r}" diaginertia="{own!r} {own!r} {own!r}"/>
    </body>
  </worldbody>
  <tendon>
{tendons}
  </tendon>
  <actuator>
{actuators}
  </actuator>
</mujoco>
"""


def joint_muscles(scenario) -> list[CoupledMuscle]:
    """The muscles of a joint scenario on the actuators of :func:`joint_mjcf`: each muscle's length is its
    rest length minus its contraction at angle zero, plus the tendon's length."""
    return [CoupledMuscle(t["name"], sc, t["name"], sc.parameters["L0_m"] - t["x_at_zero_m"]) for t, sc in scenario.muscles]
