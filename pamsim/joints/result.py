"""A joint run's result: the joint's angle and velocity, every state and output of its assembly by
name, the mode changes, and the energy balance; plotting is in :mod:`pamsim.joints.plots`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..components.stick_slip import BodyMode
from ..result import write_columns

MUSCLE_COLUMNS = ("p_gauge_Pa", "x_m", "F_tendon_N", "tau_Nm")
"""Per muscle, the columns of a joint run's CSV (``<muscle>.<quantity>``)."""


@dataclass(frozen=True)
class JointEvent:
    """A mode change of the joint: when, why, from and to which mode, at which angle."""

    t_s: float
    kind: str
    from_mode: str
    to_mode: str
    theta_rad: float


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

    @property
    def theta_rad(self) -> np.ndarray:
        """Joint angle [rad] at the samples."""
        return self.signals["joint.theta_rad"]

    @property
    def omega_rad_s(self) -> np.ndarray:
        """Joint angular velocity [rad/s] at the samples (zero while held)."""
        return self.signals["joint.omega_rad_s"]

    @property
    def final_mode(self) -> BodyMode:
        """The joint's mode at the end of the run."""
        return BodyMode(int(self.mode[-1]))

    def muscle(self, name: str, quantity: str) -> np.ndarray:
        """A muscle's signal: ``p_gauge_Pa`` (its pressure), ``x_m`` (contraction), ``F_tendon_N``,
        ``tau_Nm`` (its torque on the joint), ``taut``, ``moment_arm_m``, ``F_static_N``; ``KeyError`` for an
        unknown one."""
        attach = "pulley" if f"{name}_pulley.x_m" in self.signals else "lever"
        where = {"p_gauge_Pa": "pressure", "x_m": attach, "F_tendon_N": attach, "tau_Nm": attach,
                 "taut": attach, "moment_arm_m": attach, "F_static_N": "muscle"}
        if quantity == "p_gauge_Pa":
            found = [k for k in self.signals if k.startswith(f"{name}_") and k.endswith(".p_gauge_Pa")
                     and k.split(".")[0] in (f"{name}_chamber", f"{name}_pressure")]
            return self.signals[found[0]]
        return self.signals[f"{name}_{where[quantity]}.{quantity}"]

    def signals_key(self, muscle: str, name: str) -> str:
        """The name in :attr:`signals` of the variable ``name`` of ``muscle``'s pulley or lever."""
        return f"{muscle}_pulley.{name}" if f"{muscle}_pulley.{name}" in self.signals else f"{muscle}_lever.{name}"

    def energy_balance(self) -> dict[str, float]:
        """The tendons' and the external torque's work against what the link gained and lost [J].

        ``residual_J`` = work in - (kinetic + potential gain + bearing friction + impacts); ``relative``
        divides it by the largest term.  Per muscle, ``<name>.slack_J`` is the work of its forces that
        no tendon passed on (nonzero only where it went slack): static work - damping - friction - tendon.
        """
        s = self.signals
        d = lambda key: float(s[key][-1] - s[key][0])  # noqa: E731
        tendon = {m: self.signals_key(m, "W_tendon_J") for m in self.muscles}
        terms = {f"{m}.W_tendon_J": float(s[tendon[m]][-1]) for m in self.muscles}
        terms.update({"W_external_J": float(s["joint.W_external_J"][-1]), "dKE_J": d("joint.kinetic_energy_J"),
                      "dPE_J": d("joint.potential_energy_J"), "E_viscous_J": float(s["joint.E_viscous_J"][-1]),
                      "E_coulomb_J": float(s["joint.E_coulomb_J"][-1]), "E_impacts_J": float(sum(self.impact_losses_J))})
        residual = (sum(terms[f"{m}.W_tendon_J"] for m in self.muscles) + terms["W_external_J"] - terms["dKE_J"]
                    - terms["dPE_J"] - terms["E_viscous_J"] - terms["E_coulomb_J"] - terms["E_impacts_J"])
        slack = {f"{m}.slack_J": float(s[f"{m}_muscle.W_muscle_J"][-1] - s[f"{m}_damping.E_damping_J"][-1]
                                       - s[f"{m}_friction.E_friction_J"][-1] - s[tendon[m]][-1])
                 for m in self.muscles}
        scale = max(abs(v) for v in terms.values()) or 1.0
        return {**terms, **slack, "residual_J": float(residual), "relative": float(abs(residual) / scale)}

    def columns(self) -> dict[str, np.ndarray]:
        """``t_s``, ``theta_rad``, ``omega_rad_s``, ``mode``, then per muscle :data:`MUSCLE_COLUMNS`, then the
        joint's gravity, muscle, external and net torques."""
        cols = {"t_s": self.t_s, "theta_rad": self.theta_rad, "omega_rad_s": self.omega_rad_s, "mode": self.mode}
        for m in self.muscles:
            cols.update({f"{m}.{q}": self.muscle(m, q) for q in MUSCLE_COLUMNS})
        cols.update({k: self.signals[f"joint.{k}"] for k in ("tau_gravity_Nm", "tau_muscles_Nm", "tau_applied_Nm",
                                                                  "tau_net_Nm")})
        return cols

    def to_csv(self, path) -> None:
        """Write :meth:`columns`, one row per sample. Atomic."""
        write_columns(path, self.columns())

    def summary(self) -> dict:
        """The run in numbers: final and extreme angles, final mode, each muscle's final pressure, tendon
        force and torque, the events, the solver's statistics and the energy balance."""
        return {"name": self.name, "final_theta_rad": float(self.theta_rad[-1]),
                "peak_theta_rad": float(self.peaks.get("theta_rad", np.max(self.theta_rad))),
                "min_theta_rad": float(self.peaks.get("theta_min_rad", np.min(self.theta_rad))),
                "final_mode": self.final_mode.label,
                "muscles": {m: {q: float(self.muscle(m, q)[-1]) for q in MUSCLE_COLUMNS} for m in self.muscles},
                "events": [{"t_s": e.t_s, "kind": e.kind, "from": e.from_mode, "to": e.to_mode, "theta_rad": e.theta_rad}
                           for e in self.transitions],
                "stats": {**self.stats, "wall_time_s": self.wall_time_s}, "energy_balance": self.energy_balance()}

    def plot(self, path=None, dpi: int | None = None):
        """Angle, pressures and torques over time (:func:`pamsim.joints.plots.plot_joint`)."""
        from .plots import plot_joint

        return plot_joint(self, path, dpi=dpi)
