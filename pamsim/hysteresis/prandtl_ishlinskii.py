"""Generalized Prandtl-Ishlinskii: weighted play operators of an input passed through a monotone envelope,
with its analytic inverse (docs/hysteresis.md).

``y = y0 + sum_j w_j P_rj[g(u)]``, ``P_r`` the play of half-width ``r`` (:mod:`.play`), thresholds
``0 <= r_0 < r_1 < ...`` and the envelope ``g(u) = s tanh(u / s)`` of scale ``s`` (``s = inf``: ``g(u) = u``,
the classical operator).  A play of an envelope, ``P_r[g(u)]``, is the generalized play with equal rising and
falling envelopes of Al Janaideh, Rakheja and Su, here with a tanh envelope (docs/hysteresis.md gives the
sources and what was checked).  The inverse of the
classical part is again a Prandtl-Ishlinskii operator whose thresholds and weights follow in closed form
(Kuhnen's inverse): with the slopes ``W_j = w_0 + ... + w_j``::

    r'_j = sum_{i<=j} w_i (r_j - r_i),   w'_0 = 1 / w_0,   w'_j = -w_j / (W_j W_{j-1}),

and the inverse's play states ``q_j = W_j p_j + sum_{i>j} w_i p_i`` from the operator's states ``p``, so
``u = g^-1(P'[y - y0])`` reproduces the input exactly from any state the operator can reach.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import checks
from .play import play


@dataclass(frozen=True)
class PIRun:
    """The response of a Prandtl-Ishlinskii operator (or of its inverse) to one input signal."""

    output: np.ndarray
    """The output at each sample."""
    states: np.ndarray
    """``(samples, plays)``: each play's state; the last row restarts a run."""


