"""A scenario's model as CasADi functions, for optimal control and estimation tools.

``casadi_model(scenario)`` hands over the functions pamsim generates its own code from: the
right-hand side, outputs, event indicators, jumps and exact Jacobians of the flat model
(:mod:`pamsim.modeling`), with the names of its states, inputs, outputs and parameters, the
scenario's parameter values and its initial state.  :meth:`CasadiModel.rhs` gives the smooth ODE of
one mode of the load (sliding up, say) with the parameters fixed, which is what a shooting or
collocation method, acados or do-mpc takes.  ``docs/control.md`` has a worked trajectory
optimisation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .assemblies.one_muscle import one_muscle_assembly
from .components.hanging_load import LoadMode
from .errors import InputError
from .scenario import Scenario


@dataclass(frozen=True)
class CasadiModel:
    """The flat model of a scenario as CasADi ``Function`` s.

    ``functions``: ``f(x, u, p, q)`` (state derivatives), ``y`` (outputs), ``z`` (event indicators
    and their margins), ``transition(x, u, p, q, e)``, ``rest_mode``, ``x0(u, p)`` and
    ``jacobian(x, u, p, q)`` (A, B, C, D), where x are the states, u the inputs, p the parameters and
    q the load's mode (:class:`~pamsim.components.hanging_load.LoadMode`).
    """

    functions: dict[str, Any]
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    parameters: tuple[str, ...]
    parameter_values: np.ndarray
    x0: np.ndarray
    mode0: LoadMode
    _assembly: Any

    def rhs(self, mode: str | LoadMode):
        """``f(x, u)``: the derivatives in one mode of the load (``"slip_up"``...), the parameters fixed
        to the scenario's.  Smooth inside the mode; the hybrid model leaves it at its events."""
        import casadi as ca

        mode = LoadMode[mode.upper()] if isinstance(mode, str) else LoadMode(mode)
        flat = self._assembly.flatten({"load": int(mode)})
        x, u = ca.SX.sym("x", len(self.states)), ca.SX.sym("u", len(self.inputs))
        xdot = flat.function("f")(x, u, self.parameter_values, ca.SX(0, 1))
        return ca.Function(f"f_{mode.label}", [x, u], [xdot], ["x", "u"], ["xdot"])


def casadi_model(scenario: Scenario, initial_contraction_m: float | None = None,
                 initial_pressure_gauge_Pa: float | None = None) -> CasadiModel:
    """The model of ``scenario`` (its muscle, elements, load and valve or prescribed pressure; a
    ``[controller]`` is not part of it) as CasADi functions.  The start defaults to the scenario's."""
    opts = scenario.solver
    x0_m = scenario.initial_contraction_m if initial_contraction_m is None else initial_contraction_m
    p0 = scenario.initial_pressure_gauge_Pa if initial_pressure_gauge_Pa is None else initial_pressure_gauge_Pa
    model = scenario.build_model()
    assembly = one_muscle_assembly(model, x0_m, p0, opts.stick_margin_N, opts.release_margin_N,
                                   scenario.added_components)
    flat = assembly.flatten()
    if flat.externals:
        raise InputError(f"{scenario.origin}: model.static_force = {scenario.spec['model']['static_force']!r} "
                         f"and the other elements called on floats ({', '.join(e.name for e in flat.externals)}) "
                         "have no CasADi form; choose a closed-form model")
    p = np.array(flat.parameter_values)
    u0 = [*model.source.inputs(0.0), model.load.external_N(0.0)]
    x0, where = (np.array(r).ravel() for r in flat.function("x0").call([u0, p]))
    (mode0,) = np.array(flat.function("rest_mode").call([x0, u0, p, where])[0]).ravel()
    return CasadiModel(flat.functions, tuple(v.name for v in flat.states), tuple(v.name for v in flat.inputs),
                       tuple(v.name for v in flat.outputs), tuple(v.name for v in flat.parameters), p, x0,
                       LoadMode(int(mode0)), assembly)
