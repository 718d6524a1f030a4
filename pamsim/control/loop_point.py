"""The stick state of a scenario's hysteresis (``[hysteresis]``) at an operating point, for linearisation.

A Maxwell-slip element switches between sticking and slipping, and Bouc-Wen's ``|v|`` has a kink at
``v = 0``: neither has a derivative across its switch.  The linearisation takes the model within one stick
state, the one the operating point is in, and says which:

* the **branch**: ``loading`` where the contraction grows (``v > 0``, the rising-pressure branch of a
  contraction-pressure loop), ``unloading`` where it shrinks; from the sign of the velocity, or at
  ``v = 0`` from the sign of the load's last motion before the point (the branch it is on); ``at rest``
  at an equilibrium, where the elements are taken relaxed (every deflection 0).
* each Maxwell-slip element's **stick state**, by the nonlinear model's own rule
  (:func:`pamsim.components.elasto_slide.element`): it slips if its deflection is on its slip displacement
  and the load moves outward (on the branch), else it sticks.  A sticking element is a spring
  ``k_i = w_i F_c(x, p, m) / delta_i`` on the load (with its damper), its deflection a state that follows
  the load; through the level ``F_c`` its force ``-k_i z_i`` depends on the contraction and the pressure
  too (zero where it is relaxed).  A slipping element pulls its constant slip force ``-+w_i F_c(x, p, m)``:
  its deflection is held, moves with nothing and moves nothing, and is dropped from the linear model
  (as an uncoupled air mass is), while its force's dependence on the contraction and the pressure (the
  level's) stays in the matrices.
* Bouc-Wen's ``|v|`` is ``s v`` with ``s`` the branch's sign (+1 at rest, where ``z = 0`` makes both the
  same for ``n >= 1``).

The models held so (:meth:`~pamsim.components.maxwell_slip_friction.MaxwellSlip.held`,
:meth:`~pamsim.components.bouc_wen_friction.BoucWenFriction.held`) are the components' own equations with
the switch fixed, differentiated exactly with the rig.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..assemblies.one_muscle import AddedComponent
from ..components.bouc_wen_friction import BoucWenFriction
from ..components.elasto_slide import element
from ..components.maxwell_slip_friction import MaxwellSlip
from .operating_point import OperatingPoint

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


def _motion(op: OperatingPoint) -> tuple[int, str]:
    """The branch's sign and what it was read from (see the module notes)."""
    v = float(op.states[1])
    if v != 0.0:
        return int(math.copysign(1.0, v)), "sign of the velocity"
    if op.motion_sign:
        return int(op.motion_sign), "at rest: the direction of the load's last motion"
    return 0, "an equilibrium: the elements relaxed"


def hold_hysteresis(model, op: OperatingPoint, added: tuple) -> tuple[tuple, OperatingPoint, LoopPoint | None]:
    """``(added, op, loop)``: the ``[hysteresis]`` component among ``added`` replaced by its model held in
    the stick state of ``op``, ``op`` with its deflections (0, relaxed, where it has none: an equilibrium),
    and what was held; ``added`` and ``op`` unchanged and None without one."""
    index = next((i for i, a in enumerate(added) if isinstance(a.component, (MaxwellSlip, BoucWenFriction))), None)
    if index is None:
        return added, op, None
    a = added[index]
    sign, source = _motion(op)
    state = {f"{a.component.name}.{k}": v for k, v in a.component.held_state(0.0).items()}
    state.update({k: v for k, v in op.line_states.items() if k in state})
    level = _level_N(model, a.component, op)
    if isinstance(a.component, MaxwellSlip):
        held, loop = _maxwell_slip(a.component, state, sign, level)
    else:
        held, loop = _bouc_wen(a.component, state, sign, level)
    loop = replace(loop, branch=BRANCHES[sign], branch_from=source)
    out = added[:index] + (AddedComponent(held, a.connect),) + added[index + 1:]
    return out, replace(op, line_states={**state, **op.line_states}), loop


def _level_N(model, component, op: OperatingPoint) -> float:
    """The friction law's level at ``op`` [N], as the component reads it."""
    p_gauge = float(op.states[2]) - model.source.p_atm_Pa
    return float(component.element.level_N(float(op.states[0]), p_gauge, model.load.mass_kg))


def _maxwell_slip(component: MaxwellSlip, state: dict, sign: int, level: float):
    """The model held in each element's stick state, and the elements' report."""
    branches, elements, dropped = [], [], []
    c = component.values["damping_N_s_per_m"]
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


def _bouc_wen(component: BoucWenFriction, state: dict, sign: int, level: float):
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
