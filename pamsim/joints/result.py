"""A joint run's result: the joint's angle and velocity, every state and output of its assembly by
name, the mode changes, and the energy balance; plotting is in :mod:`pamsim.joints.plots`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..components.stick_slip import BodyMode
from ..result import write_columns
from .body import JOINT, Body

MUSCLE_COLUMNS = ("p_gauge_Pa", "x_m", "F_tendon_N", "tau_Nm")
"""Per muscle, the columns of a joint run's CSV (``<muscle>.<quantity>``); on a slider ``F_N`` in place of
``tau_Nm`` (the force of its tendon on the carriage)."""
THERMAL_COLUMNS = ("gas_temperature_K",)
"""Per muscle whose chamber has the thermal law, the columns that follow :data:`MUSCLE_COLUMNS`."""
ATTACHMENTS = ("pulley", "lever", "tendon")
"""The suffixes of a muscle's attachment's name: a joint's pulley or lever, a slider's tendon."""


@dataclass(frozen=True)
class JointEvent:
    """A mode change of the joint (slider): when, why, from and to which mode, at which angle (position)."""

    t_s: float
    kind: str
    from_mode: str
    to_mode: str
    coordinate: float
    """The body's coordinate after the event: a joint's angle [rad], a slider's position [m]."""

    @property
    def theta_rad(self) -> float:
        """A joint's angle after the event [rad]."""
        return self.coordinate


