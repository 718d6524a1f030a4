"""Synthetic measurements made by pamsim itself, for recovery and coverage studies: a scenario run with
chosen "true" coefficients, the pressure recorded, seeded Gaussian noise on the contraction; static
tests of a static force model under hung weights."""

from __future__ import annotations

from typing import Mapping

import numpy as np

from ..backends import simulate
from ..scenario import Scenario
from .columns import StaticData, TraceData
from .equilibrium import equilibrium_m


def synthetic_trace(scenario: Scenario, truth: Mapping[str, float], weight_N: float, noise_m: float = 0.05e-3,
                    seed: int = 0, duration_s: float | None = None) -> tuple[TraceData, TraceData]:
    """Simulate ``scenario`` with the coefficients ``truth`` under ``weight_N`` and record it.

    Returns ``(noisy, clean)``: the same trace with and without ``noise_m`` [m] of Gaussian noise
    (standard deviation) on the contraction, drawn from ``numpy.random.default_rng(seed)``.  The
    pressure is recorded without noise.
    """
    changes = {"parameters": dict(truth), "load": {"weight_N": weight_N}}
    if duration_s is not None:
        changes["simulation"] = {"duration_s": duration_s}
    res = simulate(scenario.with_changes(changes))
    clean = TraceData(res.t_s, res.x_m, res.p_gauge_Pa, weight_N, f"synthetic {weight_N:g} N")
    return with_noise(clean, noise_m, seed), clean


def with_noise(clean: TraceData, noise_m: float, seed: int) -> TraceData:
    """``clean`` with seeded Gaussian noise of standard deviation ``noise_m`` [m] on the contraction, drawn
    from ``numpy.random.default_rng(seed)`` (the noise of :func:`synthetic_trace`)."""
    noise = np.random.default_rng(seed).normal(0.0, noise_m, clean.x_m.shape)
    return TraceData(clean.t_s, clean.x_m + noise, clean.p_gauge_Pa, clean.weight_N, clean.origin)


def synthetic_static(force_N, p_gauge_Pa: np.ndarray, load_N: np.ndarray, x_max_m: float, noise_m: float,
                     seed: int = 0, origin: str = "synthetic static tests") -> StaticData:
    """Hanging-weight static tests of the model ``force_N(x_m, p_gauge_Pa)``: each test's equilibrium
    contraction plus seeded Gaussian noise of ``noise_m`` [m] where the load is lifted, and 0 where
    it is not (the muscle rests on its lower stop, which a rig reads without noise)."""
    x = equilibrium_m(force_N, p_gauge_Pa, load_N, x_max_m)
    noisy = x + np.random.default_rng(seed).normal(0.0, noise_m, x.shape)
    return StaticData(np.asarray(p_gauge_Pa, float), np.where(x > 0.0, noisy, 0.0), np.asarray(load_N, float),
                      "weight", origin)
