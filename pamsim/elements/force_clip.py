"""A muscle cannot push: the dynamics clip a negative static force at zero.

A library model's raw force ``force_N(x_m, p_gauge_Pa)`` may be negative (below
the pressure that overcomes the bladder's stiffness, or beyond the contraction
where the braid's pull vanishes).  A braided sleeve transmits tension only, so
the simulator applies ``max(F, 0)`` by default; ``[model] static_force_negative
= "keep"`` applies the raw value instead (a pamsim choice, docs/model.md).
"""

from __future__ import annotations

from dataclasses import dataclass

NEGATIVE_FORCE_CHOICES = ("clip", "keep")
"""``static_force_negative`` choices: ``clip`` (default) sets a negative force to zero, ``keep`` applies it."""


class WrappedStaticForce:
    """Base of a static model wrapped for the dynamics: ``name`` and ``domain`` are those of ``inner``."""

    inner: object

    @property
    def name(self) -> str:
        """The wrapped model's name."""
        return self.inner.name

    @property
    def domain(self):
        """The wrapped model's domain."""
        return self.inner.domain


@dataclass(frozen=True)
class ClippedStaticForce(WrappedStaticForce):
    """``max(inner.force_N(x, p), 0)``, for floats and numpy arrays alike."""

    inner: object

    def force_N(self, x_m, p_gauge_Pa):
        """Pulling force [N] at contraction ``x_m`` [m] and gauge pressure [Pa], never negative."""
        f = self.inner.force_N(x_m, p_gauge_Pa)
        return 0.5 * (f + abs(f))  # max(f, 0) without a numpy call on floats


def with_negative_force(model, choice: str):
    """``model`` as the dynamics apply it: clipped at zero (``"clip"``) or raw (``"keep"``)."""
    if choice not in NEGATIVE_FORCE_CHOICES:
        raise ValueError(f"static_force_negative must be one of {NEGATIVE_FORCE_CHOICES}, not {choice!r}")
    return ClippedStaticForce(model) if choice == "clip" else model
