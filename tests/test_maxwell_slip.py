"""Maxwell-slip elements in the muscle's force balance (``[hysteresis]``, :class:`pamsim.components.MaxwellSlip`):
Coulomb friction as the limit of one stiff element, on Figure 4 and the 66 paper tests; exact slip events;
the energy balance; every backend; element events named in results; and bad tables refused by key."""

from __future__ import annotations

import copy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.api import simulate
from pamsim.scenario import Scenario, ScenarioError
from pamsim.sweep.spec import load_sweep

ROOT = Path(__file__).resolve().parents[1]
FIG4 = ROOT / "scenarios" / "acra2012_fig4.toml"


def _with_elements(scenario: Scenario, deltas, shares, **extra) -> Scenario:
    spec = copy.deepcopy(dict(scenario.spec))
    spec["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": list(deltas), "share": list(shares), **extra}
    return Scenario.from_dict(spec, name=scenario.name, base_dir=scenario.base_dir)


@pytest.fixture(scope="module")
def fig4():
    return pamsim.load_scenario(FIG4)


def test_one_stiff_element_tends_to_the_coulomb_friction_it_replaces(fig4):
    """Figure 4 with the paper's load-dependent friction replaced by one element of share 1: the largest gap
    to the Coulomb model falls as the slip displacement does (tenfold per hundredfold: 1.3 mm at 100 um,
    0.13 mm at 1 um); python and native give the same run."""
    coulomb = simulate(fig4, backend="native")
    gaps = []
    for delta in (1e-4, 1e-6):
        res = simulate(_with_elements(fig4, [delta], [1.0]), backend="native")
        gaps.append(float(np.max(np.abs(res.x_m - coulomb.x_m))))
    assert gaps[1] < 2e-4 and gaps[1] < gaps[0] / 8, gaps
    py = simulate(_with_elements(fig4, [1e-4], [1.0]), backend="python")
    nat = simulate(_with_elements(fig4, [1e-4], [1.0]), backend="native")
    assert np.max(np.abs(py.x_m - nat.x_m)) < 1e-6


def test_the_66_paper_tests_with_one_stiff_element_match_coulomb_friction():
    """Every ACRA 2012 test of the grid on the native engine, its friction one element of 1 um: the trace
    stays within 0.2 mm of the Coulomb model's (the paper's own fit is 2.61 mm RMS)."""
    sweep = load_sweep(ROOT / "scenarios" / "acra2012_grid.toml")
    worst = 0.0
    for case in sweep.cases:
        sc = sweep.case_scenario(case, "load_dependent")
        a, b = simulate(sc, backend="native"), simulate(_with_elements(sc, [1e-6], [1.0]), backend="native")
        worst = max(worst, float(np.max(np.abs(a.x_m - b.x_m))))
    assert len(sweep.cases) == 66 and worst < 2e-4, worst


