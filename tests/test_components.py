"""The one-muscle model built from components against today's composed model (pamsim.model and the
simulator's mode machine): right-hand side, outputs, initial state, event jumps, and the exact
Jacobians against central finite differences."""

from __future__ import annotations

import dataclasses
import functools
import math
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.assemblies import one_muscle_assembly, scenario_assembly
from pamsim.model import Mode
from pamsim.scenario import load_scenario
from pamsim.simulator import SolverOptions

ROOT = Path(__file__).resolve().parents[1]
FIG4 = ROOT / "scenarios" / "acra2012_fig4.toml"
SCENARIOS = ["acra2012_fig3", "acra2012_fig4", "acra2012_fig5", "acra2012_fig6a", "acra2012_fig6b",
             "acra2012_fig4_chou_hannaford", "closed_loop_position"]
VARIANTS = [  # element choices on top of the Fig. 4 scenario: every law the components wrap
    {},
    {"model": {"friction": "constant"}},
    {"model": {"friction": "none", "damping": "linear"}},
    {"model": {"friction_negative_level": "abs", "damping": "none"}},
    {"pressure": {"source": "prescribed", "prescribed": {"kind": "lag", "time_s": 0.5, "tau_s": 0.01, "final_gauge_bar": 3.0}},
     "model": {"static_force": "gaylord"}},
    {"model": {"muscle": "kothera2009_3b", "static_force": "kothera_force_balance_thickness"},
     "load": {"weight_N": 20.0}, "pressure": {"supply_gauge_bar": 3.0}},
]
N_POINTS = 1000
RHS_ATOL = 1e-12 * np.array([1.0, 10.0, 1e6, 1e-4, 10.0, 10.0, 10.0, 10.0])
"""Rounding of sums of forces of tens of newtons (the flange adds its forces in another order than
the composed model): 1e-12 of each derivative's typical size, in SI units."""


def _case(spec):
    sc = load_scenario(FIG4)
    return sc.with_changes(spec) if spec else sc


def _random_state(model, rng):
    """A state anywhere the dynamics can go: between the stops, at any speed, any chamber pressure and
    gas temperature; inputs anywhere in their range."""
    x = rng.uniform(model.stops.x_low_m, model.stops.x_high_m)
    y = np.array(model.initial_state(x), dtype=float)
    y[1] = rng.uniform(-0.5, 0.5)
    y[-4:] = rng.uniform(-1, 1, 4)
    src = model.source
    if src.state_names:
        y[2] = rng.uniform(0.9e5, 6e5)
        y[3] = y[2] * src.chamber.volume_m3(x) / (src.chamber.R_J_per_kg_K * rng.uniform(250.0, 350.0))
        ins = (rng.uniform(-1.0, 1.0), rng.uniform(0.0, 5e5))
    else:
        ins = (rng.uniform(0.0, 5e5),)
    F_ext = rng.uniform(-5.0, 5.0)
    return y, ins, F_ext


def _flat(model):
    return one_muscle_assembly(model).flatten()


@pytest.mark.parametrize("spec", VARIANTS, ids=lambda s: str(s) or "fig4")
def test_right_hand_side_equals_the_composed_model(spec):
    model = _case(spec).build_model()
    flat = _flat(model)
    g = flat.compile_python()
    P = flat.parameter_values
    rng = np.random.default_rng(11)
    for _ in range(N_POINTS):
        y, ins, F_ext = _random_state(model, rng)
        u = [*ins, F_ext]
        for mode in Mode:
            if mode.is_slip:
                want = model.slip_rhs(y, float(mode), ins, F_ext)
                x = y
            else:
                x = y.copy()
                x[1] = 0.0  # a held load has zero velocity (the simulator and the C core keep it so)
                want = model.held_rhs(x, ins)
            (got,) = g.f(list(x), u, P, [float(mode)])
            err = np.abs(np.array(got) - want)
            atol = RHS_ATOL if len(want) == 8 else RHS_ATOL[[0, 1, 4, 5, 6, 7]]  # prescribed: no chamber
            assert np.all(err <= 1e-12 * np.abs(want) + atol), (mode.label, x, u, err, want)


