"""The result of a muscle driven by its length: the motion, the pressure, the force and every state and output
of the muscle-only assembly at the samples."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..result import write_columns
from .motion import Motion

LOOP_COLUMNS = ("t_s", "p_gauge_Pa", "x_m", "force_N")
"""The first columns of the CSV, those ``pamsim fit hysteresis`` reads (a prescribed-length loop)."""


@dataclass
class LengthDrivenResult:
    """A run of a muscle alone along a :class:`~pamsim.muscle_alone.motion.Motion`.

    ``signals``: every state and output of the assembly at the samples ``t_s`` [s], by the flat model's
    names (``motion.F_N``, ``muscle.F_static_N``, ``hysteresis.z1_m``, ...); ``pressure_output`` names the
    gauge pressure among them; ``events``: ``(t_s, indicator name)`` of each event.
    """

    name: str
    backend: str
    motion: Motion
    t_s: np.ndarray
    signals: dict
    pressure_output: str
    events: list
    stats: dict
    wall_time_s: float

    @property
    def contraction_m(self) -> np.ndarray:
        """The contraction ``L0 - L`` [m]."""
        return self.signals["motion.x_m"]

    @property
    def length_m(self) -> np.ndarray:
        """The muscle's length [m]."""
        return self.motion.L0_m - self.contraction_m

    @property
    def velocity_m_s(self) -> np.ndarray:
        """The contraction velocity [m/s] (minus the lengthening velocity)."""
        return self.signals["motion.v_m_s"]

    @property
    def p_gauge_Pa(self) -> np.ndarray:
        """The muscle's gauge pressure [Pa]."""
        return self.signals[self.pressure_output]

    @property
    def force_N(self) -> np.ndarray:
        """The force the muscle pulls with [N] (static, damping, friction or hysteresis; positive: tension)."""
        return self.signals["motion.F_N"]

    def columns(self) -> dict[str, np.ndarray]:
        """:data:`LOOP_COLUMNS` (so that the CSV is a loop ``pamsim fit hysteresis`` reads), ``length_m``,
        ``v_m_s``, then every other state and output of the assembly by its name."""
        cols = {"t_s": self.t_s, "p_gauge_Pa": self.p_gauge_Pa, "x_m": self.contraction_m, "force_N": self.force_N,
                "length_m": self.length_m, "v_m_s": self.velocity_m_s}
        taken = {"motion.x_m", "motion.v_m_s", "motion.F_N", self.pressure_output}
        cols.update({k: np.asarray(v, dtype=float) + 0.0 * self.t_s for k, v in self.signals.items() if k not in taken})
        return cols

    def to_csv(self, path) -> None:
        """Write :meth:`columns`, one row per sample. Atomic."""
        write_columns(path, self.columns())

    def dissipated_J(self) -> float:
        """The work done on the muscle by what moves it over the run [J], ``-integral F dx``
        (``-motion.W_muscle_out_J`` at the end): over closed cycles, the loops' area."""
        return -float(self.signals["motion.W_muscle_out_J"][-1])

    def summary(self) -> dict:
        """The run in numbers: the motion, the force's range, the work done on the muscle, the events and the
        solver's statistics."""
        x, F = self.contraction_m, self.force_N
        return {"name": self.name, "backend": self.backend, "motion": self.motion.kind,
                "knots": len(self.motion.t_s), "contraction_range_m": [float(x.min()), float(x.max())],
                "force_range_N": [float(F.min()), float(F.max())], "final_force_N": float(F[-1]),
                "work_on_muscle_J": self.dissipated_J(),
                "events": [{"t_s": t, "kind": kind} for t, kind in self.events],
                "stats": {**self.stats, "wall_time_s": self.wall_time_s}}
