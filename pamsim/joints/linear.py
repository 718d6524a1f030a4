"""A joint's linear model about its equilibrium at given muscle pressures: the MIMO system from the
muscles' pressure inputs to the joint angle and the joint's stiffness.

The model is the joint's own flat model with its Coulomb terms dropped (the bearing's and the muscles':
they have no derivative at rest, as the one-muscle ``linearize`` drops them by default), written for a
link that moves (its angular velocity is a state) and differentiated exactly by CasADi.  The states are
the integrated ones (the work integrals, which nothing reads, are left out); the inputs each muscle's
prescribed gauge pressure and the external torque; the outputs the angle and the stiffness
``k = -d tau_net / d theta`` at rest, whose own derivatives are CasADi's second derivatives of the net
torque.  A muscle fed by a valve is refused: its chamber at rest sits where the valve's flow has no
derivative (a pressure ratio of 1).

A muscle's hysteresis elements (``[muscle.hysteresis]``) are taken at the equilibrium as the one-muscle
``linearize`` takes them at rest (:mod:`pamsim.control.loop_point`): relaxed, every Maxwell-slip element
sticking (a spring on the muscle's flange, its deflection a state), Bouc-Wen on its loading branch; the model
says so (``hysteresis``).  The stiffness output is the static one, ``-d tau_net / d theta`` with the
elements' deflections held: their springs act through their states.

A muscle on an elastic tendon (:class:`pamsim.components.series_tendon.SeriesTendon`) adds its end's
contraction as a state, taken at its own rest (:class:`pamsim.joints.static.JointStatics` finds it: its
static force, with what is added on its end, equals its tendon's pull).  Its friction dropped, the massless end's velocity is the damping
law's inverse of the force left to it, differentiable there.  The stiffness output is then the muscle and
its tendon in series: ``-d tau_net / d theta`` with each end following the link so that its forces stay
balanced (``dx/dtheta = -g_theta / g_x``, ``g`` the force left to its damping), written in the state, so
that its own derivatives are again CasADi's.  Against the link, an end's spring acts through its state:
the angle's row of ``A`` is the stiffness with the ends held, the static ``k`` the ends' rest included.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..assemblies.joint import at_prescribed_pressure, joint_assembly, series_spring_name
from ..assemblies.stick_state import BRANCHES, HYSTERESIS, LoopPoint, held
from ..components.stick_slip import BodyMode
from ..elements.pressure_source import PrescribedPressure
from ..errors import InputError
from .scenario import JointScenario
from .static import JointStatics, without_coulomb


@dataclass(frozen=True)
class JointLinearModel:
    """``dx/dt = A dx + B du``, ``dy = C dx + D du`` about ``theta0_rad`` at pressures ``p0_gauge_Pa``.

    ``states``, ``inputs`` and ``outputs`` name the rows and columns (outputs: ``joint.theta_rad`` and
    ``joint.k_Nm_per_rad``); ``k0_Nm_per_rad`` is the stiffness at the operating point; ``hysteresis``:
    ``(muscle, LoopPoint)`` for each muscle with hysteresis elements, the stick state they were taken in.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    theta0_rad: float
    p0_gauge_Pa: tuple[float, ...]
    k0_Nm_per_rad: float
    hysteresis: tuple[tuple[str, LoopPoint], ...] = ()

    def poles(self) -> np.ndarray:
        """The eigenvalues of ``A`` [1/s]."""
        return np.linalg.eigvals(self.A)

    def to_control(self):
        """The model as a python-control ``StateSpace`` with named states, inputs and outputs (python-control
        allows no ``.`` in a name: ``joint.theta_rad`` is ``joint_theta_rad`` there)."""
        import control

        plain = lambda names: [n.replace(".", "_") for n in names]  # noqa: E731
        return control.ss(self.A, self.B, self.C, self.D, states=plain(self.states), inputs=plain(self.inputs),
                          outputs=plain(self.outputs))


