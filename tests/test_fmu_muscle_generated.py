"""The one-muscle FMU generated from components against the one whose model is written by hand in C.

Both FMUs have the same variables (names, value references, ranges, choices); they share no model
code: one runs ``pam_core.c``, the other the generic core with the generated model and the generated
parameter map (``pamsim.fmu.muscle_fmu``).  Co-simulation runs the same integrator on both, so they must
agree to rounding; Model Exchange runs fmpy's CVode over 8 states instead of 4 (the generated model adds
the work integrals), so to its tolerance.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import pamsim
from conftest import PAPER_SCENARIOS, SCENARIOS
from pamsim.fmu.runner import run_cs, run_me, set_values
from pamsim.fmu.variables import BY_NAME, VARIABLES, value_reference
from test_fmu import INITIAL_PRESSURE, OTHER_CHOICES

CS_AGREE_M = 1e-9
"""Co-simulation, generated against hand-written: the same integrator on the same equations (measured
8e-17 m on fig4); the bound leaves room for the order of floating-point operations to differ."""
ME_AGREE_M = 0.05e-3
"""Model Exchange: fmpy's CVode at its default tolerance over 8 states against 4 (measured 3.1e-7 m on fig4,
1.9e-5 m on the prescribed lag): the bound test_fmu holds either core's final contraction to against Python."""


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """{FMI version: path} of the generated one-muscle FMU (no preset: the FMU's own defaults)."""
    from pamsim.fmu.muscle_spec import build_generated

    root = tmp_path_factory.mktemp("generated")
    return {v: build_generated(root / f"muscle_generated_fmi{v}.fmu", v) for v in (2, 3)}


def _scenarios():
    out = {name: pamsim.load_scenario(SCENARIOS / f"{name}.toml") for name in PAPER_SCENARIOS}
    out.update({case: pamsim.Scenario.from_dict(tomllib.loads(text), name=case) for case, text in OTHER_CHOICES.items()})
    out["initial_pressure"] = pamsim.Scenario.from_dict(tomllib.loads(INITIAL_PRESSURE), name="initial_pressure")
    out["fig6b_abs"] = out["acra2012_fig6b"].with_changes({"model": {"friction_negative_level": "abs"}})
    return out


SCENARIO_CASES = _scenarios()


def test_the_variables_are_the_hand_written_fmus(generated):
    """Every variable of the hand-written FMU is there, with its value reference, kind, causality and range."""
    from fmpy import read_model_description

    for v in (2, 3):
        md = {x.name: x for x in read_model_description(str(generated[v])).modelVariables}
        for row in VARIABLES:
            assert row.name in md, row.name
            assert md[row.name].valueReference == value_reference(row.name), row.name
            assert md[row.name].causality == row.causality, row.name


def test_fmpy_validates_it(generated):
    from fmpy.validation import validate_fmu

    for v in (2, 3):
        assert validate_fmu(str(generated[v])) == [], v


@pytest.mark.parametrize("name", sorted(SCENARIO_CASES))
def test_co_simulation_equals_the_hand_written_core(fmus, generated, name):
    sc = SCENARIO_CASES[name]
    for v in (2, 3):
        mine, theirs = run_cs(sc, v, fmu_path=generated[v]), run_cs(sc, v, fmu_path=fmus[v])
        assert np.max(np.abs(mine["contraction_m"] - theirs["contraction_m"])) <= CS_AGREE_M
        assert np.array_equal(mine["friction_mode"], theirs["friction_mode"])
        assert np.max(np.abs(mine["p_gauge_Pa"] - theirs["p_gauge_Pa"])) <= 1e-3


@pytest.mark.parametrize("name", sorted(SCENARIO_CASES))
def test_model_exchange_agrees_with_the_hand_written_core_and_python(fmus, generated, name):
    sc = SCENARIO_CASES[name]
    mine, theirs = run_me(sc, 2, fmu_path=generated[2]), run_me(sc, 2, fmu_path=fmus[2])
    assert np.max(np.abs(mine["contraction_m"] - theirs["contraction_m"])) <= ME_AGREE_M
    ref = pamsim.simulate(sc)
    assert np.max(np.abs(mine["contraction_m"] - ref.x_m)) <= 0.2e-3  # test_fmu.MAX_DIFF_M


def _instance(path, version):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    md = read_model_description(str(path))
    cls = FMU2Slave if version == 2 else FMU3Slave
    fmu = cls(guid=md.guid if version == 2 else md.instantiationToken, unzipDirectory=extract(str(path)),
              modelIdentifier="pamsim_muscle", instanceName="generated")
    fmu.instantiate()
    return fmu


def _initialise(path, version, values):
    """Set ``values``, initialise; the status of exitInitializationMode (0 OK, 3 error)."""
    from fmpy.fmi1 import FMICallException

    fmu = _instance(path, version)
    try:
        set_values(fmu, version, {n: int(x) if BY_NAME[n].kind == "integer" else float(x) for n, x in values.items()})
        if version == 2:
            fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        try:
            fmu.exitInitializationMode()
            return 0
        except FMICallException as exc:
            return exc.status
    finally:
        fmu.freeInstance()


