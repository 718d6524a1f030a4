"""``pamsim linearize`` on a point of a hysteresis loop (``[hysteresis]``, docs/hysteresis.md, "Linearisation on
a loop"): the matrices against central differences of the switching model's own right-hand side in the same
stick state, the static stiffness of sticking elements against the hand sum of their springs, the reported
stick states against the run's deflections, a slipping element against its removal and against the rig's
sliding Coulomb friction, Bouc-Wen's branch at rest, and bad input refused by key."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.api import simulate
from pamsim.control import FrictionTreatment, held_equilibrium, open_valve_equilibrium, trajectory_point
from pamsim.control.exact import rest_pull
from pamsim.control.linear import linearize
from pamsim.model import Mode
from pamsim.scenario import Scenario
from pamsim.simulator import GeneratedCode, SolverOptions

ROOT = Path(__file__).resolve().parents[1]
LOOP = ROOT / "scenarios" / "hysteresis_valve_loop.toml"
DELTAS = (2e-4, 1e-3, 4e-3)
SHARES = (0.3, 0.3, 0.4)
RIG = {"x_m": "load.x_m", "v_m_s": "load.v_m_s", "p_abs_Pa": "chamber.p_abs_Pa", "air_mass_kg": "chamber.air_mass_kg"}
SCALES = {"x_m": 1e-2, "v_m_s": 1e-1, "p_abs_Pa": 1e5, "air_mass_kg": 1e-5}


@pytest.fixture(scope="module")
def loop():
    return pamsim.load_scenario(LOOP)


def _variant(scenario, name, hysteresis=None, **model):
    """``scenario`` with its ``[hysteresis]`` table replaced (``None``: removed) and ``[model]`` keys changed."""
    spec = copy.deepcopy(dict(scenario.spec))
    spec["model"].update(model)
    if hysteresis is None:
        spec.pop("hysteresis")
    else:
        spec["hysteresis"] = hysteresis
    return Scenario.from_dict(spec, name=name, base_dir=scenario.base_dir)


def _linear(scenario, op, friction=None):
    model = scenario.build_model()
    return linearize(model, op, friction, added=scenario.added_components, drop_unobservable_air_mass=False)


def _run_to(scenario, t_s):
    return simulate(scenario.with_changes({"simulation": {"duration_s": float(t_s)}}))


def _expected_states(res, deltas):
    """Per element ``slip`` or ``stick`` from the run's last sample, by hand: on its limit (to 1e-12 of it) with
    the load moving outward, or at rest after moving outward; and the branch's sign."""
    v = res.v_m_s[-1]
    moved = res.v_m_s[res.v_m_s != 0.0]
    sign = np.sign(v) if v != 0.0 else (np.sign(moved[-1]) if moved.size else 0.0)
    out = []
    for i, delta in enumerate(deltas, start=1):
        z = res.signals[f"hysteresis.z{i}_m"][-1]
        on_limit = abs(abs(z) - delta) <= 1e-12 * delta
        out.append("slip" if on_limit and sign * z > 0 else "stick")
    return out, sign


# ---------------------------------------------------------------- A against the nonlinear right-hand side
def _central_A(scenario, op, names, mode, rel_step=1e-6, side=0):
    """Columns ``names`` (the linear model's states) of the Jacobian of the python backend's generated
    right-hand side (the switching elements) at ``op``, by central differences (``side`` +-1: one-sided)."""
    model = scenario.build_model()
    gen = GeneratedCode.of_model(model, SolverOptions(), 0.0, None, scenario.added_components)
    code_names = gen.code[mode].names["states"]
    values = {RIG[n]: op.states[k] for k, n in enumerate(RIG)}
    values.update(op.line_states)
    y0 = np.array([values.get(n, 0.0) for n in code_names], dtype=float)
    rows = [code_names.index(RIG.get(n, n)) for n in names]
    gen.inputs = lambda _t: list(op.inputs)  # the operating point's own inputs
    f = gen.rhs(mode)
    cols = []
    for n in names:
        h = rel_step * SCALES.get(n, 1e-3)
        yp, ym = y0.copy(), y0.copy()
        k = code_names.index(RIG.get(n, n))
        yp[k] += h if side >= 0 else 0.0
        ym[k] -= h if side <= 0 else 0.0
        cols.append((f(0.0, yp) - f(0.0, ym))[rows] / (yp[k] - ym[k]))
    return np.column_stack(cols)


