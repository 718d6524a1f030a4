"""Does a dynamic fit reach the noise of its traces?  A fit that ends far above it, or with one trace
followed far worse than another, stopped in a local minimum or has a model that cannot follow the
data; either way its coefficients are not what the data show, and the fit says so.

The noise is estimated from each trace alone, without the model: the second differences of the
contraction, ``x[i+1] - 2 x[i] + x[i-1]``, hold the motion's acceleration times the squared sample
interval (micrometres at 1 kHz) and six times the noise variance; their standard deviation, without
the few beyond five times their median absolute deviation (where the load starts, stops or hits a stop),
gives it.  The estimate assumes noise independent from sample to sample: a filtered sensor's second
differences understate its noise, and the flag then also marks fits that reach it.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

NOISE_FACTOR = 1.08
"""A fit whose pooled RMS residual exceeds 1.08 times the traces' pooled noise is flagged.  Measured
(``python benchmarks/bench_multistart.py``, fits started at the truth, 20 noise seeds, three 2.5 s traces):
the ratio is 1.003 with a standard deviation of 0.007 (largest 1.017), so 1.08 is 11 standard deviations
above it (7 for a single trace, 0.0105), while a fit at 1.1 times the RMS at the truth has a ratio of
1.1 x (1.003 +- 0.007), at least 1.08 down to 3 standard deviations below."""
SPREAD_FACTOR = 1.2
"""Flagged when one trace's RMS over its noise exceeds another's by more than this factor.  At the truth
(same measurement) the largest over the smallest of three traces' ratios is 1.023 with a standard
deviation of 0.011 (largest 1.042): 1.2 is 16 standard deviations above."""
TRIM_SDS = 5.0
"""Second differences farther than this many standard deviations from their median are left out of the
noise estimate (a normal sample loses 6e-7 of its values, and of its variance a bias below 1e-5)."""
_MAD_TO_SD = 1.482602218505602
"""Standard deviation of a normal distribution over its median absolute deviation."""


def noise_level_mm(x_m: np.ndarray) -> float:
    """The contraction noise [mm] (standard deviation) of one trace, from its second differences.

    The second differences of independent noise of standard deviation ``s`` have the standard deviation
    ``sqrt(6) s``.  Their median absolute deviation gives a first, robust estimate; the standard deviation
    of those within :data:`TRIM_SDS` of it the final one, about twice as precise (a normal sample's
    median absolute deviation has 37 % of its standard deviation's efficiency) and still blind to the
    few samples where the load starts, stops or hits a stop.  Where the sensor's resolution is coarser
    than its noise most second differences are 0 and the median says nothing; their standard deviation
    (an upper estimate, the motion included) is the first estimate then.
    """
    d2 = np.diff(np.asarray(x_m, dtype=float), 2) * 1e3
    if d2.size == 0:
        return math.nan
    centre = float(np.median(d2))
    mad = float(np.median(np.abs(d2 - centre)))
    spread = _MAD_TO_SD * mad if mad > 0 else float(np.std(d2))
    for _ in range(2):
        kept = d2[np.abs(d2 - centre) <= TRIM_SDS * spread]
        spread = float(np.std(kept)) if kept.size > 1 else spread
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
        out.append(f"the pooled RMS {pooled_rms_mm:.4g} mm is {pooled_rms_mm / pooled_noise:.2f} times the traces' "
                   f"noise {pooled_noise:.3g} mm (worst: {names[worst]}, {rms[worst]:.4g} mm): a local minimum "
                   "or a model that cannot follow the data; try more --starts or --global")
    if len(ratio) > 1 and ratio.max() > SPREAD_FACTOR * ratio.min():
        hi, lo = int(np.argmax(ratio)), int(np.argmin(ratio))
        out.append(f"the traces are followed unevenly: {names[hi]} {rms[hi]:.4g} mm ({ratio[hi]:.1f} x its noise) "
                   f"against {names[lo]} {rms[lo]:.4g} mm ({ratio[lo]:.1f} x)")
    return out