@pytest.mark.parametrize("name", SCENARIOS)
def test_outputs_and_start_equal_the_composed_model(name):
    sc = load_scenario(ROOT / "scenarios" / f"{name}.toml")
    model = sc.build_model()
    flat = scenario_assembly(sc).flatten()
    g = flat.compile_python()
    P = flat.parameter_values
    rng = np.random.default_rng(13)
    columns = {"load.F_friction_N": "F_friction_N", "load.F_stop_N": "F_stop_N", "load.F_gravity_N": "F_gravity_N",
               "muscle.F_static_N": "F_static_N", "damping.F_damping_N": "F_damping_N",
               "external.F_external_N": "F_external_N", "load.F_coulomb_level_N": "F_coulomb_level_N",
               "chamber.p_gauge_Pa": "p_gauge_Pa", "chamber.gas_temperature_K": "gas_temperature_K",
               "valve.mass_flow_kg_s": "valve_mass_flow_kg_s"}
    for _ in range(200):
        y, ins, F_ext = _random_state(model, rng)
        for mode in Mode:
            x = y.copy()
            if not mode.is_slip:
                x[1] = 0.0
            t = np.array([0.0])
            # The composed model reads inputs from its signals: compare at t = 0 with those inputs.
            u = [*model.source.inputs(0.0), model.load.external_N(0.0)]
            want = model.breakdown(t, x.reshape(-1, 1), np.array([int(mode)]))
            (got,) = g.y(list(x), u, P, [float(mode)])
            for flat_name, column in columns.items():
                if column not in want:
                    continue
                np.testing.assert_allclose(got[flat.index("outputs", flat_name)], want[column][0], rtol=1e-12,
                                           atol=1e-12 * model.load.weight_N, err_msg=f"{flat_name} in {mode.label}")
    x0, q0 = g.x0([*model.source.inputs(0.0), 0.0], P)
    np.testing.assert_array_equal(x0, model.initial_state(sc.initial_contraction_m, sc.initial_pressure_gauge_Pa))
    (q_rest,) = g.rest_mode(x0, [*model.source.inputs(0.0), 0.0], P, q0)
    stops = model.stops
    where = (Mode.STOP_LOW if x0[0] <= stops.x_low_m else Mode.STOP_HIGH if x0[0] >= stops.x_high_m
             else Mode.STICK)
    assert q0 == [float(where)]
    u0 = [*model.source.inputs(0.0), 0.0]
    assert q_rest == [float(_hand_rest_mode(model, np.array(x0), u0, where, sc.solver.stick_margin_N))]


def _hand_rest_mode(model, y, u, where: Mode, margin_N: float) -> Mode:
    """A load at rest slides if its net force beats friction by the margin, else stays held."""
    p_gauge = y[2] - model.source.p_atm_Pa if model.source.state_names else u[0]
    net = model.static_force.force_N(y[0], p_gauge) - model.load.weight_N + u[-1]
    level = model.friction.level_N(y[0], p_gauge, model.load.mass_kg)
    if where != Mode.STOP_HIGH and net - level > margin_N:
        return Mode.SLIP_UP
    if where != Mode.STOP_LOW and -net - level > margin_N:
        return Mode.SLIP_DOWN
    return where


def _hand_jump(model, y, mode: Mode, u, opts):
    """The jump at an event worked out by hand from the model's forces (MODEL_NOTES sec. 4): the
    state after it, the mode, and what happened."""
    x, v = y[0], y[1]
    stops = model.stops
    y = y.copy()

    def rest(where):
        return _hand_rest_mode(model, y, u, where, opts.stick_margin_N)

    if not mode.is_slip:
        return y, rest(mode), "rest"
    up = mode == Mode.SLIP_UP
    if (x >= stops.x_high_m) if up else (x <= stops.x_low_m):
        y[0] = stops.x_high_m if up else stops.x_low_m
        rebound = stops.restitution * abs(v)
        if rebound > stops.min_rebound_speed_m_s:
            y[1] = -rebound if up else rebound
            return y, Mode.SLIP_DOWN if up else Mode.SLIP_UP, "rebound"
        y[1] = 0.0
        return y, rest(Mode.STOP_HIGH if up else Mode.STOP_LOW), "stop"
    y[1] = 0.0
    return y, rest(Mode.STICK), "stopped"