def _scaled_gap(A, A_ref, names):
    s = np.array([SCALES.get(n, 1e-3) for n in names])
    S = s[None, :] / s[:, None]
    ref = np.max(np.abs(A_ref) * S, axis=1, keepdims=True)
    ref[ref == 0.0] = 1.0
    return float(np.max(np.abs(A - A_ref) * S / ref))


@pytest.mark.parametrize("t_s", [3.0, 7.0, 13.0])
def test_A_matches_central_differences_of_the_switching_model(loop, t_s):
    """At 3 s (loading, every element slipping), 7 s (unloading: element 1 slipping, 2 and 3 sticking) and 13 s
    (at rest after unloading, all sticking): the linear model's A equals central differences (steps 1e-6 of
    each state's scale) of the python backend's right-hand side, the elements switching as in a run, to 1e-6
    of each row's largest entry in scaled variables; the slipping elements' deflections are not states."""
    op = trajectory_point(loop, t_s)
    lin = _linear(loop, op)
    names = list(lin.sys.state_labels)
    mode = Mode.SLIP_DOWN if op.states[1] < 0 else Mode.SLIP_UP
    A_fd = _central_A(loop, op, names, mode)
    assert _scaled_gap(lin.sys.A, A_fd, names) < 1e-6
    slipping = [e["name"][-1] for e in lin.hysteresis.as_dict()["elements"] if e["state"] == "slip"]
    assert {f"hysteresis.z{i}_m" for i in slipping} == set(lin.dropped_states) - {"air_mass_kg"}
    assert not {f"hysteresis.z{i}_m" for i in slipping} & set(names)
    assert len(slipping) == {3.0: 3, 7.0: 1, 13.0: 0}[t_s]


# ---------------------------------------------------------------- static stiffness of sticking elements
def _dc_stiffness(lin) -> float:
    g0, _ = lin.gain_at_zero("F_ext_N", "contraction_m")
    return 1.0 / g0


def _levels(scenario, x_m, p_gauge_Pa):
    law = scenario.added_components[0].component.element
    return law.level_N(x_m, p_gauge_Pa, scenario.mass_kg)


def test_sticking_elements_add_their_springs_to_the_static_stiffness_open_valve(loop):
    """The open valve's equilibrium, the elements relaxed and sticking: 1 / (DC gain F_ext -> contraction)
    equals the muscle's own static stiffness -dF_static/dx at the supply pressure (central difference of the
    static force) plus the hand sum of ``k_i = w_i F_c / delta_i``, F_c the friction law's level there."""
    model = loop.build_model()
    supply = loop.final_pressure_gauge_Pa
    op = open_valve_equilibrium(model, supply, pull=rest_pull(model, loop.added_components))
    lin = _linear(loop, op)
    x = float(op.states[0])
    h = 1e-6
    k_rig = -(model.static_force.force_N(x + h, supply) - model.static_force.force_N(x - h, supply)) / (2 * h)
    level = _levels(loop, x, supply)
    k_elements = sum(w * level / d for w, d in zip(SHARES, DELTAS))
    assert level > 1.0 and k_elements > k_rig / 2  # the elements matter here
    assert _dc_stiffness(lin) == pytest.approx(k_rig + k_elements, rel=1e-6)
    assert all(e["state"] == "stick" and e["deflection_m"] == 0.0 for e in lin.hysteresis.elements)
    assert lin.hysteresis.branch == "at rest"


@pytest.mark.parametrize("x_mm", [30.0, 45.0])
def test_sticking_elements_add_their_springs_to_the_closed_chamber(loop, x_mm):
    """Held at X with the valve closed, the elements relaxed: the stiffness is the rig's own (the same scenario
    without elements, linearised at the same point: static and pneumatic) plus the hand sum of the k_i."""
    model = loop.build_model()
    rig = _variant(loop, "rig")
    op = held_equilibrium(model, x_mm * 1e-3, loop.final_pressure_gauge_Pa)
    k_rig = _dc_stiffness(linearize(rig.build_model(), op))
    level = _levels(loop, x_mm * 1e-3, op.states[2] - model.source.p_atm_Pa)
    k_elements = sum(w * level / d for w, d in zip(SHARES, DELTAS))
    assert level > 0.5
    assert _dc_stiffness(_linear(loop, op)) == pytest.approx(k_rig + k_elements, rel=1e-6)


# ---------------------------------------------------------------- reported stick states
@pytest.mark.parametrize("t_s, branch", [(3.0, "loading"), (7.0, "unloading"), (8.0, "unloading"),
                                         (13.0, None)])