@pytest.mark.parametrize("values, message", [
    ({"release_margin_N": 1e-8}, "release_margin_N = 1e-08: must be above stick_margin_N = 1e-07"),
    ({"initial_pressure_gauge_Pa": 5e5},
     "initial_pressure_gauge_Pa = 500000: must be at most rated_pressure_gauge_Pa = 450000"),
    ({"initial_contraction_m": 0.12}, "initial_contraction_m = 0.12: must lie between the stops, 0 and 0.1157 m"),
    ({"x_high_m": 0.5}, "x_high_m = 0.5: the upper stop must be below the rest length L0_m = 0.3"),
    ({"x_high_m": 0.05, "initial_contraction_m": 0.06}, "initial_contraction_m = 0.06: must lie between the stops, "
     "0 and 0.0500 m"),
    ({"static_force_model": 1}, "static_force_model = 1 (table): this FMU was built without a force table"),
    ({"fit_x_min_m": 0.2}, "fit_x_min_m = 0.2: must be below fit_x_max_m"),
])
def test_checks_refuse_what_the_hand_written_core_refuses(generated, fmus, values, message, capfd):
    """The generated checks give the hand-written core's messages (the upper stop of the braid lock,
    0.1157 m, computed by the generated map)."""
    from fmpy import extract

    from test_fmu import _initialise_with

    for v in (2, 3):
        capfd.readouterr()
        assert _initialise_with({v: extract(str(fmus[v]))}, v, values) != 0
        assert message in capfd.readouterr().out
        assert _initialise(generated[v], v, values) != 0
        log = capfd.readouterr().out
        assert message in log, log
    assert _initialise(generated[2], 2, {}) == 0


@pytest.mark.parametrize("name, value, message", [
    ("supply_pressure_gauge_Pa", 5e5, "supply_pressure_gauge_Pa = 500000 Pa: exceeds the muscle's rating"),
    ("prescribed_pressure_gauge_Pa", -2e5, "prescribed_pressure_gauge_Pa = -200000 Pa: below vacuum"),
    ("prescribed_pressure_gauge_Pa", 4.6e5, "prescribed_pressure_gauge_Pa = 460000 Pa: exceeds the muscle's rating"),
])
def test_inputs_beyond_the_rating_are_refused_when_set(generated, fmus, name, value, message, capfd):
    from fmpy.fmi1 import FMICallException

    for path in (fmus[2], generated[2]):
        fmu = _instance(path, 2)
        capfd.readouterr()
        with pytest.raises(FMICallException):
            fmu.setReal([value_reference(name)], [value])
        assert message in capfd.readouterr().out
        fmu.setReal([value_reference(name)], [1e5])  # within the rating: taken
        fmu.freeInstance()


def test_directional_derivatives_are_exact(generated):
    """d der(velocity) / d contraction while sliding, against a central difference of the Python model, and
    d der(velocity) / d load_mass_kg (an input that the map turns into a parameter) likewise."""
    from pamsim.fmu.runner import ScenarioInputs

    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    fmu = _instance(generated[2], 2)
    inputs = ScenarioInputs(sc)
    set_values(fmu, 2, {"supply_pressure_gauge_Pa": 3.6e5, "valve_command": 1.0, "load_mass_kg": sc.mass_kg})
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    t = 0.0
    while t < 0.25 - 1e-12:
        fmu.doStep(t, 1e-3)
        t += 1e-3
    mode = fmu.getInteger([value_reference("friction_mode")])[0]
    assert mode in (1, -1)
    x, v, p, m = fmu.getReal([value_reference(n) for n in ("contraction_m", "velocity_m_s", "chamber_pressure_abs_Pa",
                                                            "air_mass_kg")])
    dd = lambda known: fmu.getDirectionalDerivative([value_reference("der(velocity_m_s)")],  # noqa: E731
                                                    [value_reference(known)], [1.0])[0]
    model = sc.build_model()
    source = model.source
    del inputs

    def acc(xx=x, mass=sc.mass_kg):
        mdl = sc.with_changes({"load": {"weight_N": mass * model.load.g_m_s2}}).build_model()
        return mdl.slip_rhs(np.array([xx, v, p, m, 0, 0, 0, 0]), float(mode), source.inputs(2.0), 0.0)[1]

    h = 1e-6
    assert dd("contraction_m") == pytest.approx((acc(xx=x + h) - acc(xx=x - h)) / (2 * h), rel=1e-6)
    hm = 1e-5
    assert dd("load_mass_kg") == pytest.approx((acc(mass=sc.mass_kg + hm) - acc(mass=sc.mass_kg - hm)) / (2 * hm),
                                               rel=1e-6)
    fmu.terminate()
    fmu.freeInstance()
