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
from dataclasses import replace

from ..assemblies.one_muscle import AddedComponent
from ..assemblies.stick_state import BRANCHES, HYSTERESIS, LoopPoint, held
from .operating_point import OperatingPoint


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
    index = next((i for i, a in enumerate(added) if isinstance(a.component, HYSTERESIS)), None)
    if index is None:
        return added, op, None
    a = added[index]
    sign, source = _motion(op)
    state = {f"{a.component.name}.{k}": v for k, v in a.component.held_state(0.0).items()}
    state.update({k: v for k, v in op.line_states.items() if k in state})
    level = _level_N(model, a.component, op)
    component, loop = held(a.component, state, sign, level)
    loop = replace(loop, branch=BRANCHES[sign], branch_from=source)
    out = added[:index] + (AddedComponent(component, a.connect),) + added[index + 1:]
    return out, replace(op, line_states={**state, **op.line_states}), loop


def _level_N(model, component, op: OperatingPoint) -> float:
    """The friction law's level at ``op`` [N], as the component reads it."""
    p_gauge = float(op.states[2]) - model.source.p_atm_Pa
    return float(component.element.level_N(float(op.states[0]), p_gauge, model.load.mass_kg))
