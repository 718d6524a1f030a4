"""The generic C engine running the generated model, against the python backend (an independent
integrator, event location and mode switching over the same generated equations), against hand
calculations, and its code generation and caching.

Events are compared over the first ``EVENTS``: a bound on the later events of a long oscillation would
measure only how fast it amplifies the integrators' differences (``benchmarks/regression.py`` explains).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.assemblies import one_muscle_assembly, scenario_assembly
from pamsim.components.hanging_load import LoadMode
from pamsim.modeling import Assembly, Component, Equations, Var
from pamsim.modeling.cmodel import CModel
from pamsim.modeling.pygen import compiled_by_mode
from pamsim.native import backend
from pamsim.native.engine import engine_library

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
EVENTS = 5
FIG4 = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")

CASES = {
    "fig3": pamsim.load_scenario(SCENARIOS / "acra2012_fig3.toml"),
    "fig4": FIG4,
    "fig5": pamsim.load_scenario(SCENARIOS / "acra2012_fig5.toml"),
    "fig6a": pamsim.load_scenario(SCENARIOS / "acra2012_fig6a.toml"),
    "fig6b": pamsim.load_scenario(SCENARIOS / "acra2012_fig6b.toml"),
    "constant friction, linear damping": FIG4.with_changes(
        {"load": {"weight_N": 42.74}, "model": {"friction": "constant", "damping": "linear"}}),
    "no friction, no damping": FIG4.with_changes({"model": {"friction": "none", "damping": "none"}}),
    "negative friction level as its magnitude": FIG4.with_changes({"model": {"friction_negative_level": "abs"}}),
    "prescribed step": FIG4.with_changes({"pressure": {"source": "prescribed", "prescribed": {
        "kind": "step", "time_s": 0.5, "final_gauge_bar": 3.0}}}),
    "valve opened, then vented": pamsim.Scenario.from_dict({
        "load": {"weight_N": 22.74}, "simulation": {"duration_s": 4.0},
        "pressure": {"source": "valve", "supply_gauge_bar": 3.6, "command": {
            "kind": "ramp", "start_s": 0.5, "end_s": 2.5, "initial": 1.0, "final": -1.0}}}),
    "start part-way, pressurised": FIG4.with_changes({"simulation": {"initial_contraction_m": 0.02},
                                                      "pressure": {"initial_gauge_bar": 2.0}}),
}


RTOL = 1e-9
"""Both backends at this tolerance: close to their converged runs, so that what is left between them is
the integrators' error (LSODA against Dormand-Prince 5(4)), not the model's."""


@pytest.mark.parametrize("name", list(CASES))
def test_the_engine_agrees_with_the_python_backend(name):
    """The generic C engine against the python backend (solve_ivp, LSODA): the same generated equations,
    integrated, stopped at events and switched by independent code."""
    scenario = CASES[name].with_changes({"solver": {"rtol": RTOL, "native_rtol_factor": 1.0}})
    res = pamsim.simulate(scenario, backend="native")
    ref = pamsim.simulate(scenario)
    assert [e.kind for e in res.transitions][:EVENTS] == [e.kind for e in ref.transitions][:EVENTS]
    times = np.array([e.t_s for e in res.transitions][:EVENTS])
    ref_times = np.array([e.t_s for e in ref.transitions][:EVENTS])
    assert np.max(np.abs(times - ref_times), initial=0.0) < 1e-6
    assert abs(res.x_m[-1] - ref.x_m[-1]) < 1e-8  # 1e-5 mm
    assert abs(res.peak_contraction_m - ref.peak_contraction_m) < 1e-8
    assert np.max(np.abs(res.x_m - ref.x_m)) < 1e-7
    # the work integrals: the engine's Gauss quadrature of each step, the python backend's states
    for key in ("W_muscle_J", "E_friction_J", "E_damping_J", "W_external_J"):
        scale = max(1.0, np.max(np.abs(ref.signals[key])))
        assert np.max(np.abs(res.signals[key] - ref.signals[key])) < 1e-6 * scale, key


def test_a_long_hold_settles_and_costs_no_steps():
    """A chamber within the tolerance of its supply is settled onto it, and the held load then stays
    at rest in one step per input segment: 100 s of holding cost what 10 s do."""
    short, long = (pamsim.simulate(FIG4.with_changes({"simulation": {"duration_s": d}}), backend="native")
                   for d in (10.0, 100.0))
    assert long.stats["rhs_evaluations"] == short.stats["rhs_evaluations"]
    assert long.p_gauge_Pa[-1] == pytest.approx(FIG4.final_pressure_gauge_Pa, abs=0.0)


def test_settle_is_the_hand_calculation():
    """At a held state within the tolerance of the supply: the pressure becomes the supply's and the air
    mass moves by dp V / (n R T_supply), the polytropic relation at the held volume."""
    assembly = scenario_assembly(FIG4)
    code = compiled_by_mode(assembly, "load", ("settle", "y"))[LoadMode.STICK]
    model = FIG4.build_model()
    src = model.source
    p_supply = FIG4.final_pressure_gauge_Pa + src.p_atm_Pa
    x = 0.03
    V = src.chamber.volume_m3(x)
    m = p_supply * V / (src.chamber.R_J_per_kg_K * src.T_supply_K)
    tol = 1e-6
    for dp, settles in ((-0.4, True), (-10.0, False), (0.0, False)):
        p = p_supply + dp
        state = [x, 0.0, p, m, 0.0, 0.0, 0.0, 0.0]
        (settled,) = code.settle(state, [1.0, FIG4.final_pressure_gauge_Pa, 0.0], assembly.parameter_values(), (), [tol])
        if not settles:
            assert settled == state
            continue
        assert settled[2] == p_supply
        expected = m - dp * V / (src.chamber.polytropic_index * src.chamber.R_J_per_kg_K * src.T_supply_K)
        assert settled[3] == pytest.approx(expected, rel=1e-14)
        assert settled[:2] + settled[4:] == state[:2] + state[4:]


def test_quadratures_are_the_states_nothing_reads():
    flat = scenario_assembly(FIG4).flatten()
    assert [flat.states[i].name for i in flat.quadratures()] == [
        "muscle.W_muscle_J", "friction.E_friction_J", "damping.E_damping_J", "external.W_external_J"]

    class Integrator(Component):
        inputs = (Var("u", "1"),)
        states = (Var("a", "1"), Var("b", "1"))
        outputs = (Var("b", "1"),)

        def equations(self, s):
            # a integrates u; b integrates a: a is read by b's derivative, b by nothing but an output
            return Equations(der={"a": s.u["u"], "b": s.x["a"]}, outputs={"b": s.x["b"]},
                             initial={"a": 0.0, "b": 0.0})

    flat = Assembly([Integrator("i")], [], {"u": "i.u"}).flatten()
    assert flat.quadratures() == [1]


def test_held_modes_are_those_where_the_load_does_not_move():
    model = CModel(scenario_assembly(FIG4))
    assert dict(zip(model.mode_values, model.held)) == {int(m): not m.is_slip for m in LoadMode}
    assert model.counts == {"nx": 4, "nq": 4, "nu": 3, "np": 42, "ny": 20, "nz": 2, "nmodes": 5}


GENERATE = """
import hashlib, sys
import pamsim
from pamsim.assemblies import scenario_assembly
from pamsim.modeling.cmodel import CModel
sc = pamsim.load_scenario(sys.argv[1])
print(hashlib.sha256(CModel(scenario_assembly(sc)).sources()["pam_model.c"].encode()).hexdigest())
"""


def test_generated_c_is_byte_identical_across_processes():
    import hashlib

    here = hashlib.sha256(CModel(scenario_assembly(FIG4)).sources()["pam_model.c"].encode()).hexdigest()
    there = subprocess.run([sys.executable, "-c", GENERATE, str(SCENARIOS / "acra2012_fig4.toml")],
                           capture_output=True, text=True, check=True).stdout.strip()
    assert here == there


LOAD = """
import sys
import pamsim
r = pamsim.simulate(pamsim.load_scenario(sys.argv[1]), backend="native")
print(r.x_m[-1], "casadi" in sys.modules)
"""


def test_the_library_is_built_once_per_structure_and_found_on_disk(tmp_path):
    """Runs that differ in parameter values share one library; another structure gets its own; a new
    process finds the library in the cache folder, without CasADi and without compiling again."""
    heavier = FIG4.with_changes({"load": {"weight_N": 42.74}})
    other = FIG4.with_changes({"model": {"friction": "constant"}})
    a, b, c = (engine_library(scenario_assembly(s)) for s in (FIG4, heavier, other))
    assert a is b and a is not c and a.path != c.path
    env = {**os.environ, "PAMSIM_NATIVE_CACHE": str(tmp_path / "native"), "PAMSIM_CODE_CACHE": str(tmp_path / "code")}
    args = [sys.executable, "-c", LOAD, str(SCENARIOS / "acra2012_fig4.toml")]
    first = subprocess.run(args, env=env, capture_output=True, text=True, check=True).stdout.split()
    libs = sorted((tmp_path / "native" / "engine").glob("*/libpamsim_engine*"))
    assert len(libs) == 1
    built = libs[0].stat().st_mtime_ns
    second = subprocess.run(args, env=env, capture_output=True, text=True, check=True).stdout.split()
    assert first[0] == second[0] and second[1] == "False"
    assert libs[0].stat().st_mtime_ns == built
    assert json.loads((libs[0].parent / "names.json").read_text())["inputs"] == [
        "valve_command", "supply_pressure_gauge_Pa", "external_force_N"]


def test_a_structure_the_engine_cannot_run_is_refused_by_name():
    model = FIG4.build_model()
    assembly = one_muscle_assembly(model)
    with pytest.raises(NotImplementedError, match="at most one hybrid component"):
        CModel(assembly, component="chamber")


@pytest.mark.parametrize("backend", ["python", "native"])
@pytest.mark.parametrize("name", ["fig4", "fig6b", "prescribed step", "start part-way, pressurised"])
def test_result_columns_are_the_generated_outputs(backend, name):
    """The force columns and flows of a python or native result come from the assembly's generated
    outputs; they equal the composed model's breakdown of the same trace, and the forces at rest at the
    end equal its rest forces."""
    scenario = CASES[name]
    res = pamsim.simulate(scenario, backend=backend)
    model = res.model
    sig = res.signals
    rows = [res.x_m, res.v_m_s]
    if model.n_source:
        rows += [res.p_gauge_Pa + model.source.p_atm_Pa, sig["air_mass_kg"]]
    rows += [sig[k] for k in ("W_muscle_J", "E_friction_J", "E_damping_J", "W_external_J")]
    want = model.breakdown(res.t_s, np.array(rows), res.mode)
    checked = 0
    for key, values in want.items():
        if key == "p_gauge_Pa":
            continue
        scale = max(1.0, np.max(np.abs(values)))
        assert np.max(np.abs(sig[key] - values)) <= 1e-9 * scale, key
        checked += 1
    assert checked >= (12 if model.n_source else 7)
    net, level = model.rest_forces(float(res.t_s[-1]), np.array([r[-1] for r in rows]))
    assert res.final_rest_forces_N == pytest.approx((net, level), rel=1e-12, abs=1e-12)


def test_a_batch_of_held_and_exact_cases_gives_each_its_run_alone():
    """One call of cases with different segment counts, some holding their inputs (no ``segment_du``)
    among ones that follow them exactly: the arrays the library is given are laid out per case, so each
    case's samples, events and statistics are those of its run alone, to the bit."""
    from dataclasses import replace

    scenarios = [FIG4, CASES["valve opened, then vented"], CASES["prescribed step"]]
    cases = []
    for scenario in scenarios:
        c = backend.case_inputs(scenario)
        cases.append((scenario_assembly(scenario), c.engine_case(engine_library(c.assembly), 64)))
    fig4_assembly, fig4 = cases[0]
    held = replace(fig4, segment_du=None, segment_t_s=fig4.segment_t_s[:2], segment_u=fig4.segment_u[:2])
    runs = [(fig4_assembly, held), *cases, (fig4_assembly, held)]
    by_library = {}
    for k, (assembly, case) in enumerate(runs):
        by_library.setdefault(id(engine_library(assembly)), []).append(k)
    for members in by_library.values():
        library = engine_library(runs[members[0]][0])
        together = library.run([runs[k][1] for k in members])
        for j, k in enumerate(members):
            alone = library.run([runs[k][1]])
            ns, n = library.layout["ns"], runs[k][1].n_samples
            first = together["sample_offset"][j]
            assert together["status"][j] == alone["status"][0] == 0
            assert np.array_equal(together["samples"][ns * first:ns * (first + n)], alone["samples"][:ns * n])
            assert np.array_equal(together["modes"][first:first + n], alone["modes"][:n])
            e0, m = together["event_offset"][j], int(alone["n_events"][0])
            assert together["n_events"][j] == m and np.array_equal(together["events"][e0:e0 + m], alone["events"][:m])
            assert np.array_equal(together["stats"][j], alone["stats"][0])
            assert np.array_equal(together["extremes"][j], alone["extremes"][0])


