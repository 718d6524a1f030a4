"""The joint at rest: its net torque, equilibrium angle and stiffness for given muscle pressures.

Everything comes from the joint's own generated code, with each muscle's pressure prescribed: the net
torque is the joint's output ``tau_net_Nm`` in its held mode (no velocity, so no damping and no
friction), and the stiffness ``k = -d tau_net / d theta`` is its exact derivative (CasADi's Jacobian
of the same output).  At an equilibrium ``k`` is the joint's stiffness against a small rotation: the
slope of the muscles' torques and of gravity; co-contraction raises it without moving the angle.

A muscle on an elastic tendon (:class:`pamsim.components.series_tendon.SeriesTendon`) rests where its
static force, with what is added on its end (a spring), equals its tendon's pull, without friction (the middle of the band its friction holds it
in): at each angle its contraction is that root, and the stiffness is the total derivative through it
(the muscle and its tendon in series).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..assemblies.joint import at_prescribed_pressure, attachment_name, joint_assembly, series_spring_name
from ..components.stick_slip import BodyMode
from ..errors import InputError
from ..modeling.pygen import compiled_by_mode
from .scenario import JointScenario


def without_coulomb(names, values) -> np.ndarray:
    """The parameter ``values`` (named ``names``) with the Coulomb terms zero: the bearing's and every muscle's
    friction."""
    p = np.array(values, dtype=float)
    for k, name in enumerate(names):
        if name == "joint.tau_coulomb_Nm" or name.split(".")[0].endswith("_friction"):
            p[k] = 0.0
    return p


@dataclass(frozen=True)
class Equilibrium:
    """Where the joint rests at given pressures: ``theta_rad``, the stiffness there ``k_Nm_per_rad``, and
    ``on_limit`` (``"lower"``/``"upper"`` if the torques push it onto a limit, where ``k`` is the muscles'
    and gravity's slope at the limit, else None)."""

    theta_rad: float
    k_Nm_per_rad: float
    on_limit: str | None


class JointStatics:
    """The joint of ``scenario`` with each muscle's pressure prescribed, at rest.

    Parameters
    ----------
    scenario : JointScenario
        The joint and its muscles (their pressure sources are replaced by prescribed pressures).
    """

    def __init__(self, scenario: JointScenario):
        if scenario.body.name != "joint":
            raise InputError(f"{scenario.origin}: the statics, stiffness and linearisation of muscles are for a joint; "
                             f"this scenario's muscles move a {scenario.body.name}")
        self.scenario = scenario
        muscles = tuple(at_prescribed_pressure(m) for m in scenario.joint_muscles())
        assembly = joint_assembly(scenario.joint_values(), muscles, scenario.joint["g_m_s2"], name=scenario.name)
        self.names = [m.name for m in muscles]
        self.code = compiled_by_mode(assembly, "joint", ("y", "jacobian"))[int(BodyMode.STICK)]
        self.p = assembly.parameter_values()
        states = self.code.names["states"]
        self._theta = states.index("joint.theta_rad")
        self._net = self.code.names["outputs"].index("joint.tau_net_Nm")
        self._n_states = len(states)
        self._limits = (scenario.joint["theta_min_rad"], scenario.joint["theta_max_rad"])
        outputs = self.code.names["outputs"]
        # A muscle end's balance is read with the Coulomb terms zero: the force left to its damping is then
        # its static force, what is added on it (a spring) and its tendon's pull together.
        self._frictionless = without_coulomb(self.code.names["parameters"], self.p)
        self._springs = [(states.index(f"{series_spring_name(m)}.x_m"), outputs.index(f"{series_spring_name(m)}.F_free_N"),
                          outputs.index(f"{attachment_name(m)}.x_m"), m.name)
                         for m in muscles if m.tendon_stiffness_N_per_m is not None]

    def _point(self, theta_rad: float, p_gauge_Pa) -> tuple[list, list]:
        if len(p_gauge_Pa) != len(self.names):
            raise ValueError(f"{len(p_gauge_Pa)} pressures for the muscles {self.names}")
        x = [0.0] * self._n_states
        x[self._theta] = float(theta_rad)
        u = [float(p) for p in p_gauge_Pa] + [0.0]  # then the external torque
        for spring in self._springs:
            x[spring[0]] = self._muscle_at_rest(x, u, spring)
        return x, u

    def _muscle_at_rest(self, x: list, u: list, spring: tuple) -> float:
        """The contraction at which a muscle on an elastic tendon pulls what its tendon does, the link at
        ``x``: the root of ``F_static + F_others - T`` (what is added on its end among ``F_others``), which
        falls as the muscle contracts (its force drops, its tendon stretches).  Bracketed from the tendon's
        unstretched length outward."""
        from scipy.optimize import brentq

        index, free, path_x, name = spring

        def gap(x_m: float) -> float:
            y = list(x)
            y[index] = x_m
            return float(self.code.y(y, u, self._frictionless, (float(BodyMode.STICK),))[0][free])

        path = self.code.y(x, u, self.p, (float(BodyMode.STICK),))[0][path_x]
        step = 1e-3
        low, high = path, path
        while gap(high) > 0.0:
            low, high, step = high, high + step, 2.0 * step
            if step > 1.0:
                raise InputError(f"muscle {name!r}: no contraction within 1 m at which it pulls what its tendon does")
        while gap(low) < 0.0:
            low, high, step = low - step, low, 2.0 * step
            if step > 1.0:
                raise InputError(f"muscle {name!r}: no contraction within 1 m at which it pulls what its tendon does")
        return low if gap(low) == 0.0 else brentq(gap, low, high, xtol=1e-15, rtol=4 * np.finfo(float).eps)

    def rest_state(self, theta_rad: float, p_gauge_Pa) -> dict[str, float]:
        """``{state name: contraction [m]}`` of each muscle's end on an elastic tendon at rest, the link at
        ``theta_rad`` and the muscles at ``p_gauge_Pa`` (empty with rigid tendons)."""
        x, _ = self._point(theta_rad, p_gauge_Pa)
        states = self.code.names["states"]
        return {states[spring[0]]: x[spring[0]] for spring in self._springs}

    def net_torque_Nm(self, theta_rad: float, p_gauge_Pa) -> float:
        """Net torque on the link at rest at ``theta_rad`` with the muscles at ``p_gauge_Pa`` (in the
        scenario's muscle order): the muscles' and gravity's."""
        x, u = self._point(theta_rad, p_gauge_Pa)
        return float(self.code.y(x, u, self.p, (float(BodyMode.STICK),))[0][self._net])

    def stiffness_Nm_per_rad(self, theta_rad: float, p_gauge_Pa) -> float:
        """``-d tau_net / d theta`` at rest [N m/rad], exactly."""
        x, u = self._point(theta_rad, p_gauge_Pa)
        C = self.code.jacobian(x, u, self.p, (float(BodyMode.STICK),))[2]
        k = -C[self._net, self._theta]
        if self._springs:
            G = self.code.jacobian(x, u, self._frictionless, (float(BodyMode.STICK),))[2]
        for index, free, _, _ in self._springs:
            # The muscle follows the link so that its balance g stays zero: dx/dtheta = -g_theta / g_x.
            k -= C[self._net, index] * (-G[free, self._theta] / G[free, index])
        return float(k)

    def equilibrium(self, p_gauge_Pa) -> Equilibrium:
        """The angle where the net torque vanishes between the limits (the stable one: torque falling
        through zero), or the limit the torques push the link onto."""
        from scipy.optimize import brentq

        lo, hi = self._limits
        grid = np.linspace(lo, hi, 65)
        tau = np.array([self.net_torque_Nm(t, p_gauge_Pa) for t in grid])
        falls = np.nonzero((tau[:-1] >= 0.0) & (tau[1:] <= 0.0))[0]
        if falls.size:
            k = falls[0]
            theta = grid[k] if tau[k] == 0.0 else brentq(lambda t: self.net_torque_Nm(t, p_gauge_Pa), grid[k],
                                                          grid[k + 1], xtol=1e-14, rtol=4 * np.finfo(float).eps)
            return Equilibrium(float(theta), self.stiffness_Nm_per_rad(theta, p_gauge_Pa), None)
        on = "upper" if tau[-1] > 0.0 else "lower"
        theta = hi if on == "upper" else lo
        return Equilibrium(float(theta), self.stiffness_Nm_per_rad(theta, p_gauge_Pa), on)


@dataclass(frozen=True)
class EquilibriumMap:
    """Equilibria over a grid of two muscles' pressures: ``theta_rad[i, j]`` and ``k_Nm_per_rad[i, j]`` at
    ``p_first_Pa[i]`` and ``p_second_Pa[j]``, ``on_limit[i, j]`` ("" between the limits), the muscles'
    names in that order."""

    names: tuple[str, str]
    p_first_Pa: np.ndarray
    p_second_Pa: np.ndarray
    theta_rad: np.ndarray
    k_Nm_per_rad: np.ndarray
    on_limit: np.ndarray

    def rows(self) -> list[dict]:
        """One dict per grid point: both pressures [Pa], the angle [rad], the stiffness [N m/rad], the limit."""
        return [{f"{self.names[0]}.p_gauge_Pa": float(a), f"{self.names[1]}.p_gauge_Pa": float(b),
                 "theta_rad": float(self.theta_rad[i, j]), "k_Nm_per_rad": float(self.k_Nm_per_rad[i, j]),
                 "on_limit": str(self.on_limit[i, j])}
                for i, a in enumerate(self.p_first_Pa) for j, b in enumerate(self.p_second_Pa)]


def equilibrium_map(statics: JointStatics, p_first_Pa, p_second_Pa) -> EquilibriumMap:
    """The equilibrium angle and stiffness of a two-muscle joint at every pair of the pressures given.

    Raises
    ------
    ValueError
        For a joint without exactly two muscles.
    """
    if len(statics.names) != 2:
        raise ValueError(f"an equilibrium map needs two muscles, not {len(statics.names)} ({statics.names})")
    a, b = np.asarray(p_first_Pa, dtype=float), np.asarray(p_second_Pa, dtype=float)
    theta, k = np.empty((a.size, b.size)), np.empty((a.size, b.size))
    limit = np.full((a.size, b.size), "", dtype=object)
    for i, pa in enumerate(a):
        for j, pb in enumerate(b):
            eq = statics.equilibrium([pa, pb])
            theta[i, j], k[i, j], limit[i, j] = eq.theta_rad, eq.k_Nm_per_rad, eq.on_limit or ""
    return EquilibriumMap(tuple(statics.names), a, b, theta, k, limit)
