"""Tracking a moving reference with the position controller: the reference's trajectory and its feedforward.

The controller of :mod:`pamsim.control.closed_loop` is a state feedback around a reference state. For a
step the reference state is the target at rest, held by its static holding pressure. For a moving
reference ``r(t)`` the reference state is the whole trajectory that makes the model follow ``r`` exactly
(its inverse dynamics, docs/control.md "Tracking"):

- velocity ``r'``;
- the pressure ``p_ff`` at which the muscle's static force carries the load along ``r``:
  ``F_static(r, p_ff) = W + m r'' + F_damp(r') + F_extra``, with ``F_extra`` an extra force along the path
  (a hysteresis compensator's estimate of the muscle's friction, or none);
- the valve command ``u_ff`` at which the chamber's pressure rate at ``(p_ff, r, r')`` is ``p_ff'``, solved
  on the plant's own chamber and valve equations; it is clipped to the valve's range where the valve
  cannot keep up.

The controller then drives the deviations from that state: ``u = u_ff - K [x - r, v - r', p - p_ff, z]``.
The trajectory is sampled on a fine grid and handed to the run as piecewise-linear signals, which every
backend follows exactly.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from ..errors import InputError
from ..model import MuscleModel
from ..signals import Trace
from .operating_point import holding_pressure_Pa

SAMPLE_INTERVAL_S = 1e-3
"""Grid of the feedforward signals [s]: at 1 Hz a sine's chord error is (2 pi f dt)^2 / 8 = 5e-6 of its
amplitude, and the feedforward's pressure rate is taken by central differences on it."""