def test_a_run_reuses_its_buffer_only_when_nothing_holds_the_last_one():
    """A run's arrays live in one buffer, which the next run reuses only if no array or view of the last
    run's is alive: a kept result is never overwritten, and a dropped one leaves its pages to the next."""
    c = backend.case_inputs(FIG4)
    library = engine_library(c.assembly)
    case = c.engine_case(library, 64)
    first = library.run([case])
    x_view, kept = first["samples"][:100], first["samples"].copy()
    address = first["samples"].ctypes.data
    del first
    heavier = backend.case_inputs(FIG4.with_changes({"load": {"weight_N": 42.74}})).engine_case(library, 64)
    second = library.run([heavier])
    assert second["samples"].ctypes.data != address  # a view of the first run is alive
    assert np.array_equal(x_view, kept[:100])
    assert not np.array_equal(second["samples"], kept)
    address = second["samples"].ctypes.data
    del second, x_view
    third = library.run([case])
    assert third["samples"].ctypes.data == address  # nothing held the second run's arrays
    assert np.array_equal(third["samples"], kept)  # and the run is the first one's, to the bit


class DippingSpeed(Component):
    """A speed ``(t - center)^2 + floor`` [m/s] (a clock and the speed as states), its zero an event whose
    jump sets it to 0.1 m/s: the speed at 1 s tells when the event fired,
    ``center - sqrt(0.1 + (1 - center)^2 - v(1))``."""

    parameters = (Var("center_s", "s"), Var("floor_m_s", "m/s"))
    states = (Var("t_s", "s", "the time", 1.0), Var("v_m_s", "m/s", "the speed", 1e-4))
    outputs = (Var("v_m_s", "m/s"),)
    n_indicators = 1
    indicator_names = ("stop",)

    def equations(self, s):
        from casadi import if_else

        t, v = s.x["t_s"], s.x["v_m_s"]
        return Equations(der={"t_s": 1.0, "v_m_s": 2.0 * (t - s.p["center_s"])}, outputs={"v_m_s": v},
                         indicators=(v,), transition={"v_m_s": if_else(s.fired[0], 0.1, v)},
                         initial={"t_s": 0.0, "v_m_s": s.p["center_s"] ** 2 + s.p["floor_m_s"]})