@pytest.fixture(scope="module")
def three(fig4):
    """Figure 4 on three elements (50, 200 and 1000 um; shares 0.2, 0.3, 0.5) with linear damping."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["model"]["damping"] = "linear"
    base = Scenario.from_dict(spec, name="three", base_dir=fig4.base_dir)
    return _with_elements(base, [5e-5, 2e-4, 1e-3], [0.2, 0.3, 0.5])


def test_a_slipping_element_sits_exactly_on_its_limit(three):
    """At every sample where an element slips, its deflection is its slip displacement to the last bit (the
    event's jump put it there, and it does not move while it slips), and no element is ever past it."""
    res = simulate(three, backend="python")
    for i, delta in enumerate((5e-5, 2e-4, 1e-3), start=1):
        z, slipping = res.signals[f"hysteresis.z{i}_m"], res.signals[f"hysteresis.slipping{i}"] == 1.0
        assert slipping.sum() > 10
        assert np.all(np.abs(z[slipping]) == delta) and np.all(np.abs(z) <= delta)
    kinds = [e.kind for e in res.transitions]
    assert {"hysteresis.slip1", "hysteresis.slip2", "hysteresis.slip3"} <= set(kinds)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_the_energy_balance_holds_with_elements(three, backend):
    """The work the load does on the elements (their springs' energy and their slip losses) closes the rig's
    balance, as a Coulomb friction's losses do."""
    res = simulate(three, backend=backend)
    balance = res.energy_balance()
    assert balance["relative"] < 1e-5 and sum(v for k, v in balance.items() if k.startswith("hysteresis.")) > 0.01


def test_every_backend_runs_the_elements_alike(three):
    """native and both FMU kinds against python: the same contraction within 1e-6 m, and native names the
    elements' events as python does."""
    py = simulate(three, backend="python")
    for backend in ("native", "fmu-cs", "fmu-me"):
        other = simulate(three, backend=backend)
        assert np.max(np.abs(other.x_m - py.x_m)) < 1e-6, backend
    native = simulate(three, backend="native")
    assert [e.kind for e in native.transitions] == [e.kind for e in py.transitions]


def test_the_element_force_is_its_share_of_the_level_where_it_slips(three):
    """A slipping element pulls its share of the friction law's level, against the motion; a sticking one
    less; the elements' total is their sum."""
    res = simulate(three, backend="python")
    s = res.signals
    level, total = s["hysteresis.level_N"], s["hysteresis.F_N"]
    parts = sum(s[f"hysteresis.F{i}_N"] for i in (1, 2, 3))
    assert np.allclose(total, parts, rtol=0, atol=1e-12)
    for i, share in enumerate((0.2, 0.3, 0.5), start=1):
        F, slipping = s[f"hysteresis.F{i}_N"], s[f"hysteresis.slipping{i}"] == 1.0
        assert np.allclose(np.abs(F[slipping]), share * level[slipping], rtol=1e-12, atol=0)
        assert np.all(np.abs(F) <= share * level * (1 + 1e-12) + 1e-12)


@pytest.mark.parametrize("change, key", [
    (lambda h: h.update(slip_displacement_m=[]), "hysteresis.slip_displacement_m"),
    (lambda h: h.update(slip_displacement_m=[1e-4] * 101, share=[0.01] * 101), "hysteresis.slip_displacement_m"),
    (lambda h: h.update(slip_displacement_m=[1e-4, -1e-4], share=[0.5, 0.5]), "hysteresis.slip_displacement_m[1]"),
    (lambda h: h.update(share=[-0.1]), "hysteresis.share[0]"),
    (lambda h: h.update(share=[0.5, 0.5]), "hysteresis.share"),
    (lambda h: h.update(model="preisach"), "hysteresis.model"),
    (lambda h: h.update(damping_N_s_per_m=-1.0), "hysteresis.damping_N_s_per_m"),
    (lambda h: h.update(stiffness=3.0), "hysteresis.stiffness"),
])
def test_bad_hysteresis_tables_are_refused_by_key(fig4, change, key):
    """No elements or more than 100, a slip displacement that is not positive (its stiffness would be
    infinite or negative), a negative share (a negative slip force), lists of different lengths, an unknown
    model or key: refused naming the key."""
    table = {"model": "maxwell_slip", "slip_displacement_m": [1e-4], "share": [1.0]}
    change(table)
    spec = copy.deepcopy(dict(fig4.spec))
    spec["hysteresis"] = table
    with pytest.raises(ScenarioError, match=key.replace("[", r"\[").replace("]", r"\]")):
        Scenario.from_dict(spec, name="bad", base_dir=fig4.base_dir)


def test_a_long_list_or_a_missing_model_reads_plainly(fig4):
    """101 elements: the message shows the list's first values and its length, not all 101; no model: the key
    is missing (not 'None: unknown')."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": [1e-3] * 101, "share": [0.01] * 101}
    with pytest.raises(ScenarioError) as info:
        Scenario.from_dict(spec, name="bad", base_dir=fig4.base_dir)
    assert "hysteresis.slip_displacement_m = [0.001, 0.001, 0.001, 0.001, 0.001, 0.001, ... (101 values)]: " \
        "must be an array of 1 to 100 numbers" in str(info.value) and len(str(info.value)) < 300
    del spec["hysteresis"]["model"]
    with pytest.raises(ScenarioError, match=r"missing key hysteresis\.model$"):
        Scenario.from_dict(spec, name="bad", base_dir=fig4.base_dir)


@pytest.mark.parametrize("table", [
    {"model": "maxwell_slip", "slip_displacement_m": [1e-4], "share": [1.0], "damping_N_s_per_m": 100.0},
    {"model": "bouc_wen", "beta_per_m_n": 10.0, "gamma_per_m_n": 10.0, "exponent": 1.0},
])
def test_elements_that_share_a_level_of_zero_are_refused_by_key(fig4, table, tmp_path):
    """``friction = "none"`` has a level of 0: Maxwell-slip or Bouc-Wen elements sharing it would have no slip
    force (only the presliding damping would act), so the scenario is refused naming ``model.friction``, from
    Python and from ``pamsim run`` (exit 2, nothing written).  PI's forces are its own: it is accepted, and
    its elements pull where the load moves."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["model"]["friction"] = "none"
    spec["hysteresis"] = table
    with pytest.raises(ScenarioError, match=r"model\.friction = 'none'"):
        Scenario.from_dict(spec, name="bad", base_dir=fig4.base_dir)
    lines = "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in table.items())
    path = tmp_path / "bad.toml"
    path.write_text(FIG4.read_text().replace('friction = "load_dependent"', 'friction = "none"', 1)
                    + "\n[hysteresis]\n" + lines)
    assert 'friction = "none"' in path.read_text()
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(path), "-o", str(tmp_path / "out")],
                          capture_output=True, text=True, cwd=ROOT / "scenarios")
    assert done.returncode == 2 and "model.friction = 'none'" in done.stderr, done.stderr
    assert "Traceback" not in done.stderr and not (tmp_path / "out").exists()
    spec["hysteresis"] = {"model": "pi", "thresholds_m": [2e-4, 1e-3], "weights_N_per_m": [3000.0, 500.0]}
    res = simulate(Scenario.from_dict(spec, name="pi", base_dir=fig4.base_dir), backend="python")
    assert np.max(np.abs(res.signals["hysteresis.F_N"])) > 0.1