@dataclass(frozen=True)
class SineReference:
    """``r(t) = center + amplitude sin(2 pi f (t - start))`` from ``start_s`` on, ``center`` before it."""

    center_m: float
    amplitude_m: float
    frequency_Hz: float
    start_s: float

    def sample(self, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position [m], velocity [m/s] and acceleration [m/s^2] of the reference at ``t_s``."""
        w = 2.0 * math.pi * self.frequency_Hz
        phase = w * np.maximum(t_s - self.start_s, 0.0)
        on = t_s >= self.start_s
        a = self.amplitude_m
        return (self.center_m + a * np.sin(phase), np.where(on, a * w * np.cos(phase), 0.0),
                np.where(on, -a * w * w * np.sin(phase), 0.0))


@dataclass(frozen=True)
class TrackingSignals:
    """The reference trajectory and its feedforward on a grid: the controller's four moving inputs."""

    t_s: np.ndarray
    reference_m: np.ndarray
    reference_velocity_m_s: np.ndarray
    feedforward_gauge_Pa: np.ndarray
    feedforward_command: np.ndarray
    extra_force_N: np.ndarray
    """The extra force the feedforward carries along the path (a compensator's hysteresis estimate)."""

    def apply(self, model: MuscleModel) -> MuscleModel:
        """``model`` (its source a :class:`~pamsim.control.closed_loop.ClosedLoopValveSource`) with these
        signals as its controller's inputs."""
        t = self.t_s
        source = dataclasses.replace(model.source, reference_m=Trace(t, self.reference_m, "reference"),
                                     reference_velocity_m_s=Trace(t, self.reference_velocity_m_s, "reference"),
                                     feedforward_gauge_Pa=Trace(t, self.feedforward_gauge_Pa, "feedforward"),
                                     feedforward_command=Trace(t, self.feedforward_command, "feedforward"))
        return dataclasses.replace(model, source=source)


FEEDFORWARDS = ("inverse_dynamics", "static")
"""``inverse_dynamics``: the module's reference state; ``static``: the holding pressure of the static model along
the path alone, with no velocity reference and no command (a step's feedforward, applied at every instant)."""


def tracking_signals(model: MuscleModel, reference: SineReference, duration_s: float, supply_gauge_Pa: float,
                     extra_force: Callable[[np.ndarray], np.ndarray] | None = None,
                     feedforward: str = "inverse_dynamics") -> TrackingSignals:
    """The feedforward of ``model`` (its source the closed loop's) along ``reference``.

    Parameters
    ----------
    model : MuscleModel
        The closed loop's model: its load, damping, static force and its source's plant (valve and chamber).
    reference : SineReference
    duration_s : float
        Length of the signals [s].
    supply_gauge_Pa : float
        The valve's supply pressure [Pa] (the holding pressures must stay below it).
    extra_force : callable, optional
        ``F(r) -> N`` along the sampled path, zero at its first sample: an extra force the muscle must
        overcome (positive: more pull). The compensator's hysteresis estimate.
    feedforward : {"inverse_dynamics", "static"}
        See :data:`FEEDFORWARDS`.

    Raises
    ------
    InputError
        Where the path needs more pull than the supply gives, or a vacuum.
    """
    if feedforward not in FEEDFORWARDS:
        raise InputError(f"feedforward = {feedforward!r}: choose from {', '.join(FEEDFORWARDS)}")
    t = np.arange(0.0, duration_s + 0.5 * SAMPLE_INTERVAL_S, SAMPLE_INTERVAL_S)
    r, v, a = reference.sample(t)
    extra = np.zeros_like(t) if extra_force is None else np.asarray(extra_force(r), dtype=float)
    if feedforward == "static":
        p_ff = _holding_pressures(model, r, model.load.weight_N + extra, supply_gauge_Pa)
        return TrackingSignals(t, r, np.zeros_like(t), p_ff, np.zeros_like(t), extra)
    load = model.load.weight_N + model.load.mass_kg * a + np.asarray(model.damping.force_N(v), dtype=float) + extra
    p_ff = _holding_pressures(model, r, load, supply_gauge_Pa)
    dp = np.gradient(p_ff, t)
    plant = model.source.plant
    u_ff = np.array([_command_for_rate(plant, p, d, x, vv, supply_gauge_Pa)
                     for p, d, x, vv in zip(p_ff, dp, r, v)])
    return TrackingSignals(t, r, v, p_ff, u_ff, extra)


def _holding_pressures(model: MuscleModel, r: np.ndarray, load_N: np.ndarray, supply_gauge_Pa: float) -> np.ndarray:
    """Gauge pressure [Pa] carrying ``load_N`` at each ``r``; the first failure named by its time sample."""
    out = np.empty_like(r)
    for k, (x, F) in enumerate(zip(r, load_N)):
        try:
            out[k] = holding_pressure_Pa(model, float(x), float(F), supply_gauge_Pa)
        except InputError as exc:
            raise InputError(f"the tracking reference at sample {k} ({k * SAMPLE_INTERVAL_S:g} s): {exc}") from None
    return out


def _command_for_rate(plant, p_gauge_Pa: float, dp_Pa_s: float, x_m: float, v_m_s: float,
                      supply_gauge_Pa: float) -> float:
    """The valve command in [-1, 1] at which the chamber, at ``p_gauge_Pa`` and the reference's ``x_m``,
    ``v_m_s``, has the pressure rate ``dp_Pa_s``; the nearer end of the range where no command gives it."""
    s = plant.initial_state(x_m, p_gauge_Pa)

    def excess(u):
        return plant.derivatives(s, x_m, v_m_s, (u, supply_gauge_Pa))[0] - dp_Pa_s

    low, high = excess(-1.0), excess(1.0)
    if low >= 0.0:
        return -1.0
    if high <= 0.0:
        return 1.0
    return float(brentq(excess, -1.0, 1.0, xtol=1e-12))


def tracking_rms_m(t_s: np.ndarray, x_m: np.ndarray, signals: TrackingSignals, from_s: float) -> float:
    """Root mean square [m] of the tracking error ``x - r`` over the samples from ``from_s`` on."""
    tail = t_s >= from_s
    error = x_m[tail] - np.interp(t_s[tail], signals.t_s, signals.reference_m)
    return float(np.sqrt(np.mean(error ** 2)))
