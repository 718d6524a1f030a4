"""Exact Jacobians of the control model, from the components' generated expressions.

The control model is the one-muscle rig's assembly with the load sliding (``SLIP_UP``: the load
moves and every force acts on it) and the Coulomb term's direction given by a
:class:`FrictionDirection` component that writes the :class:`~pamsim.control.system.FrictionTreatment`
on symbols: 0 (dropped), ``tanh(v / v_s)`` (regularised) or the sliding direction.  CasADi
differentiates it: no difference quotient, no step to choose.  The work integrals are left out (they
feed nothing back) and the tendon force is ``m a + W - F_ext`` of the same expressions, as
:meth:`~pamsim.control.system.MusclePlant.output` defines it.

The valve's kink at command 0 has two one-sided slopes: the derivative is taken just inside the
filling and the venting branch (commands of +-1e-300, where the flow itself is zero to machine
precision), and ``valve_slope`` picks one or their mean; at a saturated command, just inside the
valve's range.
"""

from __future__ import annotations

import numpy as np

from ..assemblies.one_muscle import AddedComponent, one_muscle_assembly
from ..components.hanging_load import LoadMode
from ..errors import InputError
from ..modeling import Component, Equations, Symbols, Var
from .system import FrictionTreatment, require_valve_source

CONTROL_STATES = ("load.x_m", "load.v_m_s", "chamber.p_abs_Pa", "chamber.air_mass_kg")
"""The control model's states in the assembly (:data:`pamsim.control.system.STATES`)."""

INSIDE_KINK = 1e-300
"""Command [1] just inside either branch of the valve at its kink, 0: a slope, but no flow."""
TIE_STEP = 1e-12
"""Either side of the point [fraction of each variable's typical scale] at which a column is taken."""
INSIDE_SATURATION = 1e-12
"""Distance [1] inside the valve's range at a saturated command: the slope there differs from the
limit by that fraction of the curvature."""


class FrictionDirection(Component):
    """The factor of the Coulomb level in a smooth control model: ``direction`` from the load's
    velocity ``v_m_s`` as a :class:`FrictionTreatment` says."""

    inputs = (Var("v_m_s", "m/s", "load velocity"),)
    outputs = (Var("direction", "1", "factor of the Coulomb level (0, tanh(v / v_s), or +-1)"),)

    def __init__(self, name: str, treatment: FrictionTreatment):
        self.treatment = treatment
        super().__init__(name)

    def structure_key(self) -> tuple:
        """The class and the treatment: they are part of the generated code."""
        t = self.treatment
        return super().structure_key() + (t.kind, t.velocity_scale_m_s, t.direction)

    def equations(self, s: Symbols) -> Equations:
        t, v = self.treatment, s.u["v_m_s"]
        if t.kind == "dropped":
            direction = 0.0 * v
        elif t.kind == "regularised":
            direction = np.tanh(v / t.velocity_scale_m_s)
        else:
            direction = t.direction + 0.0 * v
        return Equations(outputs={"direction": direction})


def control_functions(model, friction: FrictionTreatment, added: tuple = ()):
    """CasADi functions ``(x, u) -> (f, y)`` and ``(x, u) -> (df/dx, df/du, dy/dx, dy/du)`` of the control
    states, the rig's four ``(x_m, v_m_s, p_abs_Pa, air_mass_kg)`` then those of the added components
    (:func:`line_states`), inputs ``(valve_command, supply_gauge_Pa, F_ext_N)`` and outputs
    ``(contraction_m, p_gauge_Pa, F_tendon_N)``, with ``model``'s parameter values as constants.
    ``added`` (:class:`~pamsim.assemblies.one_muscle.AddedComponent` s, a scenario's ``[[component]]``
    tables) act on the rig too: forces and work integrals, and the volumes of a supply line.

    Raises
    ------
    InputError
        For an added component with states the control model cannot carry (:func:`line_states`).
    """
    import casadi as ca

    flat = _control_flat(model, friction, added)
    names = [v.name for v in flat.states]
    keep = [names.index(n) for n in (*CONTROL_STATES, *_carried(flat, added))]
    x = ca.vertcat(*[flat.x[i] for i in keep])
    u = ca.vertcat(*flat.u)
    p = dict(zip([v.name for v in flat.parameters], flat.p))
    values = dict(zip([v.name for v in flat.parameters], flat.parameter_values))
    f = ca.vertcat(*[flat.f[i] for i in keep])
    mass, g = p["load.mass_kg"], p["load.g_m_s2"]
    out = {v.name: e for v, e in zip(flat.outputs, flat.y)}
    y = ca.vertcat(flat.x[keep[0]], out["chamber.p_gauge_Pa"], mass * f[1] + mass * g - flat.u[2])
    # The parameters become the model's numbers; the work states, which nothing reads, are not there.
    fixed = [ca.substitute(e, ca.vertcat(*flat.p), ca.DM([values[k] for k in p])) for e in (f, y)]
    values_fn = ca.Function("control_fy", [x, u], fixed)
    jac = ca.Function("control_jacobian", [x, u], [ca.jacobian(fixed[0], x), ca.jacobian(fixed[0], u),
                                                    ca.jacobian(fixed[1], x), ca.jacobian(fixed[1], u)])
    return values_fn, jac