@pytest.mark.parametrize("friction, parameters, key", [
    ("constant", {"coulomb_constant_N": 0.0}, r"parameters\.coulomb_constant_N = 0\.0"),
    ("load_dependent", {"N2_N_per_bar_m2": 0.0, "N1_N_per_bar_m": 0.0, "N0_N_per_bar": 0.0},
     r"parameters\.N0_N_per_bar = 0\.0"),
])
def test_a_friction_law_whose_coefficients_make_its_level_zero_is_refused_as_none_is(fig4, friction, parameters, key):
    """A law named with a level but whose coefficients are 0 is the same mistake as ``friction = "none"``; a
    nonzero coefficient is accepted."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["model"]["friction"] = friction
    spec["parameters"] = {**spec.get("parameters", {}), **parameters}
    spec["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": [1e-4], "share": [1.0]}
    with pytest.raises(ScenarioError, match=key + r": the friction law's level is 0"):
        Scenario.from_dict(spec, name="bad", base_dir=fig4.base_dir)
    spec["parameters"][key.split(r"\.")[1].split(" ")[0]] = 0.5
    assert Scenario.from_dict(spec, name="ok", base_dir=fig4.base_dir).build_model() is not None


# ---------------------------------------------------------------- where the load rests
TEN_DELTAS = list(np.geomspace(1e-4, 5e-3, 10))


def test_a_rig_without_coulomb_friction_takes_margins_of_the_forces_resolution(fig4):
    """With a ``[hysteresis]`` table the load's margins are ``rtol`` times its weight and twice that (by hand
    from the scenario's own rtol, mass and g); the Coulomb rig keeps 1e-7 N and 2e-7 N; margins given in
    ``[solver]`` are kept as given."""
    assert (fig4.solver.stick_margin_N, fig4.solver.release_margin_N) == (1e-7, 2e-7)
    sc = _with_elements(fig4, [1e-4], [1.0])
    weight = fig4.spec["load"]["weight_N"]
    assert sc.solver.stick_margin_N == pytest.approx(1e-6 * weight, rel=1e-12)
    assert sc.solver.release_margin_N == pytest.approx(2e-6 * weight, rel=1e-12)
    loose = sc.with_changes({"solver": {"rtol": 1e-4}})
    assert loose.solver.stick_margin_N == pytest.approx(1e-4 * weight, rel=1e-12)
    own = sc.with_changes({"solver": {"stick_margin_N": 1e-7, "release_margin_N": 2e-7}})
    assert (own.solver.stick_margin_N, own.solver.release_margin_N) == (1e-7, 2e-7)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_a_load_at_rest_on_its_elements_is_held_not_released_again(fig4, backend):
    """Figure 4 with ten damped elements: the load comes to rest on its elements' springs and is held once,
    with no release after it (with the Coulomb rig's 1e-7 N margins python released it 127 times, on its
    integrator's noise in the pressure, and native never held it), where the Coulomb rig's margins leave it
    to within 0.1 um."""
    sc = _with_elements(fig4, TEN_DELTAS, [0.1] * 10, damping_N_s_per_m=100.0)
    res = simulate(sc, backend=backend)
    holds = [e for e in res.transitions if e.to_mode == "stick"]
    assert len(holds) == 1 and 1.5 < holds[0].t_s < 2.5, holds
    assert not [e for e in res.transitions if e.t_s > holds[0].t_s]
    assert res.final_mode == 0  # held (stick) at the end
    fine = simulate(sc.with_changes({"solver": {"stick_margin_N": 1e-7, "release_margin_N": 2e-7}}), backend=backend)
    assert abs(res.x_m[-1] - fine.x_m[-1]) < 1e-7


@pytest.mark.parametrize("solver, key", [({"stick_margin_N": -1e-7}, "solver.stick_margin_N"),
                                         ({"release_margin_N": 1e-7}, "solver.release_margin_N"),
                                         ({"stick_margin_N": 1e-3}, "solver.stick_margin_N"),
                                         ({"release_margin_N": "big"}, "solver.release_margin_N")])
def test_bad_margins_are_refused_by_key(fig4, solver, key):
    """A negative stick margin, a release margin not above the stick margin, or one that is not a number."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["solver"] = solver
    with pytest.raises(ScenarioError, match=key):
        Scenario.from_dict(spec, name="bad", base_dir=fig4.base_dir)


def test_the_command_line_refuses_a_bad_table_with_exit_2(tmp_path):
    """``pamsim run`` on a scenario with a negative slip displacement: exit 2, the key named, no traceback,
    nothing written."""
    text = FIG4.read_text() + '\n[hysteresis]\nmodel = "maxwell_slip"\nslip_displacement_m = [-1e-4]\nshare = [1.0]\n'
    path = tmp_path / "bad.toml"
    path.write_text(text.replace('parameter_set = ', 'parameter_set = ', 1))
    done = subprocess.run([sys.executable, "-m", "pamsim", "run", str(path), "-o", str(tmp_path / "out")],
                          capture_output=True, text=True, cwd=ROOT / "scenarios")
    assert done.returncode == 2 and "hysteresis.slip_displacement_m[0]" in done.stderr
    assert "Traceback" not in done.stderr and not (tmp_path / "out").exists()


def test_a_linear_signal_goes_straight_between_its_knots(tmp_path):
    """``kind = "linear"``: at a knot its value, halfway between two the mean of theirs; the prescribed
    pressure of a run follows it on python and native alike."""
    spec = copy.deepcopy(dict(pamsim.load_scenario(ROOT / "scenarios" / "hysteresis_loops.toml").spec))
    spec["simulation"]["duration_s"] = 3.0
    sc = Scenario.from_dict(spec, name="linear", base_dir=ROOT / "scenarios")
    signal = sc.build_model().source.p_gauge_Pa
    times = spec["pressure"]["prescribed"]["times_s"]
    values = [v * 1e5 for v in spec["pressure"]["prescribed"]["values_gauge_bar"]]
    for k in range(len(times) - 1):
        assert signal(float(times[k])) == pytest.approx(values[k], rel=1e-15)
        assert signal(0.5 * (times[k] + times[k + 1])) == pytest.approx(0.5 * (values[k] + values[k + 1]), rel=1e-12)
    for backend in ("python", "native"):
        res = simulate(sc, backend=backend)
        assert np.allclose(res.p_gauge_Pa, signal(res.t_s), rtol=1e-12, atol=1e-6)


def test_the_loops_scenario_shows_return_point_memory():
    """``scenarios/hysteresis_loops.toml`` on native: after the turns of falling amplitude inside the first minor
    loop, the last rise passes 3 bar within 0.2 mm of where that loop left the rising branch (ideal Maxwell-slip
    returns exactly; the load's inertia and damping leave a little); the minor loop is narrower than the major
    one, and the elements slip."""
    sc = pamsim.load_scenario(ROOT / "scenarios" / "hysteresis_loops.toml")
    res = simulate(sc, backend="native")
    p_bar, x = res.p_gauge_Pa / 1e5, res.x_m

    def at(t):
        return int(np.searchsorted(res.t_s, t))

    last = np.arange(at(41.8), at(48.2))
    again = last[np.argmin(np.abs(p_bar[last] - 3.0))]
    assert abs(x[again] - x[at(30.6)]) < 2e-4

    def width(down, up, p):
        d, u = np.arange(at(down[0]), at(down[1])), np.arange(at(up[0]), at(up[1]))
        return x[d][np.argmin(np.abs(p_bar[d] - p))] - x[u][np.argmin(np.abs(p_bar[u] - p))]

    major, minor = width((12.2, 23.4), (1.0, 12.2), 2.4), width((30.6, 35.4), (23.4, 30.6), 2.4)
    assert 0.0 < minor < major
    assert sum(e.kind.startswith("hysteresis.slip") for e in res.transitions) >= 10


@pytest.fixture(scope="module")
def bouc_wen(fig4):
    """Figure 4 with Bouc-Wen friction (n = 1, beta = gamma = 5000 m^-1: z_u = 0.1 mm) and linear damping."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["model"]["damping"] = "linear"
    spec["hysteresis"] = {"model": "bouc_wen", "beta_per_m_n": 5000.0, "gamma_per_m_n": 5000.0, "exponent": 1.0}
    return Scenario.from_dict(spec, name="bouc_wen", base_dir=fig4.base_dir)


@pytest.mark.parametrize("backend", ["python", "native"])
def test_bouc_wen_follows_its_loading_branch_in_closed_form(bouc_wen, backend):
    """On the first rise (the load leaves its stop at 1.03 s with z = 0, and climbs until it turns), n = 1 gives
    dz/dx = 1 - (beta + gamma) z, so z = z_u (1 - exp(-(x - x0) / z_u)) with z_u = 1 / (beta + gamma); the
    force is the level times z / z_u; the energy balances."""
    res = simulate(bouc_wen, backend=backend)
    turn = next(e.t_s for e in res.transitions if e.kind == "velocity_zero")
    rise = (res.t_s > 1.0) & (res.t_s < turn)
    x, z = res.x_m[rise], res.signals["hysteresis.z_m"][rise]
    z_u = 1.0 / 10000.0
    assert np.max(np.abs(z - z_u * (1.0 - np.exp(-(x - x[0]) / z_u)))) < 1e-3 * z_u
    F, level = res.signals["hysteresis.F_N"], res.signals["hysteresis.level_N"]
    assert np.allclose(F, -level * res.signals["hysteresis.z_m"] / z_u, rtol=1e-12, atol=1e-12)
    assert res.energy_balance()["relative"] < 1e-5


def test_bouc_wen_runs_alike_on_every_backend(bouc_wen):
    """native and the co-simulation FMU against python, within 1e-5 m."""
    py = simulate(bouc_wen, backend="python")
    for backend in ("native", "fmu-cs"):
        assert np.max(np.abs(simulate(bouc_wen, backend=backend).x_m - py.x_m)) < 1e-5, backend


@pytest.mark.parametrize("change, key", [
    ({"exponent": 0.0}, "hysteresis.exponent"),
    ({"exponent": -1.0}, "hysteresis.exponent"),
    ({"beta_per_m_n": -10.0, "gamma_per_m_n": 5.0}, "hysteresis.gamma_per_m_n"),
    ({"slip_displacement_m": [1e-4]}, "hysteresis.slip_displacement_m"),
])
def test_bad_bouc_wen_tables_are_refused_by_key(fig4, change, key):
    """n <= 0, beta + gamma <= 0 (z would grow without bound on loading), a Maxwell-slip key: refused by key."""
    spec = copy.deepcopy(dict(fig4.spec))
    spec["hysteresis"] = {"model": "bouc_wen", "beta_per_m_n": 10.0, "gamma_per_m_n": 10.0, "exponent": 1.0, **change}
    with pytest.raises(ScenarioError, match=key):
        Scenario.from_dict(spec, name="bad", base_dir=fig4.base_dir)


MUSCLE_ALONE = """
name = "muscle_alone_maxwell_slip"
[model]
parameter_set = "shadow_6x300_acra2012"
friction = "constant"
damping = "none"
[load]
weight_N = 22.74
[pressure]
source = "prescribed"
prescribed = { kind = "constant", value_gauge_bar = 3.0 }
[simulation]
duration_s = 2.0
[hysteresis]
model = "maxwell_slip"
slip_displacement_m = [5e-4, 2e-3, 4e-3]
share = [0.2, 0.3, 0.5]
"""
"""A muscle alone on three elements sharing the paper's constant friction level (2.5 N), without damping."""


@pytest.mark.parametrize("kind, rel, past, rtol", [("CoSimulation", 1e-4, 1e-12, None),
                                                   ("ModelExchange", 1e-3, 1e-6, 1e-7)])
def test_a_length_cycle_of_the_muscle_alone_dissipates_the_loop_area(tmp_path, kind, rel, past, rtol):
    """The muscle-only FMU carries the elements: driven along a 1 Hz sinusoid of contraction of amplitude
    A = 10 mm, each element i dissipates per cycle the area of its parallelogram, 4 F_i (A - delta_i), with
    F_i its share of 2.5 N (the property: dissipated energy = loop area).  Over the second cycle the
    elements' work equals the hand sum (0.073 J) to ``rel``, and the area of the force-contraction loop
    (trapezoids over 1 ms samples) to 1 %; every deflection stays within its slip displacement (to ``past``:
    fmpy's model-exchange integrator reports the state where it located the event, before the jump).  In
    model exchange fmpy's CVode integrates at ``rtol`` (measured 1.1e-4 from the hand sum at 1e-7; at the
    FMU's default 1e-6 it is 7e-3: CVode steps past a slip and locates it from there)."""
    from fmpy import simulate_fmu

    src = tmp_path / "alone.toml"
    src.write_text(MUSCLE_ALONE)
    path = tmp_path / "alone.fmu"
    done = subprocess.run([sys.executable, "-m", "pamsim", "fmu", "build", "--scenario", str(src), "--muscle-only",
                           "-o", str(path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    t = np.linspace(0.0, 2.0, 4001)
    A, L0 = 0.01, 0.3
    inputs = np.zeros(t.size, dtype=[("time", float), ("prescribed_pressure_gauge_Pa", float), ("length_m", float),
                                     ("lengthening_velocity_m_s", float)])
    inputs["time"], inputs["prescribed_pressure_gauge_Pa"] = t, 3e5
    inputs["length_m"] = L0 - (0.03 + A * np.sin(2 * np.pi * t))
    inputs["lengthening_velocity_m_s"] = -A * 2 * np.pi * np.cos(2 * np.pi * t)
    names = [f"hysteresis.E_element{i}_J" for i in (1, 2, 3)] + [f"hysteresis.z{i}_m" for i in (1, 2, 3)]
    res = simulate_fmu(str(path), fmi_type=kind, start_time=0.0, stop_time=2.0, output_interval=1e-3, input=inputs,
                       start_values={"input_source": 0}, output=["motion.x_m", "hysteresis.F_N", *names],
                       validate=False, relative_tolerance=rtol)
    second = res["time"] >= 1.0
    work = sum(res[n][-1] - res[n][second][0] for n in names[:3])
    hand = sum(4 * w * 2.5 * (A - d) for w, d in zip((0.2, 0.3, 0.5), (5e-4, 2e-3, 4e-3)))
    area = -np.trapezoid(res["hysteresis.F_N"][second], res["motion.x_m"][second])
    assert work == pytest.approx(hand, rel=rel) and area == pytest.approx(hand, rel=1e-2)
    for i, d in zip((1, 2, 3), (5e-4, 2e-3, 4e-3)):
        assert np.max(np.abs(res[f"hysteresis.z{i}_m"])) <= d * (1 + past)


def test_a_joints_muscles_take_elements_too():
    """The antagonistic pair (constant 2.5 N friction, linear damping, the flexor at 2.6 bar) with one element
    of share 1 on each muscle: the elements' slips are events named after the muscle; python, native and the
    co-simulation FMU agree within 1e-5 rad; the angle tends to the Coulomb pair's (gap 100 times smaller from
    100 um to 1 um); the energy balances, with nothing left in a muscle's slack."""
    import tomllib

    from pamsim.joints.run import simulate_joint
    from pamsim.joints.scenario import JointScenario

    spec = tomllib.loads((ROOT / "scenarios" / "antagonistic_pair.toml").read_text())
    for m in spec["muscle"]:
        m["model"].update(friction="constant", damping="linear")
    spec["muscle"][0]["pressure"]["supply_gauge_bar"] = 2.6
    coulomb = simulate_joint(JointScenario.from_dict(copy.deepcopy(spec)), "native")
    gaps = []
    for delta in (1e-4, 1e-6):
        elements = copy.deepcopy(spec)
        for m in elements["muscle"]:
            m["hysteresis"] = {"model": "maxwell_slip", "slip_displacement_m": [delta], "share": [1.0]}
        sc = JointScenario.from_dict(elements)
        runs = {b: simulate_joint(sc, b) for b in ("python", "native", "fmu-cs")}
        for b in ("native", "fmu-cs"):
            assert np.max(np.abs(runs[b].theta_rad - runs["python"].theta_rad)) < 1e-5, b
        assert "extensor_hysteresis.slip1" in {e.kind for e in runs["native"].transitions}
        # the two elements may slip at one instant: python takes them one by one, the engine as one event
        # named after the last
        assert {e.kind for e in runs["native"].transitions} <= {e.kind for e in runs["python"].transitions}
        balance = runs["python"].energy_balance()
        assert balance["relative"] < 1e-5 and all(abs(balance[f"{n}.slack_J"]) < 1e-9 for n in ("flexor", "extensor"))
        gaps.append(float(np.max(np.abs(runs["native"].theta_rad - coulomb.theta_rad))))
    assert gaps[1] < gaps[0] / 30 and gaps[1] < 2e-4, gaps


def test_linearize_refuses_a_prescribed_pressure_with_added_components():
    """``pamsim linearize`` on the loops scenario (a prescribed pressure, a [hysteresis] table) names the
    source and exits 2; it ended in a traceback before (reading the valve's ambient pressure)."""
    done = subprocess.run([sys.executable, "-m", "pamsim", "linearize", str(ROOT / "scenarios" / "hysteresis_loops.toml")],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "valve source" in done.stderr and "Traceback" not in done.stderr


def test_the_elements_friction_law_parameters_say_what_they_are():
    """The friction law's numbers reach the assembly (and its FMU's parameters) through the elements: each
    carries the description the muscle's parameter schema gives its name, where it had none."""
    from pamsim.assemblies.one_muscle import scenario_assembly
    from pamsim.parameter_schema import KNOWN

    flat = scenario_assembly(pamsim.load_scenario(ROOT / "scenarios" / "hysteresis_loops.toml")).flatten()
    described = {v.name: v.description for v in flat.parameters}
    for name in ("N0_N_per_bar", "N1_N_per_bar_m", "N2_N_per_bar_m2", "phi_bar_per_kg"):
        assert described[f"hysteresis.{name}"] == KNOWN[name].description != ""
