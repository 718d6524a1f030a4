"""Does a dynamic fit reach the noise of its traces?  A fit that ends far above it, or with one trace
followed far worse than another, stopped in a local minimum or has a model that cannot follow the
data; either way its coefficients are not what the data show, and the fit says so.

The noise is estimated from each trace alone, without the model: the second differences of the
contraction, ``x[i+1] - 2 x[i] + x[i-1]``, hold the motion's acceleration times the squared sample
interval (micrometres at 1 kHz) and six times the noise variance; their median absolute deviation is
robust to the few samples where the load starts or stops.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

NOISE_FACTOR = 2.0
"""A trace (or the pool) whose RMS residual exceeds twice its noise level is flagged: at the optimum of a
model that can follow the data the ratio is 1 within a few per cent."""
SPREAD_FACTOR = 2.0
"""Flagged when one trace's RMS over its noise exceeds another's by more than this factor."""
_MAD_TO_SD = 1.482602218505602
"""Standard deviation of a normal distribution over its median absolute deviation."""


def noise_level_mm(x_m: np.ndarray) -> float:
    """The contraction noise [mm] (standard deviation) of one trace, from its second differences.

    Where the sensor's resolution is coarser than its noise most second differences are 0 and the
    median says nothing; their standard deviation (an upper estimate, the motion included) is used then.
    """
    d2 = np.diff(np.asarray(x_m, dtype=float), 2) * 1e3
    if d2.size == 0:
        return math.nan
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    spread = _MAD_TO_SD * mad if mad > 0 else float(np.std(d2))
    return spread / math.sqrt(6.0)


def quality_warnings(names: Sequence[str], rms_mm: Sequence[float], noise_mm: Sequence[float],
                     pooled_rms_mm: float) -> list[str]:
    """One line for each way the fit misses the noise: the pool's RMS above :data:`NOISE_FACTOR` times its
    noise, and the traces' RMS over noise ratios differing by more than :data:`SPREAD_FACTOR`."""
    rms, noise = np.asarray(rms_mm, dtype=float), np.asarray(noise_mm, dtype=float)
    if not np.all(noise > 0):
        return []
    ratio = rms / noise
    pooled_noise = float(np.sqrt(np.mean(noise ** 2)))
    out = []
    if pooled_rms_mm > NOISE_FACTOR * pooled_noise:
        worst = int(np.argmax(ratio))
        out.append(f"the pooled RMS {pooled_rms_mm:.4g} mm is {pooled_rms_mm / pooled_noise:.1f} times the traces' "
                   f"noise {pooled_noise:.3g} mm (worst: {names[worst]}, {rms[worst]:.4g} mm): a local minimum "
                   "or a model that cannot follow the data; try more --starts or --global")
    if len(ratio) > 1 and ratio.max() > SPREAD_FACTOR * ratio.min():
        hi, lo = int(np.argmax(ratio)), int(np.argmin(ratio))
        out.append(f"the traces are followed unevenly: {names[hi]} {rms[hi]:.4g} mm ({ratio[hi]:.1f} x its noise) "
                   f"against {names[lo]} {rms[lo]:.4g} mm ({ratio[lo]:.1f} x)")
    return out
