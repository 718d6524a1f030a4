"""Input paths of the hysteresis tests (``test_hysteresis_*.py``): one piecewise-linear path sampled at
different densities, as the same input at other rates would be."""

from __future__ import annotations

import numpy as np


def resample(vertices, per_segment, rng=None):
    """The piecewise-linear path through ``vertices`` with ``per_segment`` points inside each piece (evenly
    spaced, or at random positions drawn from ``rng``), the vertices kept; returns the samples and the
    vertices' indices among them."""
    xs, idx = [np.array([vertices[0]])], [0]
    for a, b in zip(vertices[:-1], vertices[1:]):
        s = np.sort(rng.uniform(0, 1, per_segment)) if rng is not None else np.linspace(0, 1, per_segment + 2)[1:-1]
        xs.append(np.concatenate([a + (b - a) * s, [b]]))
        idx.append(idx[-1] + per_segment + 1)
    return np.concatenate(xs), np.array(idx)