def _prescribed(scenario: JointScenario):
    """The joint's muscles with constant prescribed pressures, refusing a muscle fed by a valve."""
    muscles = scenario.joint_muscles()
    for m in muscles:
        if not isinstance(m.source, PrescribedPressure):
            raise InputError(f"{scenario.origin}: muscle {m.name!r}: pressure.source = {m.source.name!r}: a joint is "
                             "linearised with each muscle's pressure prescribed (a valve's flow has no derivative "
                             "at rest); give it a prescribed pressure")
    return tuple(at_prescribed_pressure(m) for m in muscles)


def linearize_joint(scenario: JointScenario, p_gauge_Pa) -> JointLinearModel:
    """The linear model of ``scenario``'s joint about its equilibrium at the muscles' gauge pressures
    ``p_gauge_Pa`` (in the scenario's muscle order).

    Raises
    ------
    InputError
        A muscle fed by a valve, pressures that push the link onto a limit (no equilibrium inside), or a
        static force without a symbolic form.
    """
    muscles = _prescribed(scenario)
    statics = JointStatics(scenario)
    eq = statics.equilibrium(p_gauge_Pa)
    if eq.on_limit:
        raise InputError(f"{scenario.origin}: at {[p / 1e5 for p in p_gauge_Pa]} bar the link rests on its "
                         f"{eq.on_limit} limit: there is no equilibrium to linearise about")
    u0 = [float(v) for v in p_gauge_Pa] + [0.0]
    rest = statics.rest_state(eq.theta_rad, p_gauge_Pa)
    muscles, loops = _relaxed_hysteresis(scenario, muscles, eq.theta_rad, u0, rest)
    assembly = joint_assembly(scenario.joint_values(), muscles, scenario.joint["g_m_s2"], name=scenario.name)
    moving, held = (assembly.flatten({"joint": int(m)}) for m in (BodyMode.SLIP_UP, BodyMode.STICK))
    if moving.externals:
        raise InputError(f"{scenario.origin}: a static force without a symbolic form cannot be linearised exactly")
    keep = [i for i in range(len(moving.states)) if i not in moving.quadratures()]
    x0 = _operating_state(moving, eq.theta_rad, rest)
    ends = [series_spring_name(m) for m in muscles if m.tendon_stiffness_N_per_m is not None]
    A, B, C, D, k0 = (np.array(m, dtype=float)
                      for m in _jacobians(moving, held, keep, ends)(x0, u0, _without_coulomb(moving)))
    return JointLinearModel(A, B, C, D, tuple(moving.states[i].name for i in keep), tuple(v.name for v in moving.inputs),
                            ("joint.theta_rad", "joint.k_Nm_per_rad"), eq.theta_rad,
                            tuple(float(v) for v in p_gauge_Pa), float(k0.item()), loops)


def _relaxed_hysteresis(scenario: JointScenario, muscles: tuple, theta_rad: float, u0: list,
                        rest: dict) -> tuple[tuple, tuple]:
    """``(muscles, loops)``: each muscle's hysteresis elements held relaxed at the equilibrium ``theta_rad``
    (the muscles' ends on elastic tendons at their ``rest``)
    (:mod:`pamsim.control.loop_point`'s rule at rest: Maxwell-slip elements sticking, Bouc-Wen on its
    loading branch) at their friction level there, and what was held, per muscle."""
    names = [f"{m.name}_{a.component.name}.level_N" for m in muscles for a in m.added
             if isinstance(a.component, HYSTERESIS)]
    if not names:
        return muscles, ()
    flat = joint_assembly(scenario.joint_values(), muscles, scenario.joint["g_m_s2"]).flatten(
        {"joint": int(BodyMode.STICK)})
    levels = _outputs_at(flat, _operating_state(flat, theta_rad, rest), u0, names)
    out, loops = [], []
    for m in muscles:
        added = []
        for a in m.added:
            if not isinstance(a.component, HYSTERESIS):
                added.append(a)
                continue
            c = a.component
            state = {f"{c.name}.{k}": v for k, v in c.held_state(0.0).items()}
            component, loop = held(c, state, 0, levels[f"{m.name}_{c.name}.level_N"])
            added.append(replace(a, component=component))
            named = tuple({**e, "name": f"{m.name}_{e['name']}"} for e in loop.elements)
            loops.append((m.name, replace(loop, branch=BRANCHES[0], branch_from="an equilibrium: the elements relaxed",
                                          elements=named)))
        out.append(replace(m, added=tuple(added)))
    return tuple(out), tuple(loops)


