"""The one-muscle FMU generated from components: its parameter map, variables, checks and exact
directional derivatives.  Its runs against the Python simulator are tests/test_fmu.py's.

The FMU's parameters are a muscle's and its run-time choices; the generated model's are its
components'.  The map between them is generated from the elements' own ``from_parameters`` on CasADi
symbols (``pamsim.fmu.muscle_fmu``); here it is held to the assembly built from the same values on floats.
"""

from __future__ import annotations

import numpy as np
import pytest

import pamsim
from conftest import SCENARIOS
from pamsim.fmu.runner import set_values
from pamsim.fmu.variables import VARIABLES, value_reference
from test_fmu import _initialise_with


@pytest.mark.parametrize("name", ["acra2012_fig4", "acra2012_fig4_chou_hannaford", "acra2012_fig6b"])
def test_the_generated_map_gives_the_assemblys_own_parameters(name):
    """pm_kmap at the FMU's start values, evaluated by CasADi, equals the parameters of the assembly built
    from those values on floats, bit for bit (the braid geometry, the upper stop, every law's numbers)."""
    from pamsim.fmu.muscle_fmu import knob_map, muscle_assembly
    from pamsim.fmu.muscle_spec import knob_names
    from pamsim.fmu.preset import for_scenario
    from pamsim.fmu.variables import with_preset

    preset = for_scenario(pamsim.load_scenario(SCENARIOS / f"{name}.toml"))
    rows = {v.name: v for v in with_preset(VARIABLES, preset.table, preset)}
    knobs = knob_names()
    start = {n: float(rows[n].start) for n in knobs}
    assembly = muscle_assembly(start, preset.table)
    names = tuple(v.name for v in assembly.flatten().parameters)
    kmap, _ = knob_map(knobs, names, start, preset.table)
    got = np.array(kmap(np.array([start[n] for n in knobs]))).ravel()
    assert np.array_equal(got, np.array(assembly.parameter_values()))
    # The map moves what depends on a knob: the braid's thread length follows L0_m.
    moved = dict(start, L0_m=start["L0_m"] * 1.01)
    p2 = np.array(kmap(np.array([moved[n] for n in knobs]))).ravel()
    assert p2[names.index("chamber.thread_length_m")] == pytest.approx(
        got[names.index("chamber.thread_length_m")] * 1.01, rel=1e-12)


def test_every_variable_of_the_table_is_there(fmus):
    """Every variable of the one-muscle FMU's table is there, with its value reference and causality."""
    from fmpy import read_model_description

    for v in (2, 3):
        md = {x.name: x for x in read_model_description(str(fmus[v])).modelVariables}
        for row in VARIABLES:
            assert row.name in md, row.name
            assert md[row.name].valueReference == value_reference(row.name), row.name
            assert md[row.name].causality == row.causality, row.name


def test_fmpy_validates_it(fmus):
    from fmpy.validation import validate_fmu

    for v in (2, 3):
        assert validate_fmu(str(fmus[v])) == [], v


def _instance(path, version):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    md = read_model_description(str(path))
    cls = FMU2Slave if version == 2 else FMU3Slave
    fmu = cls(guid=md.guid if version == 2 else md.instantiationToken, unzipDirectory=extract(str(path)),
              modelIdentifier="pamsim_muscle", instanceName="muscle")
    fmu.instantiate()
    return fmu


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
def test_checks_refuse_with_their_messages(unzipped, values, message, capfd):
    """The generated checks, with the messages the FMU has always given (the upper stop of the braid lock,
    0.1157 m, computed by the generated map)."""
    for v in (2, 3):
        capfd.readouterr()
        assert _initialise_with(unzipped, v, values) != 0
        log = capfd.readouterr().out
        assert message in log, log
    assert _initialise_with(unzipped, 2, {}) == 0


@pytest.mark.parametrize("name, value, message", [
    ("supply_pressure_gauge_Pa", 5e5, "supply_pressure_gauge_Pa = 500000 Pa: exceeds the muscle's rating"),
    ("prescribed_pressure_gauge_Pa", -2e5, "prescribed_pressure_gauge_Pa = -200000 Pa: below vacuum"),
    ("prescribed_pressure_gauge_Pa", 4.6e5, "prescribed_pressure_gauge_Pa = 460000 Pa: exceeds the muscle's rating"),
])
def test_inputs_beyond_the_rating_are_refused_when_set(fmus, name, value, message, capfd):
    from fmpy.fmi1 import FMICallException

    for path in (fmus[2],):
        fmu = _instance(path, 2)
        capfd.readouterr()
        with pytest.raises(FMICallException):
            fmu.setReal([value_reference(name)], [value])
        assert message in capfd.readouterr().out
        fmu.setReal([value_reference(name)], [1e5])  # within the rating: taken
        fmu.freeInstance()


def test_directional_derivatives_are_exact(fmus):
    """d der(velocity) / d contraction while sliding, against a central difference of the Python model, and
    d der(velocity) / d load_mass_kg (an input that the map turns into a parameter) likewise."""
    from pamsim.fmu.runner import ScenarioInputs

    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    fmu = _instance(fmus[2], 2)
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