@pytest.mark.parametrize("restitution, min_rebound_m_s", [(0.0, 1e-3), (0.5, 1e-3), (0.5, 0.1)])
def test_event_jumps_agree_with_a_hand_calculation(restitution, min_rebound_m_s):
    sc = _case({"parameters": {"stop_restitution": restitution}} if restitution else {})
    model = sc.build_model()
    model = dataclasses.replace(model, stops=dataclasses.replace(model.stops, min_rebound_speed_m_s=min_rebound_m_s))
    flat = _flat(model)
    g = flat.compile_python()
    P = flat.parameter_values
    opts = SolverOptions()
    rng = np.random.default_rng(17)
    seen = set()
    for _ in range(N_POINTS):
        y, ins, F_ext = _random_state(model, rng)
        mode = Mode(int(rng.choice([-1, 0, 1, 2, 3])))
        # Put a sliding load on or past what ends its mode: a stop, or a velocity of the other sign.
        if mode.is_slip:
            if rng.random() < 0.5:
                y[0] = model.stops.x_high_m if mode == Mode.SLIP_UP else model.stops.x_low_m
                y[1] = abs(y[1]) * float(mode)
            else:
                y[1] = -abs(y[1]) * float(mode) * rng.choice([1.0, 0.0])
        else:
            y[1] = 0.0
        u = [*ins, F_ext]
        z, _ = g.z(list(y), u, P, [float(mode)])
        fired = [1.0 if zk <= 0.0 else 0.0 for zk in z]
        x_next, q_next = g.transition(list(y), u, P, [float(mode)], fired)
        (q_rest,) = g.rest_mode(x_next, u, P, q_next)
        want_y, want_mode, what = _hand_jump(model, y, mode, u, opts)
        seen.add((mode.label, what, want_mode.label))
        assert q_rest == [float(want_mode)], (mode, what, y)
        np.testing.assert_array_equal(x_next, want_y)
    # Every jump occurred: stops with (restitution 0.5) or without rebound, stopping, release both ways.
    assert len(seen) >= 11, seen


def _fd_jacobian(fun, z, nominal, h_rel=1e-6):
    """Central differences of ``fun`` at ``z``, with the one-sided ones to tell a kink inside the step."""
    n = len(z)
    f0 = np.asarray(fun(z))
    J, kink = np.zeros((len(f0), n)), np.zeros((len(f0), n), dtype=bool)
    for j in range(n):
        h = h_rel * max(abs(z[j]), nominal[j])
        zp, zm = z.copy(), z.copy()
        zp[j] += h
        zm[j] -= h
        fp, fm = np.asarray(fun(zp)), np.asarray(fun(zm))
        J[:, j] = (fp - fm) / (2 * h)
        fwd, bwd = (fp - f0) / h, (f0 - fm) / h
        kink[:, j] = np.abs(fwd - bwd) > 1e-4 * (np.abs(J[:, j]) + 1e-12 * np.abs(f0) / h)
    return J, kink


