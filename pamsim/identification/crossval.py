"""Cross-validation of a fit: refit without some tests, predict the tests left out."""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import InputError
from .choices import CV_CHOICES

LOO_MAX_POINTS = 100
"""``auto`` uses leave-one-out up to this many tests, k-fold above (each refit costs a fit)."""


def folds(n: int, kind: str, k: int, seed: int, groups: np.ndarray | None = None) -> tuple[str, list[np.ndarray]]:
    """The label (``leave-one-out`` or ``k-fold (k=K)``) and the held-out index sets.

    Tests with the same label in ``groups`` (repeated tests) are held out together: a copy left in
    the training set would predict its twin, and the error would look smaller than it is.
    """
    groups = np.arange(n) if groups is None else np.asarray(groups)
    labels, members = np.unique(groups, return_inverse=True)
    m = labels.size
    if kind == "auto":
        kind = "loo" if m <= LOO_MAX_POINTS else "kfold"
    if kind == "loo":
        return "leave-one-out", [np.flatnonzero(members == g) for g in range(m)]
    if kind == "kfold":
        if not 2 <= k <= m:
            raise InputError(f"--folds = {k}: need 2 <= k <= {m} (the number of distinct tests)")
        order = np.random.default_rng(seed).permutation(m)
        return f"{k}-fold", [np.flatnonzero(np.isin(members, part)) for part in np.array_split(order, k)]
    raise InputError(f"--cv = {kind!r}: choose from {', '.join(CV_CHOICES)}")


def cross_validate(fit: Callable[[np.ndarray], np.ndarray], errors: Callable[[np.ndarray, np.ndarray], np.ndarray],
                   n: int, n_free: int, kind: str | None, k: int = 10, seed: int = 0,
                   groups: np.ndarray | None = None) -> tuple[str, np.ndarray]:
    """Prediction error of every test from a fit that did not see it.

    Parameters
    ----------
    fit : callable
        ``fit(train_indices) -> theta``.
    errors : callable
        ``errors(theta, test_indices) -> array`` of prediction errors of those tests.
    n, n_free : int
        Number of tests and of free coefficients.  A training set smaller than ``n_free`` cannot
        determine the coefficients: then no cross-validation is done.
    kind : {"auto", "loo", "kfold", "none", None}
    groups : array, optional
        A label per test; tests sharing one are always in the same fold (see :func:`folds`).

    Returns
    -------
    (str, ndarray)
        The kind actually used (``"none"`` when skipped, with the reason) and the errors in test order
        (empty when skipped).
    """
    if kind in (None, "none"):
        return "none", np.empty(0)
    label, parts = folds(n, kind, k, seed, groups)
    if n - max(len(p) for p in parts) < n_free:
        return f"none (a training set of {n - max(len(p) for p in parts)} tests cannot fix {n_free} coefficients)", \
            np.empty(0)
    out = np.empty(n)
    everything = np.arange(n)
    for test in parts:
        train = np.setdiff1d(everything, test)
        out[test] = errors(fit(train), test)
    return label, out