@dataclass(frozen=True)
class PrandtlIshlinskii:
    """A generalized Prandtl-Ishlinskii operator.

    Input and output carry whatever units the caller uses (``pamsim fit hysteresis``: contraction [m] in,
    force [N] out); thresholds and the envelope scale are in the input's unit, weights in output per input.

    Parameters
    ----------
    thresholds : array_like
        ``r_j``: strictly increasing, the first at least 0 (1 to 100 plays).
    weights : array_like
        ``w_j``, one per threshold.
    offset : float
        ``y0``, added to the output.
    envelope_scale : float
        ``s`` of the envelope ``s tanh(u / s)``, above 0; ``inf`` (default) for the classical operator.
    """

    thresholds: np.ndarray
    weights: np.ndarray
    offset: float = 0.0
    envelope_scale: float = math.inf

    def __post_init__(self):
        r = checks.vector("thresholds", self.thresholds, 0.0)
        bad = np.flatnonzero(np.diff(r) <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise checks.InputError(f"thresholds[{i}] = {float(r[i])!r}: thresholds must increase strictly "
                                    f"(thresholds[{i - 1}] = {float(r[i - 1])!r})")
        w = checks.vector("weights", self.weights)
        if w.size != r.size:
            raise checks.InputError(f"weights: {w.size} values for {r.size} thresholds (one per play)")
        object.__setattr__(self, "thresholds", r)
        object.__setattr__(self, "weights", w)
        object.__setattr__(self, "offset", checks.number("offset", self.offset))
        object.__setattr__(self, "envelope_scale", checks.number("envelope_scale", self.envelope_scale, 0.0,
                                                                 strict=True, infinite=True))

    def envelope(self, u) -> np.ndarray:
        """``g(u) = s tanh(u / s)`` (``u`` itself for ``s = inf``)."""
        s = self.envelope_scale
        return np.asarray(u, dtype=float) if math.isinf(s) else s * np.tanh(np.asarray(u, dtype=float) / s)

    def envelope_inverse(self, v) -> np.ndarray:
        """``g^-1(v) = s artanh(v / s)``; ``|v|`` must stay below ``s`` (the envelope's range)."""
        v = np.asarray(v, dtype=float)
        s = self.envelope_scale
        if math.isinf(s):
            return v
        if np.any(np.abs(v) >= s):
            worst = float(v[np.argmax(np.abs(v))])
            raise checks.InputError(f"envelope_scale = {s!r}: the inverse asks for g(u) = {worst!r}, outside the "
                                    "envelope's range (-s, s): the output is beyond what the operator reaches")
        return s * np.arctanh(v / s)

    def run(self, u, states0=None) -> PIRun:
        """The output for the input ``u`` (linear between samples; with an envelope, ``g(u)`` is), from the
        play states ``states0`` (default 0; a run's ``states[-1]`` continues it)."""
        p = play(self.envelope(u), self.thresholds, states0)
        return PIRun(self.offset + p @ self.weights, p)

    def slopes(self) -> np.ndarray:
        """``W_j = w_0 + ... + w_j``: the slope of the output against ``g(u)`` once plays ``0..j`` move."""
        return np.cumsum(self.weights)

    def check_invertible(self) -> int:
        """The sign (+1 increasing, -1 decreasing) of an invertible operator; raise :class:`InputError`
        unless ``r_0 = 0`` and every slope ``W_j`` is nonzero with one sign (the operator is then strictly
        monotone on every branch)."""
        if self.thresholds[0] != 0.0:
            raise checks.InputError(f"thresholds[0] = {float(self.thresholds[0])!r}: the inverse needs r_0 = 0 (a play "
                                    "that follows the input at once, or the output stalls at each reversal)")
        W = self.slopes()
        sign = 1 if W[0] > 0 else -1
        bad = np.flatnonzero(~(sign * W > 0))
        if bad.size:
            j = int(bad[0])
            raise checks.InputError(f"weights[{j}] = {float(self.weights[j])!r}: the slope w_0 + ... + w_{j} = "
                                    f"{float(W[j])!r} "
                                    "must have the sign of w_0 and not be 0 for the operator to be invertible")
        return sign

    def inverse(self) -> "InversePI":
        """The analytic inverse (see the module's docstring); :meth:`check_invertible` must pass."""
        sign = self.check_invertible()
        w = sign * self.weights
        W = np.cumsum(w)
        r = self.thresholds
        r_inv = W * r - np.cumsum(w * r)
        w_inv = np.empty_like(w)
        w_inv[0] = 1.0 / w[0]
        w_inv[1:] = -w[1:] / (W[1:] * W[:-1])
        return InversePI(self, PrandtlIshlinskii(r_inv, w_inv), sign)

    def inverse_states(self, states) -> np.ndarray:
        """The inverse's play states ``q_j = W_j p_j + sum_{i>j} w_i p_i`` for this operator's states ``p``
        (weights taken with the sign that makes the operator increasing)."""
        sign = self.check_invertible()
        w = sign * self.weights
        p = np.asarray(states, dtype=float)
        tail = np.cumsum((w * p)[..., ::-1], axis=-1)[..., ::-1]  # sum_{i>=j} w_i p_i
        return np.cumsum(w) * p + tail - w * p


@dataclass(frozen=True)
class InversePI:
    """The inverse of a :class:`PrandtlIshlinskii` operator: the input that gives a wanted output."""

    forward: PrandtlIshlinskii
    core: PrandtlIshlinskii
    """The classical operator from ``sign * (y - y0)`` to ``g(u)``."""
    sign: int
    """+1 for an increasing operator, -1 for a decreasing one (whose negation is inverted)."""

    def run(self, y, states0=None) -> PIRun:
        """The input ``u`` at each sample for the wanted output ``y``, from the inverse's play states
        ``states0`` (default 0; :meth:`PrandtlIshlinskii.inverse_states` gives them for a forward state)."""
        inner = self.core.run(self.sign * (np.asarray(y, dtype=float) - self.forward.offset), states0)
        return PIRun(self.forward.envelope_inverse(inner.output), inner.states)

    def forward_states(self, states) -> np.ndarray:
        """The forward operator's play states for the inverse's ``states``: the same map, from the inverse's
        side (the inverse of the inverse is the operator)."""
        return self.core.inverse_states(states)