def test_reported_stick_states_are_the_runs(loop, t_s, branch):
    """The report's branch and each element's stick state, deflection, limit and spring against the run's
    deflections at T, classified in the test (and, where the load moves, the run's own ``slipping`` output);
    at 13 s the load is at rest and the branch is its last motion's (None): the last swing of its ringing
    as it came to rest on its elements, in the run's velocity samples."""
    res = _run_to(loop, t_s)
    states, sign = _expected_states(res, DELTAS)
    branch = branch or {1: "loading", -1: "unloading"}[sign]
    lin = _linear(loop, trajectory_point(loop, t_s))
    rep = lin.hysteresis.as_dict()
    assert rep["branch"] == branch and {"loading": 1, "unloading": -1}[branch] == sign
    assert ("last motion" in rep["branch_from"]) == (res.v_m_s[-1] == 0.0)
    level = res.signals["hysteresis.level_N"][-1]
    for i, (e, want) in enumerate(zip(rep["elements"], states), start=1):
        assert e["state"] == want
        assert e["deflection_m"] == res.signals[f"hysteresis.z{i}_m"][-1]
        assert e["slip_limit_m"] == DELTAS[i - 1]
        assert e["k_N_per_m"] == pytest.approx(SHARES[i - 1] * level / DELTAS[i - 1], rel=1e-12)
        if res.v_m_s[-1] != 0.0:
            assert (res.signals[f"hysteresis.slipping{i}"][-1] == 1.0) == (want == "slip")
    assert states == {3.0: ["slip"] * 3, 7.0: ["slip", "stick", "stick"], 8.0: ["slip", "slip", "stick"],
                      13.0: ["stick"] * 3}[t_s]


# ---------------------------------------------------------------- a slipping element
def _only_third(scenario, op):
    """The scenario with elements 1 and 2 removed, and ``op`` with element 3's deflection renamed."""
    table = dict(scenario.spec["hysteresis"], slip_displacement_m=[DELTAS[2]], share=[SHARES[2]])
    one = _variant(scenario, "one", table)
    return one, replace(op, line_states={"hysteresis.z1_m": op.line_states["hysteresis.z3_m"]})


def test_a_slipping_element_adds_only_its_constant_force_at_a_constant_level(loop):
    """Constant friction (2.5 N): at 8 s elements 1 and 2 slip, 3 sticks.  Removing the two slipping elements
    leaves A, B, C, D as they are (to 1e-12); only f(x0, u0) changes, in the load's row by their constant
    slip forces over the mass, ``-sign(v) (w_1 + w_2) F_c / m``."""
    const = _variant(loop, "constant", dict(loop.spec["hysteresis"]), friction="constant")
    op = trajectory_point(const, 8.0)
    lin = _linear(const, op)
    assert [e["state"] for e in lin.hysteresis.elements] == ["slip", "slip", "stick"]
    one, op1 = _only_third(const, op)
    lin1 = _linear(one, op1)
    assert list(lin1.sys.state_labels) == [n.replace("z3", "z1") for n in lin.sys.state_labels]
    for key in ("A", "B", "C", "D"):
        a, b = getattr(lin.sys, key), getattr(lin1.sys, key)
        assert np.max(np.abs(a - b)) <= 1e-12 * max(np.max(np.abs(a)), 1.0), key
    level = const.parameters["coulomb_constant_N"]
    slip_N = -np.sign(op.states[1]) * (SHARES[0] + SHARES[1]) * level
    assert lin.residual[1] - lin1.residual[1] == pytest.approx(slip_N / const.mass_kg, rel=1e-9)


def test_a_slipping_elements_pressure_coupling_is_the_sliding_coulomb_frictions(loop):
    """The paper's load-dependent friction, at 8 s: what the two slipping elements add to A (against the model
    with them removed) is ``w_1 + w_2`` times what the rig's own Coulomb friction adds when linearised sliding
    the same way (the scenario without elements, ``sliding`` minus ``dropped``): the level's dependence on
    the contraction and the pressure, a second implementation (the Coulomb friction component)."""
    op = trajectory_point(loop, 8.0)
    lin = _linear(loop, op)
    one, op1 = _only_third(loop, op)
    lin1 = _linear(one, op1)
    rig = _variant(loop, "rig").build_model()
    rig_op = replace(op, line_states={})
    sliding = linearize(rig, rig_op, FrictionTreatment("sliding"), drop_unobservable_air_mass=False).sys.A
    dropped = linearize(rig, rig_op, FrictionTreatment("dropped"), drop_unobservable_air_mass=False).sys.A
    added = (lin.sys.A - lin1.sys.A)[:4, :4]
    coulomb = (SHARES[0] + SHARES[1]) * (sliding - dropped)
    assert abs(coulomb[1, 2]) > 1e-6  # the level follows the pressure: the coupling is there
    assert np.allclose(added, coulomb, rtol=1e-9, atol=1e-12 * np.max(np.abs(lin.sys.A)))
    assert np.allclose(lin.sys.A[4:], lin1.sys.A[4:], rtol=1e-12, atol=0.0)


