"""Maxwell-slip: N elasto-slide elements in parallel driven by one displacement (docs/hysteresis.md).

Element i is a spring of stiffness ``k_i`` [N/m] holding a block that slides when the spring's force reaches
its slip force ``F_i`` [N]: its deflection ``d_i`` stays within ``+-F_i / k_i`` and the output force is
``sum k_i d_i`` (Al-Bender, Lampaert and Swevers 2004, the generalized Maxwell-slip model, here with constant
slip forces as in its rate-independent form).  The block's position ``x - d_i`` is a play operator of
half-width ``F_i / k_i`` and its deflection the stop operator ``x - play`` (:mod:`.play`), so the update is exact for an input linear between its samples and
the model is rate independent by construction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import checks
from .play import stop



@dataclass(frozen=True)
class MaxwellSlipRun:
    """The response of a :class:`MaxwellSlip` model to one input signal."""

    force_N: np.ndarray
    """Output force at each sample: the sum of the element forces."""
    deflection_m: np.ndarray
    """``(samples, elements)``: each element's spring deflection; the last row restarts a run."""
    sticking: np.ndarray
    """``(samples, elements)``: True where the element's force is below its slip force (the element sticks);
    False where it is at its slip force (it slides, or would on a further move the same way)."""
    slip_m: np.ndarray
    """``(elements,)``: the distance each element's block slid over the run, both ways counted."""
    dissipated_J: float
    """Energy dissipated by sliding over the run: ``sum F_i * slip_m[i]``."""


@dataclass(frozen=True)
class MaxwellSlip:
    """N elasto-slide elements in parallel.

    Parameters
    ----------
    stiffness_N_per_m : array_like
        ``k_i``, each above 0 [N/m].
    slip_force_N : array_like
        ``F_i``, each at least 0 [N]; as many as stiffnesses (1 to 100).
    """

    stiffness_N_per_m: np.ndarray
    slip_force_N: np.ndarray

    def __post_init__(self):
        k = checks.vector("stiffness_N_per_m", self.stiffness_N_per_m, 0.0, strict=True)
        f = checks.vector("slip_force_N", self.slip_force_N, 0.0)
        if k.size != f.size:
            raise checks.InputError(f"slip_force_N: {f.size} values for {k.size} stiffnesses (one per element)")
        object.__setattr__(self, "stiffness_N_per_m", k)
        object.__setattr__(self, "slip_force_N", f)

    @property
    def n_elements(self) -> int:
        """N, the number of elements."""
        return self.stiffness_N_per_m.size

    @property
    def slip_deflection_m(self) -> np.ndarray:
        """``F_i / k_i``: the deflection at which each element slides."""
        return self.slip_force_N / self.stiffness_N_per_m

    def run(self, x_m, deflection0_m=None) -> MaxwellSlipRun:
        """Drive the elements with the displacement ``x_m`` (linear between samples).

        Parameters
        ----------
        x_m : array_like
            Input displacement at each sample [m].
        deflection0_m : array_like, optional
            The elements' deflections at the first sample (default 0: all relaxed), clipped to their slip
            deflections; pass a run's ``deflection_m[-1]`` to continue it.

        Returns
        -------
        MaxwellSlipRun
        """
        x = np.asarray(x_m, dtype=float)
        d0 = np.zeros(self.n_elements) if deflection0_m is None else np.asarray(deflection0_m, dtype=float)
        limit = self.slip_deflection_m
        deflection = stop(x, limit, d0)
        # The block slides by what the input moves beyond the deflection's change.
        slip = np.abs(np.diff(x)[:, None] - np.diff(deflection, axis=0)).sum(axis=0)
        force = deflection * self.stiffness_N_per_m
        sticking = np.abs(deflection) < limit
        return MaxwellSlipRun(force.sum(axis=1), deflection, sticking, slip, float(slip @ self.slip_force_N))