@dataclass
class JointResult:
    """Trace of one joint run, sampled at the output rate.

    ``signals`` holds every state and output of the assembly under its flat name
    (``joint.theta_rad``, ``flexor_chamber.p_gauge_Pa``, ``extensor_pulley.tau_Nm``...);
    ``impact_losses_J`` the kinetic energy each event removed (a stop without rebound); ``peaks`` the
    largest and smallest angle over every integrator step, which the samples may miss.
    """

    name: str
    t_s: np.ndarray
    signals: Mapping[str, np.ndarray] = field(repr=False)
    mode: np.ndarray = field(repr=False)
    transitions: list[JointEvent] = field(repr=False)
    impact_losses_J: list[float] = field(repr=False)
    stats: dict = field(repr=False)
    wall_time_s: float
    muscles: tuple[str, ...]
    peaks: dict[str, float] = field(default_factory=dict)
    body: Body = JOINT
    """The body the muscles moved (:data:`pamsim.joints.body.JOINT` or ``SLIDER``): the names of its
    variables in :attr:`signals`."""

    def body_signal(self, name: str) -> np.ndarray:
        """A variable of the body (``theta_rad``, ``tau_gravity_Nm``; a slider's ``x_m``, ``F_gravity_N``)."""
        return self.signals[f"{self.body.name}.{name}"]

    @property
    def position(self) -> np.ndarray:
        """The body's coordinate at the samples: a joint's angle [rad], a slider's position [m]."""
        return self.body_signal(self.body.position)

    @property
    def velocity(self) -> np.ndarray:
        """The body's velocity at the samples (zero while held): [rad/s] or [m/s]."""
        return self.body_signal(self.body.velocity)

    @property
    def theta_rad(self) -> np.ndarray:
        """Joint angle [rad] at the samples (a slider's result has none: :attr:`position`)."""
        return self._joint_signal("theta_rad")

    @property
    def omega_rad_s(self) -> np.ndarray:
        """Joint angular velocity [rad/s] at the samples (zero while held)."""
        return self._joint_signal("omega_rad_s")

    def _joint_signal(self, name: str) -> np.ndarray:
        if self.body.name != "joint":
            raise AttributeError(f"{name}: a {self.body.name}'s result has no joint angle; it has position "
                                 f"({self.body.position}) and velocity ({self.body.velocity})")
        return self.signals[f"joint.{name}"]

    @property
    def final_mode(self) -> BodyMode:
        """The joint's mode at the end of the run."""
        return BodyMode(int(self.mode[-1]))

    def muscle(self, name: str, quantity: str) -> np.ndarray:
        """A muscle's signal: ``p_gauge_Pa`` (its pressure), ``x_m`` (contraction), ``F_tendon_N``,
        ``tau_Nm`` (its torque on the joint; on a slider ``F_N``, its force on the carriage), ``taut``,
        ``moment_arm_m``, ``F_static_N``, on an elastic tendon ``stretch_m``, and with a thermal chamber
        ``gas_temperature_K``; ``KeyError`` for an unknown one."""
        attach = next(a for a in ATTACHMENTS if f"{name}_{a}.x_m" in self.signals)
        # On an elastic tendon the muscle's own end is the spring's node; its attachment's x_m is the path's.
        end = "series_spring" if f"{name}_series_spring.x_m" in self.signals else attach
        where = {"p_gauge_Pa": "pressure", "x_m": end, "F_tendon_N": attach, "tau_Nm": attach, "F_N": attach,
                 "taut": attach, "moment_arm_m": attach, "F_static_N": "muscle", "stretch_m": "series_spring",
                 "gas_temperature_K": "chamber"}
        if quantity == "p_gauge_Pa":
            found = [k for k in self.signals if k.startswith(f"{name}_") and k.endswith(".p_gauge_Pa")
                     and k.split(".")[0] in (f"{name}_chamber", f"{name}_pressure")]
            return self.signals[found[0]]
        return self.signals[f"{name}_{where[quantity]}.{quantity}"]

    def thermal_muscles(self) -> tuple[str, ...]:
        """The muscles whose chamber has the thermal law (a gas temperature of its own, and the wall's heat)."""
        return tuple(m for m in self.muscles if f"{m}_chamber.wall_heat_W" in self.signals)

    def _quantities(self, muscle: str) -> tuple[str, ...]:
        """A muscle's columns: :data:`MUSCLE_COLUMNS` (the body's effort last), then :data:`THERMAL_COLUMNS` for a
        thermal chamber."""
        own = (*MUSCLE_COLUMNS[:-1], self.body.attach_effort)
        return own + THERMAL_COLUMNS if muscle in self.thermal_muscles() else own

    def signals_key(self, muscle: str, name: str) -> str:
        """The name in :attr:`signals` of the variable ``name`` of ``muscle``'s pulley, lever or tendon."""
        return next(key for a in ATTACHMENTS if (key := f"{muscle}_{a}.{name}") in self.signals)

    def energy_balance(self) -> dict[str, float]:
        """The tendons' and the external torque's (force's) work against what the body gained and lost [J].

        ``residual_J`` = work in - (kinetic + potential gain + bearing friction + impacts); ``relative``
        divides it by the largest term.  Per muscle, ``<name>.slack_J`` is the work of its forces that
        no tendon passed on (nonzero only where it went slack): static work - damping - friction - tendon,
        less what an elastic tendon stored, plus what the components added on the muscle's end gave it
        (their ``W_`` terms, the rig's convention) less what they took (``E_``: the hysteresis').
        """
        s = self.signals
        d = lambda key: float(s[key][-1] - s[key][0])  # noqa: E731
        tendon = {m: self.signals_key(m, "W_tendon_J") for m in self.muscles}
        terms = {f"{m}.W_tendon_J": float(s[tendon[m]][-1]) for m in self.muscles}
        b = self.body.name
        terms.update({"W_external_J": float(s[f"{b}.W_external_J"][-1]), "dKE_J": d(f"{b}.kinetic_energy_J"),
                      "dPE_J": d(f"{b}.potential_energy_J"), "E_viscous_J": float(s[f"{b}.E_viscous_J"][-1]),
                      "E_coulomb_J": float(s[f"{b}.E_coulomb_J"][-1]), "E_impacts_J": float(sum(self.impact_losses_J))})
        residual = (sum(terms[f"{m}.W_tendon_J"] for m in self.muscles) + terms["W_external_J"] - terms["dKE_J"]
                    - terms["dPE_J"] - terms["E_viscous_J"] - terms["E_coulomb_J"] - terms["E_impacts_J"])
        slack = {f"{m}.slack_J": float(s[f"{m}_muscle.W_muscle_J"][-1] - s[f"{m}_damping.E_damping_J"][-1]
                                       - s[f"{m}_friction.E_friction_J"][-1] - s[tendon[m]][-1]
                                       - (d(k) if (k := f"{m}_series_spring.E_elastic_J") in s else 0.0)
                                       + sum(self._added_work_J(m)))
                 for m in self.muscles}
        scale = max(abs(v) for v in terms.values()) or 1.0
        return {**terms, **slack, "residual_J": float(residual), "relative": float(abs(residual) / scale)}

    def _added_work_J(self, muscle: str) -> list[float]:
        """The work [J] each component added on ``muscle``'s end gave it (``W_`` states) or took (``E_``,
        negative): every ``<muscle>_<component>.W_*`` or ``.E_*`` but the muscle's own forces' and tendon's."""
        own = {f"{muscle}_muscle", f"{muscle}_damping", f"{muscle}_friction", f"{muscle}_series_spring",
               self.signals_key(muscle, "W_tendon_J").split(".")[0]}
        out = []
        for key, values in self.signals.items():
            owner, _, var = key.partition(".")
            other = any(owner.startswith(f"{o}_") for o in self.muscles if len(o) > len(muscle))  # "a_b" vs "a"
            if owner.startswith(f"{muscle}_") and not other and owner not in own and var[:2] in ("W_", "E_"):
                out.append(float(values[-1]) if var.startswith("W_") else -float(values[-1]))
        return out

    def columns(self) -> dict[str, np.ndarray]:
        """``t_s``, ``theta_rad``, ``omega_rad_s``, ``mode``, then per muscle :data:`MUSCLE_COLUMNS` (and
        :data:`THERMAL_COLUMNS` with a thermal chamber), then the joint's gravity, muscle, external and net
        torques (a slider's: ``x_m``, ``v_m_s``, forces)."""
        body = self.body
        cols = {"t_s": self.t_s, body.position: self.position, body.velocity: self.velocity, "mode": self.mode}
        for m in self.muscles:
            cols.update({f"{m}.{q}": self.muscle(m, q) for q in self._quantities(m)})
        cols.update({k: self.body_signal(k) for k in map(body.effort_name, ("gravity", "muscles", "applied", "net"))})
        return cols

    def to_csv(self, path) -> None:
        """Write :meth:`columns`, one row per sample. Atomic."""
        write_columns(path, self.columns())

    def summary(self) -> dict:
        """The run in numbers: final and extreme angles, final mode, each muscle's final pressure, tendon
        force and torque, the events, the solver's statistics and the energy balance."""
        pos, q = self.body.position, self.position
        return {"name": self.name, f"final_{pos}": float(q[-1]),
                f"peak_{pos}": float(self.peaks.get(pos, np.max(q))),
                f"min_{pos}": float(self.peaks.get(self.body.min_key, np.min(q))),
                "final_mode": self.final_mode.label,
                "muscles": {m: {k: float(self.muscle(m, k)[-1]) for k in self._quantities(m)} for m in self.muscles},
                "events": [{"t_s": e.t_s, "kind": e.kind, "from": e.from_mode, "to": e.to_mode, pos: e.coordinate}
                           for e in self.transitions],
                "stats": {**self.stats, "wall_time_s": self.wall_time_s}, "energy_balance": self.energy_balance()}

    def plot(self, path=None, dpi: int | None = None):
        """Angle, pressures and torques over time (:func:`pamsim.joints.plots.plot_joint`)."""
        from .plots import plot_joint

        return plot_joint(self, path, dpi=dpi)
