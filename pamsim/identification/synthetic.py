"""Synthetic measurements made by pamsim itself, for recovery studies: a scenario run with chosen
"true" coefficients, the pressure recorded, seeded Gaussian noise on the contraction."""

from __future__ import annotations

from typing import Mapping

import numpy as np

from ..backends import simulate
from ..scenario import Scenario
from .columns import TraceData


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
    noise = np.random.default_rng(seed).normal(0.0, noise_m, res.x_m.shape)
    label = f"synthetic {weight_N:g} N"
    clean = TraceData(res.t_s, res.x_m, res.p_gauge_Pa, weight_N, label)
    return TraceData(res.t_s, res.x_m + noise, res.p_gauge_Pa, weight_N, label), clean
