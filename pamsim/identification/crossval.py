"""Cross-validation of a fit: refit without some tests, predict the tests left out."""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import InputError
from .choices import CV_CHOICES

LOO_MAX_POINTS = 100
"""``auto`` uses leave-one-out up to this many tests, k-fold above (each refit costs a fit)."""


def folds(n: int, kind: str, k: int, seed: int) -> tuple[str, list[np.ndarray]]:
    """The label (``leave-one-out`` or ``k-fold (k=K)``) and the held-out index sets."""
    if kind == "auto":
        kind = "loo" if n <= LOO_MAX_POINTS else "kfold"
    if kind == "loo":
        return "leave-one-out", [np.array([i]) for i in range(n)]
    if kind == "kfold":
        if not 2 <= k <= n:
            raise InputError(f"--folds = {k}: need 2 <= k <= {n} (the number of tests)")
        order = np.random.default_rng(seed).permutation(n)
        return f"{k}-fold", [np.sort(part) for part in np.array_split(order, k)]
    raise InputError(f"--cv = {kind!r}: choose from {', '.join(CV_CHOICES)}")


def cross_validate(fit: Callable[[np.ndarray], np.ndarray], errors: Callable[[np.ndarray, np.ndarray], np.ndarray],
                   n: int, n_free: int, kind: str | None, k: int = 10, seed: int = 0) -> tuple[str, np.ndarray]:
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

    Returns
    -------
    (str, ndarray)
        The kind actually used (``"none"`` when skipped, with the reason) and the errors in test order
        (empty when skipped).
    """
    if kind in (None, "none"):
        return "none", np.empty(0)
    label, parts = folds(n, kind, k, seed)
    if n - max(len(p) for p in parts) < n_free:
        return f"none (a training set of {n - max(len(p) for p in parts)} tests cannot fix {n_free} coefficients)", \
            np.empty(0)
    out = np.empty(n)
    everything = np.arange(n)
    for test in parts:
        train = np.setdiff1d(everything, test)
        out[test] = errors(fit(train), test)
    return label, out