def _control_flat(model, friction: FrictionTreatment, added: tuple):
    """The rig's flat model with the load sliding and the Coulomb term's direction from ``friction``."""
    treatment = (AddedComponent(FrictionDirection("treatment", friction), {"v_m_s": "load.v_m_s"}),)
    assembly = one_muscle_assembly(model, added=tuple(added) + treatment, friction_direction="treatment.direction")
    flat = assembly.flatten({"load": int(LoadMode.SLIP_UP)})
    if flat.externals:  # an element called on floats: CasADi would take it for a constant
        raise NotImplementedError(f"no exact Jacobian through {', '.join(e.name for e in flat.externals)}")
    return flat


def line_states(model, added: tuple) -> tuple[tuple[str, float], ...]:
    """``(name, nominal scale)`` of each state the control model carries besides the rig's four: the added
    components' own (a supply line's pressures and air masses), not the integrals that nothing reads (their
    work), in the assembly's order.

    Raises
    ------
    InputError
        For a component with such states that cannot say where they rest (a ``held_state(p_abs_Pa)``).
    """
    if not any(a.component.states for a in added) and len(model.source.state_names) <= 2:
        return ()
    flat = _control_flat(model, FrictionTreatment("dropped"), added)
    nominal = {v.name: v.nominal for v in flat.states}
    return tuple((name, nominal[name]) for name in _carried(flat, added))


def _carried(flat, added) -> list[str]:
    """The names of the states the control model carries besides the rig's four (see :func:`line_states`):
    the valve's own (a spool's position and velocity), then the added components'."""
    own = {a.component.name: a.component for a in added}
    quadratures = flat.quadratures()
    owner = [v.name.split(".", 1)[0] for v in flat.states]
    spool = [v.name for i, v in enumerate(flat.states) if i not in quadratures and owner[i] == "valve"]
    extra = [v.name for i, v in enumerate(flat.states) if i not in quadratures and owner[i] in own]
    for name in extra:
        component = own[name.split(".", 1)[0]]
        if not callable(getattr(component, "held_state", None)):
            raise InputError(f"component {component.name!r}: pamsim linearize takes added components that act on the "
                             "rig with forces, or the volumes of a supply line, not ones with other states of their "
                             f"own ({', '.join(n for n in extra if n.startswith(component.name + '.'))})")
    return spool + extra


def held_line_states(model, added: tuple, p_abs_Pa, known: dict | None = None) -> np.ndarray:
    """The values of :func:`line_states` with every volume of the line at rest at ``p_abs_Pa`` (the valve open
    on a supply at that pressure: no flow anywhere), or each at its own (``{component name: p_abs_Pa}``,
    :func:`pamsim.control.line_rest.held_line_pressures`), those in ``known`` (a spool's) as it gives them."""
    by_name = {a.component.name: a.component for a in added}
    known = known or {}
    values = []
    for name, _ in line_states(model, added):
        if name in known:
            values.append(known[name])
            continue
        owner, _, state = name.partition(".")
        p = p_abs_Pa[owner] if isinstance(p_abs_Pa, dict) else p_abs_Pa
        values.append(by_name[owner].held_state(p)[state])
    return np.asarray(values, dtype=float)


def rest_pull(model, added: tuple):
    """The force the muscle and the ``added`` components pull the load with at rest, as a static force
    model (``force_N(x_m, p_gauge_Pa)``, :mod:`pamsim.static`): the muscle's static force plus what
    the added components exert on the load at rest, from the assembly's generated net force."""
    if not added:
        return model.static_force
    require_valve_source(model)  # the added components' force is read at the chamber's pressure
    return _RestPull(model, tuple(added))