@pytest.mark.parametrize("center, floor, fires", [(0.3, -0.01, True), (0.56, -0.01, True), (0.3, 0.01, False),
                                                  (0.3, -1e-9, False), (0.3, -1e-5, True)],
                         ids=["parabola", "midpoint", "above zero", "below resolution", "above resolution"])
def test_the_engine_finds_a_zero_that_dips_and_comes_back_inside_one_step(center, floor, fires):
    """The engine on its own, from 0 to 1 s at rtol 1e-2: its steps grow tenfold (Dormand-Prince is exact
    on the quadratic), the last from 0.111 s to 1 s, with the speed positive at both its ends.  Centred at
    0.3 s the dip lies between the step's start and its midpoint (the parabola through the three values
    finds it); at 0.56 s the midpoint is below zero.  The event fires at the analytic zero,
    ``center - sqrt(-floor)``; a dip of 1e-9 m/s, below the speed's absolute tolerance (1e-6 m/s), is no
    event, one of 1e-5 m/s is.  (Before the engine looked into sliding steps, none of them fired.)"""
    assembly = Assembly([DippingSpeed("dip", {"center_s": center, "floor_m_s": floor})], [])
    session = engine_library(assembly).session()
    session.reset(assembly.parameter_values(), [], 1e-2, 10.0, 1000)
    session.advance([], 1.0)
    session.read()
    v_end = session.states[1]
    assert session.stats["events"] == int(fires)
    if fires:
        t_event = center - np.sqrt(0.1 + (1.0 - center) ** 2 - v_end)
        assert abs(t_event - (center - np.sqrt(-floor))) < 1e-9
    else:
        assert abs(v_end - ((1.0 - center) ** 2 + floor)) < 1e-12
