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

import math
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
    (default: the scenario's signals), replaceable by a controller's; ``tendon_stiffness_N_per_m``: a spring
    in series between the muscle and MuJoCo's tendon (None: rigid), whose massless muscle end is a state of
    pamsim's (:func:`pamsim.assemblies.muscle_only.muscle_only_assembly`): the length MuJoCo gives is then
    the spring's far end, and the force it gets back the spring's pull.
    """

    name: str
    scenario: Any
    actuator: str
    length_offset_m: float
    pressure_inputs: Callable[[float], Sequence[float]] | None = None
    tendon_stiffness_N_per_m: float | None = None
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
        mujoco.mj_forward(model, data)  # the tendons' lengths at the start, which each muscle's chamber starts from
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
        try:
            assembly = muscle_only_assembly(model, sc.parameters["L0_m"], sc.parameters["g_m_s2"],
                                            sc.initial_pressure_gauge_Pa, sc.added_components,
                                            m.tendon_stiffness_N_per_m)
        except ValueError as exc:
            raise InputError(f"muscle {m.name!r}: {exc}") from None
        library = engine_library(assembly)
        m._session = library.session()
        names = library.names
        m._n_pressure = len(names["inputs"]) - 2  # then length_m, lengthening_velocity_m_s
        m._force_at = names["outputs"].index("motion.F_N")
        if m.pressure_inputs is None:
            m.pressure_inputs = model.source.inputs
        m._inputs = np.zeros(len(names["inputs"]))
        self._fill(m, self.muscles.index(m), float(self.data.time))
        m._session.reset(assembly.parameter_values(), m._inputs, rtol, 1e-3, MAX_INTERNAL_STEPS)

    def _fill(self, m: CoupledMuscle, k: int, t_s: float) -> None:
        """The muscle's inputs: its pressure inputs at ``t_s``, then its length and lengthening velocity now."""
        d = self.data
        m._inputs[:m._n_pressure] = [float(v) for v in m.pressure_inputs(t_s)]
        m._inputs[m._n_pressure] = m.length_offset_m + d.ten_length[self._tendon[k]]
        m._inputs[m._n_pressure + 1] = d.ten_velocity[self._tendon[k]]

    def step(self) -> None:
        """Advance every muscle over the next MuJoCo step from the tendons' lengths and velocities in
        ``data`` and set its actuator's control.  Those must be the current state's: call it between
        ``mujoco.mj_step1`` and ``mujoco.mj_step2`` (as :meth:`mj_step` does), or after ``mujoco.mj_forward``;
        after ``mujoco.mj_step`` they are the previous step's."""
        dt = float(self.model.opt.timestep)
        t_end = float(self.data.time) + dt
        for k, m in enumerate(self.muscles):
            # The pressure inputs at the step's middle: a valve that opens on a step's boundary opens at it
            # however MuJoCo's clock has rounded the boundary.
            self._fill(m, k, t_end - 0.5 * dt)
            m._session.step(m._inputs, t_end)
            self.data.ctrl[self._actuator[k]] = -max(float(m._session.outputs[m._force_at]), 0.0)

    def mj_step(self) -> None:
        """One MuJoCo step with the muscles' forces: ``mj_step1`` (the current tendon lengths and
        velocities), :meth:`step`, ``mj_step2`` (MuJoCo's documented split for controls that read the
        state; with the Euler integrator the same as ``mj_step``)."""
        import mujoco

        mujoco.mj_step1(self.model, self.data)
        self.step()
        mujoco.mj_step2(self.model, self.data)

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
    """The MuJoCo model (MJCF text) of a joint scenario's body and tendons, per muscle a ``general``
    actuator of gain 1 named after the muscle.

    A joint becomes a hinge about y with the link's inertia about it, its weight (hanging down at angle
    zero), the bearing's viscous friction and the limits; a slider a slide joint along its guide, with
    the carriage's mass.  A muscle on a pulley (or a slider's tendon) pulls on a fixed tendon of
    coefficient ``-side radius`` (``-side``): its length falls as the muscle contracts.  A muscle on a
    lever pulls on a spatial tendon between a site on the world at ``base_attach_m`` from the joint and
    one on the link at ``link_attach_m``, the two at ``angle_at_zero_rad`` apart at angle zero, as
    :class:`pamsim.components.pulley.LeverAttachment` places them.  The Coulomb friction of the bearing
    (guide) becomes the joint's ``frictionloss``, MuJoCo's soft friction constraint, and the limits its
    soft limits: close to pamsim's exact stick/slip and stops, not equal to them.  The keyframe
    ``initial`` holds the scenario's initial angle (position): ``mujoco.mj_resetDataKeyframe(model, data, 0)``.

    Raises
    ------
    InputError
        A joint whose link does not hang down at angle zero, or whose inertia is not above its mass's
        ``m l^2`` about the hinge.
    """
    j = scenario.joint
    g = j["g_m_s2"]
    if scenario.body.name == "slider":
        body = _slide_body(j)
    else:
        m, l, J = j["link_mass_kg"], j["com_distance_m"], j["inertia_kg_m2"]
        for key, ok in (("theta_down_rad", j["theta_down_rad"] == 0.0), ("inertia_kg_m2", J > m * l * l)):
            if not ok:
                raise InputError(f"{scenario.origin}: joint.{key} = {j[key]!r}: the MuJoCo model takes a link hanging "
                                 "down at angle zero, and an inertia above m l^2 (its centre of mass's share)")
        own = J - m * l * l  # about the centre of mass
        links = "\n".join(_site(f"{t['name']}_link", t["lever"]["link_attach_m"], LINK_ANGLE)
                          for t, _ in scenario.muscles if t["lever"] is not None)
        body = f"""    <body name="link">
      <joint name="hinge" type="hinge" axis="0 1 0" damping="{j['b_Nm_s_per_rad']!r}"
             frictionloss="{j['tau_coulomb_Nm']!r}"
             range="{j['theta_min_rad']!r} {j['theta_max_rad']!r}" limited="true"/>
      <inertial pos="0 0 {-l!r}" mass="{max(m, 1e-9)!r}" diaginertia="{own!r} {own!r} {own!r}"/>
{links}
    </body>"""
    bases = "\n".join(_site(f"{t['name']}_base", t["lever"]["base_attach_m"],
                            LINK_ANGLE + t["side"] * t["lever"]["angle_at_zero_rad"])
                      for t, _ in scenario.muscles if t["lever"] is not None)
    tendons = "\n".join(_tendon(t, scenario.body.name) for t, _ in scenario.muscles)
    actuators = "\n".join(f'    <general name="{t["name"]}" tendon="{t["name"]}_tendon" gainprm="1" ctrllimited="false"/>'
                          for t, _ in scenario.muscles)
    return f"""<mujoco model="{scenario.name}">
  <compiler angle="radian"/>
  <option timestep="{timestep_s!r}" gravity="0 0 {-g!r}"/>
  <worldbody>
{bases}
{body}
  </worldbody>
  <tendon>
{tendons}
  </tendon>
  <actuator>
{actuators}
  </actuator>
  <keyframe>
    <key name="initial" qpos="{j[scenario.body.limit_keys[2]]!r}"/>
  </keyframe>
</mujoco>
"""


LINK_ANGLE = math.pi / 2
"""Where the link points at angle zero, as the angle ``gamma`` of a point ``(cos gamma, 0, -sin gamma)``
in the hinge's plane (straight down); a hinge angle ``theta`` about y turns ``gamma`` into
``gamma + theta``."""


def _site(name: str, radius_m: float, gamma: float) -> str:
    """A site at ``radius_m`` from the joint, at angle ``gamma`` (:data:`LINK_ANGLE`'s convention)."""
    return f'    <site name="{name}" pos="{radius_m * math.cos(gamma)!r} 0 {-radius_m * math.sin(gamma)!r}"/>'


def _tendon(t: dict, body: str) -> str:
    """A muscle's tendon: fixed on a pulley or a slider, spatial on a lever."""
    if t["lever"] is not None:
        return (f'    <spatial name="{t["name"]}_tendon"><site site="{t["name"]}_base"/>'
                f'<site site="{t["name"]}_link"/></spatial>')
    joint, coef = ("carriage", -t["side"]) if body == "slider" else ("hinge", -t["side"] * t["radius_m"])
    return f'    <fixed name="{t["name"]}_tendon"><joint joint="{joint}" coef="{coef!r}"/></fixed>'


def _slide_body(j: dict) -> str:
    """A slider's carriage on a slide joint along its guide (x up the slope)."""
    a, m = j["incline_rad"], j["mass_kg"]
    return f"""    <body name="carriage">
      <joint name="carriage" type="slide" axis="{math.cos(a)!r} 0 {math.sin(a)!r}" damping="{j['b_N_s_per_m']!r}"
             frictionloss="{j['F_coulomb_N']!r}" range="{j['x_min_m']!r} {j['x_max_m']!r}" limited="true"
             ref="0"/>
      <inertial pos="0 0 0" mass="{m!r}" diaginertia="{m * 1e-4!r} {m * 1e-4!r} {m * 1e-4!r}"/>
    </body>"""


def joint_muscles(scenario) -> list[CoupledMuscle]:
    """The muscles of a joint (slider) scenario on the actuators of :func:`joint_mjcf`: each muscle's length
    is its tendon's MuJoCo length plus an offset, its rest length less its contraction at angle (position)
    zero on a fixed tendon, less the tendon's own length on a lever's spatial one.  On an elastic tendon
    MuJoCo's tendon is its rigid path, and the spring in series and the muscle's end are pamsim's
    (``CoupledMuscle.tendon_stiffness_N_per_m``)."""
    return [CoupledMuscle(t["name"], sc, t["name"], sc.parameters["L0_m"] - t["x_at_zero_m"] if t["lever"] is None
                          else -t["lever"]["tendon_length_m"], tendon_stiffness_N_per_m=t.get("tendon_stiffness_N_per_m"))
            for t, sc in scenario.muscles]