class _RestPull:
    """``force_N(x, p)``: the muscle's static force plus the added components' force on the load at rest."""

    def __init__(self, model, added: tuple):
        import casadi as ca

        flat = one_muscle_assembly(model, added=added).flatten({"load": int(LoadMode.STICK)})
        x_sym, p_sym = ca.SX.sym("x"), ca.SX.sym("p")
        names = [v.name for v in flat.states]
        values = {"load.x_m": x_sym, "chamber.p_abs_Pa": p_sym + model.source.p_atm_Pa,
                  "chamber.air_mass_kg": ca.SX(1.0)}  # no force depends on the air mass
        params = dict(zip([v.name for v in flat.parameters], flat.parameter_values))
        outputs = {v.name: e for v, e in zip(flat.outputs, flat.y)}
        # F_net = F_static + F_added - W + F_ext with the external force input at 0.
        added_N = outputs["load.F_net_N"] - outputs["muscle.F_static_N"] - outputs["load.F_gravity_N"]
        subs_from = ca.vertcat(*flat.x, *flat.p, *flat.u)
        subs_to = ca.vertcat(*[values.get(n, ca.SX(0.0)) for n in names],
                             *[ca.SX(params[v.name]) for v in flat.parameters], *[ca.SX(0.0) for _ in flat.u])
        self._added = ca.Function("added_force", [x_sym, p_sym], [ca.substitute(added_N, subs_from, subs_to)])
        self.static_force = model.static_force
        names = [repr(a.component.name) for a in added]
        self.added_names = f"component{'s' if len(names) > 1 else ''} {', '.join(names)}"

    def added_N(self, x_m, p_gauge_Pa):
        """What the added components alone pull the load with at rest [N] (scalars or arrays)."""
        x = np.asarray(x_m, dtype=float)
        added = np.vectorize(lambda xi: float(self._added(xi, float(p_gauge_Pa))))(x)
        return added if x.ndim else float(added)

    def force_N(self, x_m, p_gauge_Pa):
        """The pull [N] at contraction ``x_m`` and gauge pressure ``p_gauge_Pa`` (scalars or arrays)."""
        return self.static_force.force_N(x_m, p_gauge_Pa) + self.added_N(x_m, p_gauge_Pa)


def exact_jacobians(model, states, inputs, friction: FrictionTreatment, valve_slope: str, added: tuple = ()):
    """``(A, B, C, D)`` of the control model at ``states``, ``inputs`` (numpy arrays; the states the rig's four,
    then :func:`line_states`).

    Each column is the mean of the analytic derivative just either side of the point, a step of
    :data:`TIE_STEP` of the variable's typical scale away: where a branch of the model switches exactly
    there (a chamber at its supply's pressure, where the flow's direction flips), the derivative at the
    point itself would be the convention of one branch (CasADi's derivative of ``|x|`` at 0 is 0), and
    the mean is what a central difference gives.  Elsewhere the two sides agree to that fraction of the
    curvature.  The valve's column at a kink or a saturation is taken as the module notes say.
    """
    from .system import INPUT_SCALES, STATE_SCALES

    _, jac = control_functions(model, friction, added)
    scales = tuple(STATE_SCALES) + tuple(nominal for _, nominal in line_states(model, added))
    x0 = np.asarray(states, dtype=float)
    u0 = np.asarray(inputs, dtype=float)

    def at(x, u):
        return [np.array(m) for m in jac(x, u)]

    def column(i: int, of_state: bool, points) -> tuple[np.ndarray, np.ndarray]:
        """Column i of (A, C) or (B, D), the mean over ``points`` (values of that variable)."""
        cols = []
        for value in points:
            x, u = x0.copy(), u0.copy()
            (x if of_state else u)[i] = value
            A, B, C, D = at(x, u)
            cols.append((A[:, i], C[:, i]) if of_state else (B[:, i], D[:, i]))
        return np.mean([a for a, _ in cols], axis=0), np.mean([c for _, c in cols], axis=0)

    A, B, C, D = at(x0, u0)
    for i, scale in enumerate(scales):
        A[:, i], C[:, i] = column(i, True, (x0[i] + TIE_STEP * scale, x0[i] - TIE_STEP * scale))
    for j, scale in enumerate(INPUT_SCALES):
        points = (u0[j] + TIE_STEP * scale, u0[j] - TIE_STEP * scale)
        if j == 0 and u0[0] == 0.0:
            points = [INSIDE_KINK * s for s in {"mean": (1.0, -1.0), "fill": (1.0,), "vent": (-1.0,)}[valve_slope]]
        elif j == 0 and abs(u0[0]) >= 1.0:
            points = (np.sign(u0[0]) * (1.0 - INSIDE_SATURATION),)
        B[:, j], D[:, j] = column(j, False, points)
    return A, B, C, D