@pytest.mark.parametrize("spec", VARIANTS, ids=lambda s: str(s) or "fig4")
def test_exact_jacobians_agree_with_central_differences(spec):
    """df/dx, df/du, dy/dx, dy/du of every component of the assembly at random states and modes, to
    1e-7 relative.  An entry whose finite-difference step straddles a kink (|v|, a clamp, the valve's
    choked-laminar switches) is not comparable and is counted, not tested: at most 1 % of them."""
    model = _case(spec).build_model()
    flat = _flat(model)
    g = flat.compile_python()
    P = flat.parameter_values
    x_nom = np.array([v.nominal for v in flat.states])
    u_nom = np.array([{"1": 1.0, "Pa": 1e5, "N": 1.0}[v.unit] for v in flat.inputs])
    rng = np.random.default_rng(19)
    compared = skipped = 0
    for _ in range(N_POINTS):
        y, ins, F_ext = _random_state(model, rng)
        u = np.array([*ins, F_ext])
        q = [float(rng.choice([-1, 0, 1, 2, 3]))]
        A, B, C, D = g.jacobian(list(y), list(u), P, q)
        for exact, fun, z, nom in (
                (np.hstack([A, B]), lambda zz: g.f(list(zz[:len(y)]), list(zz[len(y):]), P, q)[0],
                 np.concatenate([y, u]), np.concatenate([x_nom, u_nom])),
                (np.hstack([C, D]), lambda zz: g.y(list(zz[:len(y)]), list(zz[len(y):]), P, q)[0],
                 np.concatenate([y, u]), np.concatenate([x_nom, u_nom]))):
            fd, kink = _fd_jacobian(fun, z, nom)
            scale = np.abs(exact) + np.abs(fd)
            row_scale = np.max(np.abs(exact) * nom, axis=1, keepdims=True) / nom
            ok = np.abs(exact - fd) <= 1e-7 * scale + 1e-9 * row_scale
            compared += int(np.sum(~kink))
            skipped += int(np.sum(kink))
            bad = ~ok & ~kink
            assert not bad.any(), (np.argwhere(bad), exact[bad], fd[bad], q, y, u)
    assert skipped <= 0.01 * compared, (skipped, compared)


def _applicable_static_forces():
    """``(muscle, model name, scenario)`` for each shipped muscle and each static model that applies to it."""
    from pamsim.muscles import shipped_names
    from pamsim.static_models import REGISTRY

    sc = load_scenario(FIG4)
    for muscle in shipped_names():
        for name in REGISTRY:
            try:
                case = sc.with_changes({"model": {"muscle": muscle, "static_force": name},
                                        "pressure": {"supply_gauge_bar": 0.1}, "load": {"weight_N": 1.0}})
            except Exception:
                continue  # the model does not apply to this muscle
            yield muscle, name, case


def test_every_static_force_of_every_shipped_muscle_is_a_component():
    """Each (muscle, model) pair that applies: its component's force, as equations or as an external
    function, equals the model's on floats over the muscle's travel and pressure range."""
    traced = external = 0
    for muscle, name, case in _applicable_static_forces():
        model = case.build_model()
        flat = _flat(model)
        outputs = flat.compile_python().y
        i = flat.index("outputs", "muscle.F_static_N")
        for x in np.linspace(model.stops.x_low_m, model.stops.x_high_m, 9):
            for p in np.linspace(0.0, case.parameters["rated_pressure_gauge_Pa"], 5):
                y = list(model.initial_state(float(x)))
                y[2] = p + model.source.p_atm_Pa
                (out,) = outputs(y, [0.0, 0.0, 0.0], flat.parameter_values, [0.0])
                want = float(model.static_force.force_N(float(x), float(p)))
                assert out[i] == pytest.approx(want, rel=1e-9, abs=1e-9 * max(1.0, abs(want)), nan_ok=True), \
                    (muscle, name, x, p)
        traced += not flat.externals
        external += bool(flat.externals)
    assert traced >= 250, (traced, external)


