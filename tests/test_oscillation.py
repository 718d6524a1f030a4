"""The zig-zag filter of the oscillation estimator visits only candidate samples; a second,
sample-by-sample implementation (the filter as first written) must find the same turning points."""

import numpy as np
import pytest

from pamsim.oscillation import _turning_indices


def reference_turning_indices(y: np.ndarray, hysteresis: float) -> list[int]:
    """The zig-zag filter visiting every sample."""
    found, direction, extreme, n = [], 0, 0, y.size
    for i in range(1, n):
        if direction == 0:
            if abs(y[i] - y[0]) > hysteresis:
                direction = 1 if y[i] > y[0] else -1
                extreme = i
        elif direction * (y[i] - y[extreme]) > 0.0:
            extreme = i
        elif direction * (y[extreme] - y[i]) > hysteresis:
            found.append(extreme)
            direction = -direction
            extreme = i
    if direction != 0 and extreme <= n - 3:
        found.append(extreme)
    return found


def _traces(seed: int):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    walk = np.cumsum(rng.normal(size=n))
    yield walk
    # Plateaus (a stuck load) and repeated values inside runs.
    yield np.round(walk)
    yield np.repeat(walk[: max(n // 4, 1)], 4)
    t = np.linspace(0.0, 2.0, n)
    yield np.exp(-t) * np.cos(2 * np.pi * 5 * t) + 0.01 * rng.normal(size=n)
    yield np.where(t > 1.0, 0.3, np.sin(2 * np.pi * 3 * t))


@pytest.mark.parametrize("seed", range(40))
def test_candidate_filter_equals_sample_by_sample_filter(seed):
    for y in _traces(seed):
        for hysteresis in (0.0, 0.05, 0.5, 2.0):
            assert _turning_indices(y, hysteresis) == reference_turning_indices(y, hysteresis)


def test_short_and_constant_traces():
    for y in (np.array([]), np.array([1.0]), np.array([1.0, 2.0]), np.full(10, 3.0), np.array([0.0, 1.0, 0.0])):
        assert _turning_indices(y, 0.1) == reference_turning_indices(y, 0.1)
