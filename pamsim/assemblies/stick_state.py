"""Hysteresis components held in one stick state, and the report of it (:class:`LoopPoint`): what a
linearisation differentiates in place of a model whose switches have no derivative.

:mod:`pamsim.control.loop_point` finds the stick state of the rig's operating point;
:func:`pamsim.joints.linear.linearize_joint` holds a joint's muscles' elements relaxed at its equilibrium.
The rules (which element slips, Bouc-Wen's branch) are :mod:`pamsim.control.loop_point`'s notes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..components.bouc_wen_friction import BoucWenFriction
from ..components.elasto_slide import element
from ..components.maxwell_slip_friction import MaxwellSlip

HYSTERESIS = (MaxwellSlip, BoucWenFriction)
"""The components a linearisation holds in a stick state."""

BRANCHES = {1: "loading", -1: "unloading", 0: "at rest"}
"""The branch's name by the sign of the motion."""


@dataclass(frozen=True)
class LoopPoint:
    """Where on its loop the hysteresis was linearised: the branch, how it was found, and per element its
    stick state (Maxwell-slip) or its tangent (Bouc-Wen); ``dropped``: the slipping elements' deflections,
    left out of the linear model."""

    model: str
    branch: str
    branch_from: str
    elements: tuple[dict, ...]
    dropped: tuple[str, ...] = ()

    def as_dict(self) -> dict:
        """JSON-ready: ``{"model", "branch", "branch_from", "elements": [...]}``."""
        return {"model": self.model, "branch": self.branch, "branch_from": self.branch_from,
                "elements": [dict(e) for e in self.elements]}

    def lines(self) -> list[str]:
        """The text the command line prints."""
        out = [f"hysteresis: {self.model}, branch {self.branch} ({self.branch_from})"]
        for e in self.elements:
            out.append("  " + ", ".join(f"{k} {_text(v)}" for k, v in e.items()))
        return out


def _text(value) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def held_maxwell_slip(component: MaxwellSlip, state: dict, sign: int, level: float):
    """``(held model, LoopPoint)``: ``component`` held in each element's stick state at its deflections
    ``state`` (``{"<name>.z<i>_m": value}``) on the branch ``sign`` at the friction level ``level`` [N], and
    the elements' report (its branch left blank for the caller)."""
    branches, elements, dropped = [], [], []
    c = component.values.get("damping_N_s_per_m", 0.0)  # none on a massless end (on_massless_end)
    for i in range(1, component.n_elements + 1):
        delta, share = component.values[f"delta{i}_m"], component.values[f"share{i}"]
        name = f"{component.name}.z{i}_m"
        z = state[name]
        slips = bool(element(z, float(sign), 1.0, delta, 0.0).slipping)
        branches.append(int(math.copysign(1.0, z)) if slips else 0)
        entry = {"name": f"{component.name}.element{i}", "state": "slip" if slips else "stick",
                 "k_N_per_m": share * level / delta, "slip_force_N": share * level, "deflection_m": z,
                 "slip_limit_m": delta}
        if slips:
            entry["force_N"] = -branches[-1] * share * level
            dropped.append(name)
        else:
            entry.update(damping_N_s_per_m=share * c, margin_m=delta - abs(z))
        elements.append(entry)
    return component.held(branches), LoopPoint(component.model_name, "", "", tuple(elements), tuple(dropped))


def held_bouc_wen(component: BoucWenFriction, state: dict, sign: int, level: float):
    """The model on the branch ``sign`` (+1 at rest), and its tangent there: ``dz/dx`` along the branch and
    the force's slope against the contraction at a constant level, ``-F_c / z_u dz/dx``."""
    P = component.values
    s = sign or 1
    z = state[f"{component.name}.z_m"]
    n = P["exponent"]
    z_u = (1.0 / (P["beta_per_m_n"] + P["gamma_per_m_n"])) ** (1.0 / n)
    slope = 1.0 - P["beta_per_m_n"] * s * math.copysign(1.0, z) * abs(z) ** n - P["gamma_per_m_n"] * abs(z) ** n
    entry = {"name": component.name, "z_m": z, "z_saturation_m": z_u, "dz_dx": slope,
             "k_N_per_m": level / z_u * slope, "level_N": level}
    return component.held(s), LoopPoint("bouc_wen", "", "", (entry,))


def held(component, state: dict, sign: int, level: float):
    """``(held model, LoopPoint)`` of a :data:`HYSTERESIS` component: :func:`held_maxwell_slip` or
    :func:`held_bouc_wen`."""
    hold = held_maxwell_slip if isinstance(component, MaxwellSlip) else held_bouc_wen
    return hold(component, state, sign, level)