def test_a_force_table_is_an_external_function():
    """A tabulated static force (an implicit model's) has no symbolic form: the component calls it on
    floats, and the Python model equals it.  Its spline has a CasADi form, through which the exact
    Jacobians go: the table of the polynomial (quadratic in x, affine in p, so the spline reproduces
    it) has the polynomial model's own Jacobians, a second implementation."""
    from pamsim.elements.force_table import TabulatedStaticForce
    from pamsim.static_models.acra2012 import Acra2012Polynomial

    sc = load_scenario(FIG4)
    poly = Acra2012Polynomial.from_parameters(sc.parameters)
    # Over every state drawn below (beyond the polynomial's fitted domain, which tabulate would keep to).
    x, p = np.linspace(0.0, sc.build_model().stops.x_high_m, 33), np.linspace(-2e5, 6e5, 9)
    table = TabulatedStaticForce(poly.name, poly.domain, x, p, poly.force_N(*np.meshgrid(x, p, indexing="ij")))
    model = dataclasses.replace(sc.build_model(), static_force=table)
    flat = _flat(model)
    assert [e.name for e in flat.externals] == ["muscle.force_N"]
    g = flat.compile_python()
    flat_poly = _flat(dataclasses.replace(model, static_force=poly))  # its coefficients are parameters
    jac, jac_poly = flat.function("jacobian"), flat_poly.function("jacobian")
    rng = np.random.default_rng(23)
    for _ in range(200):
        y, ins, F_ext = _random_state(model, rng)
        for mode in (Mode.SLIP_UP, Mode.STICK):
            x = y.copy()
            if not mode.is_slip:
                x[1] = 0.0
            want = model.slip_rhs(x, float(mode), ins, F_ext) if mode.is_slip else model.held_rhs(x, ins)
            (got,) = g.f(list(x), [*ins, F_ext], flat.parameter_values, [float(mode)])
            np.testing.assert_array_equal(got, want)
            u, q = [*ins, F_ext], [float(mode)]
            for a, b in zip(jac(list(x), u, flat.parameter_values, q),
                            jac_poly(list(x), u, flat_poly.parameter_values, q)):
                a, b = np.array(a), np.array(b)
                np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-7 * max(1.0, np.abs(b).max()))
    with pytest.raises(NotImplementedError, match="muscle.force_N"):
        flat.c_sources()  # the flat model's own C (cgen) has no external functions; the engine's C lifts them


# ---------------------------------------------------------------- elements of other forms


@dataclasses.dataclass(frozen=True)
class _Term:
    k_N_per_Pa: float


@dataclasses.dataclass(frozen=True)
class _TermsForce:
    """A static force whose numbers sit in a tuple of dataclasses: constants of the generated code."""

    terms: tuple
    name: str = "terms"

    def force_N(self, x_m, p_gauge_Pa):
        return sum(t.k_N_per_Pa for t in self.terms) * p_gauge_Pa * (1.0 - x_m / 0.08)


def _scaled(a, p):
    return a * p


@dataclasses.dataclass(frozen=True)
class _ShapeForce:
    """A static force with a callable field (a closure, a partial)."""

    shape: object
    name: str = "shape"

    def force_N(self, x_m, p_gauge_Pa):
        return self.shape(p_gauge_Pa) * (1.0 - x_m / 0.08)


def _closure(a):
    return lambda p: a * p


@pytest.mark.parametrize("pair", [
    (_TermsForce((_Term(1e-4),)), _TermsForce((_Term(3e-4),))),
    (_ShapeForce(functools.partial(_scaled, 1e-4)), _ShapeForce(functools.partial(_scaled, 3e-4))),
    (_ShapeForce(_closure(1e-4)), _ShapeForce(_closure(3e-4))),
], ids=["tuple of dataclasses", "partial", "closure"])
def test_models_that_differ_in_baked_numbers_do_not_share_generated_code(pair):
    """Generated code is shared by structure; numbers the code holds as constants are structure."""
    from pamsim.components.element import structure_key

    assert structure_key(pair[0]) != structure_key(pair[1])
    base = load_scenario(FIG4).build_model()
    for element in pair:  # both in one process, so a wrongly shared cache would show
        model = dataclasses.replace(base, static_force=element)
        assembly = one_muscle_assembly(model)
        from pamsim.modeling.pygen import compiled_by_mode

        code = compiled_by_mode(assembly, "load", ("f",))
        y = np.array(model.initial_state(0.01))
        y[1], y[2] = 0.05, 3e5
        (got,) = code[Mode.SLIP_UP].f(list(y), [0.5, 4e5, 0.0], assembly.parameter_values(), ())
        np.testing.assert_array_equal(got, model.slip_rhs(y, 1.0, (0.5, 4e5), 0.0))


def test_input_order_is_part_of_the_structure():
    from pamsim.modeling import Assembly

    model = load_scenario(FIG4).build_model()
    a = one_muscle_assembly(model)
    swapped = Assembly(a.components, a.connections, dict(reversed(list(a.inputs.items()))), a.name)
    assert a.structure_key() != swapped.structure_key()