def _outputs_at(flat, x0: list, u0: list, names: list[str]) -> dict[str, float]:
    """The values of ``flat``'s outputs ``names`` at states ``x0`` and inputs ``u0`` (its own parameters)."""
    import casadi as ca

    index = [v.name for v in flat.outputs]
    f = ca.Function("outputs_at", [ca.vertcat(*flat.x), ca.vertcat(*flat.u), ca.vertcat(*flat.p)],
                    [ca.vertcat(*[flat.y[index.index(n)] for n in names])])
    values = np.array(f(x0, u0, flat.parameter_values), dtype=float).ravel()
    return dict(zip(names, (float(v) for v in values)))


def _without_coulomb(flat) -> np.ndarray:
    """``flat``'s parameter values with the Coulomb terms zero (:func:`pamsim.joints.static.without_coulomb`)."""
    return without_coulomb([v.name for v in flat.parameters], flat.parameter_values)


def _jacobians(moving, held, keep: list[int], ends: list[str]):
    """CasADi function of (x, u, p): df/dx and df/du of the moving link's states ``keep``, d/dx and d/du of
    the outputs (angle, stiffness at rest), and the stiffness itself.  ``ends``: the muscles on elastic
    tendons' springs, whose ends follow the link in the stiffness (see the module's docstring)."""
    import casadi as ca

    x, u, p = ca.vertcat(*moving.x), ca.vertcat(*moving.u), ca.vertcat(*moving.p)
    xs, f = ca.vertcat(*[moving.x[i] for i in keep]), ca.vertcat(*[moving.f[i] for i in keep])
    names = [v.name for v in moving.states]
    theta = moving.x[names.index("joint.theta_rad")]
    outputs = [v.name for v in held.outputs]

    def held_output(name: str):  # in the moving model's symbols: one set of symbols
        return ca.substitute(held.y[outputs.index(name)], ca.vertcat(*held.x, *held.u, *held.p), ca.vertcat(x, u, p))

    tau = held_output("joint.tau_net_Nm")
    k = -ca.jacobian(tau, theta)
    if ends:
        x_end = ca.vertcat(*[moving.x[names.index(f"{spring}.x_m")] for spring in ends])
        g = ca.vertcat(*[held_output(f"{spring}.F_free_N") for spring in ends])
        follow = -ca.solve(ca.jacobian(g, x_end), ca.jacobian(g, theta))  # dx_end / dtheta at the ends' rest
        k = k - ca.mtimes(ca.jacobian(tau, x_end), follow)
    y = ca.vertcat(theta, k)
    return ca.Function("joint_linear", [x, u, p],
                       [ca.jacobian(f, xs), ca.jacobian(f, u), ca.jacobian(y, xs), ca.jacobian(y, u), k])


def _operating_state(flat, theta_rad: float, rest: dict | None = None) -> list[float]:
    """Every state at the operating point: the link at ``theta_rad`` at rest, the states ``rest`` gives
    (``{name: value}``: a muscle's end on an elastic tendon), the others (work integrals) zero."""
    names = [v.name for v in flat.states]
    x0 = [0.0] * len(names)
    x0[names.index("joint.theta_rad")] = theta_rad
    for name, value in (rest or {}).items():
        x0[names.index(name)] = value
    return x0