# ---------------------------------------------------------------- Bouc-Wen
BOUC_WEN = {"model": "bouc_wen", "beta_per_m_n": 500.0, "gamma_per_m_n": 500.0, "exponent": 1.0}


def test_bouc_wen_follows_the_velocitys_branch_and_at_rest_the_last_motions(loop):
    """Bouc-Wen (n = 1, beta = gamma = 500 m^-1) at 7 s, unloading: A equals central differences of the
    python backend's right-hand side.  With the velocity set to 0 there (the load at rest after unloading),
    the v column is the one-sided difference towards v < 0 (the last motion's branch, to 1e-6), which the
    other side misses (the |v| kink: d z'/dv differs by -2 beta z there); the report says which."""
    bw = _variant(loop, "bouc_wen", BOUC_WEN)
    op = trajectory_point(bw, 7.0)
    assert op.states[1] < 0.0
    lin = _linear(bw, op)
    names = list(lin.sys.state_labels)
    assert _scaled_gap(lin.sys.A, _central_A(bw, op, names, Mode.SLIP_DOWN), names) < 1e-6
    rest = replace(op, states=np.array([op.states[0], 0.0, *op.states[2:]]), motion_sign=-1)
    lin0 = _linear(bw, rest)
    assert lin0.hysteresis.branch == "unloading" and "last motion" in lin0.hysteresis.branch_from
    k_v = names.index("v_m_s")
    below = _central_A(bw, rest, names, Mode.SLIP_DOWN, side=-1)
    above = _central_A(bw, rest, names, Mode.SLIP_UP, side=1)
    k_z = names.index("hysteresis.z_m")
    assert lin0.sys.A[k_z, k_v] == pytest.approx(below[k_z, k_v], rel=1e-6)
    z = op.line_states["hysteresis.z_m"]
    assert above[k_z, k_v] - below[k_z, k_v] == pytest.approx(-2 * 500.0 * z, rel=1e-4)


# ---------------------------------------------------------------- the command line
def _cli(*args, cwd=ROOT / "scenarios"):
    return subprocess.run([sys.executable, "-m", "pamsim", "linearize", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd)


def test_the_command_line_reports_the_branch_and_stick_states(loop, tmp_path):
    """``--at-time 13 --json``: the hysteresis block, every element sticking on the branch of the run's last
    motion (it ended in a traceback before: the repeated pole at 0 of the sticking elements); the text output
    prints each element."""
    done = _cli(LOOP, "--at-time", 13, "--json")
    assert done.returncode == 0, done.stderr
    rep = json.loads(done.stdout)
    _, sign = _expected_states(_run_to(loop, 13.0), DELTAS)
    assert rep["hysteresis"]["branch"] == {1: "loading", -1: "unloading"}[sign]
    assert [e["state"] for e in rep["hysteresis"]["elements"]] == ["stick"] * 3
    assert rep["states"][-3:] == ["hysteresis.z1_m", "hysteresis.z2_m", "hysteresis.z3_m"]
    text = _cli(LOOP, "--at-time", 7, "-o", tmp_path / "out")
    assert text.returncode == 0, text.stderr
    assert "branch unloading" in text.stdout and "state slip" in text.stdout and "state stick" in text.stdout
    # The rig has no Coulomb friction of its own to drop: the elements are its friction.
    assert rep["friction"].startswith("no Coulomb friction: the [hysteresis] elements")
    assert "friction: no Coulomb friction" in text.stdout and "Coulomb friction dropped" not in text.stdout


@pytest.mark.parametrize("args, key", [(["--at-time", 20], "--at-time 20"), (["--at-time", 0], "--at-time 0"),
                                       (["--contraction-mm", 200], "contraction 200 mm"),
                                       (["--friction", "sliding", "--at-time", 7], "--friction sliding")])
def test_bad_operating_points_are_refused_by_key(tmp_path, args, key):
    """A time that is not on the run, a contraction out of range, a Coulomb friction treatment (the elements
    take its place): exit 2, one line naming the key, no traceback, nothing written."""
    out = tmp_path / "out"
    done = _cli(LOOP, *args, "-o", out)
    assert done.returncode == 2 and key in done.stderr, done.stderr
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert not out.exists()