@dataclasses.dataclass(frozen=True)
class _TanhDamping:
    """A law written with math.tanh: on a symbol, math gives NaN without a word."""

    c_N_s_per_m: float
    v_s_m_s: float
    name: str = "tanh"

    def force_N(self, v_m_s):
        return self.c_N_s_per_m * self.v_s_m_s * math.tanh(v_m_s / self.v_s_m_s)


class _PlainFriction:
    """A friction law that is not a dataclass: it takes symbols, its number a constant of the code."""

    name = "plain"

    def __init__(self, level_N):
        self.level = level_N

    def level_N(self, x_m, p_gauge_Pa, mass_kg):
        return self.level + 0.0 * x_m


def test_laws_with_no_symbolic_form_run_on_floats_and_agree():
    base = load_scenario(FIG4).build_model()
    model = dataclasses.replace(base, damping=_TanhDamping(5.0, 0.01), friction=_PlainFriction(1.5))
    flat = _flat(model)
    assert [e.name for e in flat.externals] == ["damping.force_N"]
    assert not [v.name for v in flat.parameters if v.name.startswith(("friction.", "damping."))]
    g = flat.compile_python()
    rng = np.random.default_rng(31)
    for _ in range(200):
        y, ins, F_ext = _random_state(model, rng)
        for mode in (Mode.SLIP_UP, Mode.SLIP_DOWN):
            (got,) = g.f(list(y), [*ins, F_ext], flat.parameter_values, [float(mode)])
            np.testing.assert_array_equal(got, model.slip_rhs(y, float(mode), ins, F_ext))
    result = pamsim.simulate_model(model, 2.0, x0_m=0.0)
    assert np.all(np.isfinite(result.x_m)) and result.x_m.max() > 0.01


def test_static_force_jacobians_of_every_shipped_muscle_agree_with_central_differences():
    """dF/dx and dF/dp of every static model that becomes equations, for every shipped muscle it
    applies to, at random points inside its domain: exact against central differences, 1e-7 relative
    (the few points whose difference step straddles a kink of the clip at F = 0 are counted, not
    compared: at most 2 %)."""
    rng = np.random.default_rng(37)
    compared = skipped = models = 0
    for muscle, name, case in _applicable_static_forces():
        model = case.build_model()
        flat = _flat(model)
        if flat.externals:
            continue
        models += 1
        i_F = flat.index("outputs", "muscle.F_static_N")
        C = flat.function("jacobian")
        y_fn = flat.function("y")
        P = flat.parameter_values
        d = model.static_force.domain
        x_hi = min(model.stops.x_high_m, d.x_max_m)
        p_hi = min(case.parameters["rated_pressure_gauge_Pa"], d.p_max_Pa)
        for _ in range(8):
            x = rng.uniform(max(d.x_min_m, 0.0), x_hi)
            p_gauge = rng.uniform(max(d.p_min_Pa, 0.0), p_hi)
            y = np.array(model.initial_state(x))
            y[2] = p_gauge + model.source.p_atm_Pa
            u = [1.0, 3e5, 0.0]
            dy_dx = np.array(C(y, u, P, [0.0])[2])[i_F]
            exact = np.array([dy_dx[0], dy_dx[2]])  # d/dx, d/dp_abs
            fd, kinks = [], []
            for k, h in ((0, 1e-7), (2, 1e-6 * y[2])):  # about eps^(1/3) of the scale of each
                yp, ym = y.copy(), y.copy()
                yp[k] += h
                ym[k] -= h
                Fp, Fm = (float(np.array(y_fn(v, u, P, [0.0]))[i_F, 0]) for v in (yp, ym))
                F0 = float(np.array(y_fn(y, u, P, [0.0]))[i_F, 0])
                fd.append((Fp - Fm) / (2 * h))
                kinks.append(abs((Fp - F0) - (F0 - Fm)) > 1e-4 * abs(Fp - Fm) + 1e-12 * abs(F0))
            for e, f, kink in zip(exact, fd, kinks):
                if kink:
                    skipped += 1
                    continue
                compared += 1
                assert abs(e - f) <= 1e-7 * max(abs(e), abs(f)) + 1e-9, (muscle, name, x, p_gauge, e, f)
    assert models >= 250 and skipped <= 0.02 * compared, (models, compared, skipped)
