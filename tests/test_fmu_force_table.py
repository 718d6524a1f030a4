"""A static force reaches the FMU as a table F(x, p) baked in at build time and interpolated by one
C routine; the ACRA 2012 polynomial stays exact in C.  References: the exact-polynomial FMU, the
tabulated model itself evaluated in Python, and pamsim.simulate with the same model."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

import pamsim
from conftest import SCENARIOS
from pamsim.fmu import build
from pamsim.fmu.force_table import tabulate
from pamsim.fmu.runner import force_table_for, run_cs, run_me, set_values
from pamsim.fmu.variables import value_reference
from pamsim.muscles import load_muscle
from test_fmu import _Api, _initialise_with, _instance, _start_fig4, n_states

RATED_PA = 4.5e5
X_HIGH_M = 0.1157  # the braid-lock stop of the Shadow muscle (test_fmu: "between the stops, 0 and 0.1157 m")


class SmoothForce:
    """A static force that is not polynomial in x or p (so the table cannot be exact):
    72 N of blocked force at 3.6 bar, falling exponentially with contraction, against a tanh spring."""

    name = "smooth_test_force"

    @classmethod
    def from_parameters(cls, params, options=None):
        return cls()

    def force_N(self, x_m, p_gauge_Pa):
        x, p = np.asarray(x_m, dtype=float), np.asarray(p_gauge_Pa, dtype=float)
        return 1.2e-4 * p * np.exp(-x / 0.035) * np.sqrt(1.0 + p / 2e5) - 8.0 * np.tanh(x / 0.02)


def _forces_through_fmu(path, version, x, p):
    """F_static_N of the FMU at each (x, p gauge), set as Model Exchange states."""
    fmu = _instance({version: path}, version, "me")
    api = _Api(fmu, version)
    api.init()
    fmu.newDiscreteStates() if version == 2 else fmu.updateDiscreteStates()
    fmu.enterContinuousTimeMode()
    out = []
    y = np.zeros(n_states(path))  # the model's four states, then its work integrals (at 0)
    for xi, pi in zip(x, p):
        y[:4] = [xi, 0.0, pi + 101325.0, 1e-5]
        fmu.setContinuousStates(y.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), len(y))
        out.append(api.get("F_static_N")[0])
    fmu.terminate()
    fmu.freeInstance()
    return np.array(out)


@pytest.fixture(scope="module")
def smooth_fmus(tmp_path_factory):
    folder = tmp_path_factory.mktemp("table")
    table = tabulate(SmoothForce(), (0.0, X_HIGH_M), (0.0, RATED_PA))
    return {v: build(folder / f"smooth{v}.fmu", v, table) for v in (2, 3)}


@pytest.mark.parametrize("version", [2, 3])
def test_interpolation_error_within_a_thousandth_of_the_blocked_force(smooth_fmus, version):
    rng = np.random.default_rng(8)
    x = rng.uniform(0.0, X_HIGH_M, 400)
    p = rng.uniform(0.0, RATED_PA, 400)
    model = SmoothForce()
    blocked = float(model.force_N(0.0, RATED_PA))
    expected = np.maximum(model.force_N(x, p), 0.0)  # the C core clips a negative force, as the dynamics do
    error = np.abs(_forces_through_fmu(smooth_fmus[version], version, x, p) - expected)
    assert error.max() <= 1e-3 * blocked, f"{error.max():.3g} N against {1e-3 * blocked:.3g} N"
    # The criterion can fail: a 5 x 3 table of the same model, not refined, misses it.
    coarse = build(smooth_fmus[version].with_name(f"coarse{version}.fmu"), version,
                   tabulate(model, (0.0, X_HIGH_M), (0.0, RATED_PA), points=(5, 3), refine=False))
    assert np.abs(_forces_through_fmu(coarse, version, x, p) - expected).max() > 1e-3 * blocked


@pytest.mark.parametrize("version", [2, 3])
def test_tabulated_polynomial_runs_as_the_exact_polynomial(tmp_path, version):
    """Fig. 4 in co-simulation on the polynomial's table and on the exact polynomial (one FMU, both
    choices): the bicubic table reproduces a force cubic in x and p, so the runs agree."""
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    # Over the whole travel and rating (its fit range, tabulate_model's domain, is narrower: the load rises past it).
    travel = (0.0, sc.build_model().stops.x_high_m)
    table = tabulate(sc.static_model(), travel, (0.0, sc.parameters["rated_pressure_gauge_Pa"]),
                     model_name="acra2012_polynomial")
    path = build(tmp_path / "poly_table.fmu", version, table)
    runs = {}
    for choice in (0, 1):
        fmu = _instance({version: path}, version)
        api = _Api(fmu, version)
        set_values(fmu, version, {"static_force_model": choice})
        _start_fig4(api)
        api.init()
        x = []
        for k in range(80):
            api.step(k * 0.1, 0.1)
            x.append(api.get("contraction_m", "F_static_N"))
        runs[choice] = np.array(x)
        fmu.terminate()
        fmu.freeInstance()
    assert runs[0][-1, 0] > 0.05  # the load rose
    # Equal up to the rounding of the node derivatives (finite differences): 1e-8 of the blocked force.
    dx, dF = np.max(np.abs(runs[0] - runs[1]), axis=0)
    assert dx <= 1e-8 and dF <= 1e-6, (dx, dF)


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("choice,message", [
    (1, "static_force_model = 1 (table): this FMU was built without a force table"),
    (2, "static_force_model = 2: must lie in [0, 1]"),  # a choice the C core does not have at all
])
def test_fmu_without_a_table_refuses_the_table_choice(unzipped, version, choice, message, capfd):
    capfd.readouterr()
    assert _initialise_with(unzipped, version, {"static_force_model": choice}) == 3
    assert message in capfd.readouterr().out


def _kothera_energy_scenario():
    """Kothera's actuator 5a with its energy model (K-4), 10 N stepped to 3.6 bar, 3 s."""
    return pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes(
        {"model": {"muscle": "kothera2009_5a", "static_force": "kothera_energy"}, "load": {"weight_N": 10.0},
         "simulation": {"duration_s": 3.0}}, name="kothera_5a_energy")


@pytest.mark.parametrize("interface", ["cs", "me"])
@pytest.mark.parametrize("model", ["chou_hannaford", "kothera_energy"])
def test_scenario_with_another_static_model_runs_on_its_table_like_python(interface, model):
    """The runner tabulates a scenario's non-polynomial static force, builds the FMU with the table
    and starts it on the table; the run matches pamsim.simulate within 0.2 mm."""
    sc = (pamsim.load_scenario(SCENARIOS / "acra2012_fig4_chou_hannaford.toml") if model == "chou_hannaford"
          else _kothera_energy_scenario())
    table = force_table_for(sc)
    assert table is not None and table.model_name == model
    assert force_table_for(pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")) is None
    ref = pamsim.simulate(sc)
    assert ref.x_m.max() > 0.005  # the load moved (11.6 mm on Kothera 5a, 95 mm on the Shadow)
    tr = run_cs(sc, 2) if interface == "cs" else run_me(sc, 2)
    assert np.allclose(tr["t_s"], ref.t_s, atol=1e-9)
    d = np.abs(tr["contraction_m"] - ref.x_m)
    assert d.max() <= 0.2e-3, f"max contraction difference {d.max() * 1e3:.4f} mm"


def test_cli_builds_a_table_fmu_from_a_scenario(tmp_path):
    """A scenario's static force other than the polynomial is baked in as a table; the polynomial stays exact
    (its table would end at its fit range, which the load rises past)."""
    from conftest import run_main
    from fmpy import read_model_description

    out = run_main("fmu", "build", "--scenario", SCENARIOS / "acra2012_fig4_chou_hannaford.toml",
                   "-o", tmp_path / "t.fmu")
    assert out.returncode == 0, out.stderr
    assert "table of chou_hannaford" in out.stdout
    md = read_model_description(str(tmp_path / "t.fmu"))
    start = {v.name: v.start for v in md.modelVariables}
    assert start["static_force_model"] == "1"
    assert value_reference("static_force_model") == 63
    exact = run_main("fmu", "build", "--scenario", SCENARIOS / "acra2012_fig4.toml", "-o", tmp_path / "p.fmu")
    assert exact.returncode == 0, exact.stderr
    assert "the ACRA 2012 polynomial, exact" in exact.stdout
    start = {v.name: v.start for v in read_model_description(str(tmp_path / "p.fmu")).modelVariables}
    assert start["static_force_model"] == "0"


def test_cli_builds_a_table_fmu_from_a_muscle_and_model(tmp_path):
    from conftest import run_main

    out = run_main("fmu", "build", "--muscle", "kothera2009_5a", "--static-force", "kothera_energy",
                  "-o", tmp_path / "k.fmu")
    assert out.returncode == 0, out.stderr
    assert "table of kothera_energy" in out.stdout
    # The baked table has the shape of the one the runner makes for a scenario with that muscle and model.
    runner_table = force_table_for(_kothera_energy_scenario())
    assert f"{runner_table.shape[0]} x {runner_table.shape[1]} table" in out.stdout
    bad = run_main("fmu", "build", "--muscle", "kothera2009_5a", "--static-force", "kothera_enrgy",
                  "-o", tmp_path / "bad.fmu")
    assert bad.returncode == 2 and "kothera_enrgy" in bad.stderr and "Traceback" not in bad.stderr
    assert not (tmp_path / "bad.fmu").exists()
    lone = run_main("fmu", "build", "--static-force", "kothera_energy", "-o", tmp_path / "lone.fmu")
    assert lone.returncode == 2 and "--muscle" in lone.stderr
    # Without --static-force: the muscle's default_static_force, as every other command takes it.
    default = run_main("fmu", "build", "--muscle", "kothera2009_5a", "-o", tmp_path / "default.fmu")
    assert default.returncode == 0, default.stderr
    assert f"table of {load_muscle('kothera2009_5a').default_static_force}" in default.stdout


@pytest.mark.parametrize("version", [2, 3])
def test_table_choice_without_a_table_reads_nan_during_initialisation(fmus, version):
    """Before the choice is refused (at the end of initialisation), a derivative read evaluates the
    model: the missing table gives NaN, not a read outside the table's memory."""
    fmu = _instance(fmus, version, "me")
    set_values(fmu, version, {"static_force_model": 1, "initial_contraction_m": 0.02})
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    n = n_states(fmus[version])
    dx = np.zeros(n)
    get = fmu.getDerivatives if version == 2 else fmu.getContinuousStateDerivatives
    get(dx.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)  # evaluates the model, outputs included
    assert np.isnan(_Api(fmu, version).get("F_static_N")[0])
    fmu.freeInstance()


# ------------------------------------------------------------------ the table is never extrapolated


def _muscle_preset(muscle, model=None):
    """The preset of ``pamsim fmu build --muscle muscle [--static-force model]``, with its force table."""
    from pamsim.fmu.preset import for_muscle

    spec = {"model": {"muscle": muscle, **({"static_force": model} if model else {})}, "load": {"weight_N": 1.0},
            "pressure": {"source": "valve", "supply_gauge_bar": 0.0, "valve_open_time_s": 0.0},
            "simulation": {"duration_s": 1.0}}
    preset = for_muscle(pamsim.Scenario.from_dict(spec))
    assert preset.table is not None
    return preset


def _refused(path, start_values):
    from fmpy import simulate_fmu
    from fmpy.fmi1 import FMICallException

    with pytest.raises(FMICallException):
        simulate_fmu(str(path), stop_time=0.1, start_values=start_values)


def test_a_table_fmu_refuses_a_travel_beyond_its_table(tmp_path, capfd):
    """The survey's 40 mm muscle's table covers its own travel, to 28.40 mm; the Shadow muscle's
    geometry (the FMU's old start values) travels to 115.68 mm and is refused at initialisation."""
    from fmpy import simulate_fmu

    from pamsim.elements.stops import EndStops
    from pamsim.parameters import get_parameter_set

    preset = _muscle_preset("mpam_survey_40mm")
    table = preset.table
    path = build(tmp_path / "survey40.fmu", 2, preset=preset)
    shadow = get_parameter_set("shadow_6x300_acra2012")
    capfd.readouterr()
    # The Shadow muscle's geometry, its stop the braid lock derived from it (x_high_m = 0).
    _refused(path, {**{n: shadow[n] for n in ("L0_m", "r0_m", "theta0_deg")}, "x_high_m": 0.0})
    log = capfd.readouterr().out
    travel = EndStops.from_parameters(shadow).x_high_m
    assert (f"invalid parameters: L0_m = {shadow['L0_m']:g}, theta0_deg = {shadow['theta0_deg']:g}, x_high_m = 0: "
            f"the load's travel, 0 to {travel:.6g} m (the upper stop), leaves the force table of "
            f"{table.model_name}, which covers contraction 0 to {table.x_max_m:.6g} m") in log
    # Its own geometry and stop (the end of eq. 33's domain, inside the table): at 7.58 bar the load
    # rises past the braid lock and comes to rest where the python model has it.
    res = simulate_fmu(str(path), stop_time=2.0, start_values={
        "valve_command": 1.0, "supply_pressure_gauge_Pa": 7.58e5, "load_mass_kg": 0.005})
    lock = EndStops.from_parameters(get_parameter_set("mpam_survey_40mm")).x_high_m
    ref = pamsim.simulate(pamsim.Scenario.from_dict({
        "model": {"muscle": "mpam_survey_40mm"}, "load": {"mass_kg": 0.005},
        "pressure": {"source": "valve", "supply_gauge_Pa": 7.58e5, "valve_open_time_s": 0.0},
        "simulation": {"duration_s": 2.0}}))
    assert ref.x_m[-1] > lock and res["contraction_m"][-1] == pytest.approx(ref.x_m[-1], abs=1e-5)
    assert "left the force table" not in capfd.readouterr().out


@pytest.mark.parametrize("muscle,model", [("kothera2009_2b", None), ("kothera2009_5a", "kothera_energy")])
def test_a_table_fmu_refuses_pressures_beyond_its_table(tmp_path, capfd, muscle, model):
    """Kothera's actuators are rated (and tabulated) to 60 psi, 4.14 bar: a 4.4 bar supply is refused
    as above the rating, and a rating raised past the table at initialisation."""
    from fmpy import simulate_fmu

    preset = _muscle_preset(muscle, model)
    table, rating = preset.table, preset.starts["rated_pressure_gauge_Pa"]
    assert table.p_max_Pa == rating
    path = build(tmp_path / "k.fmu", 2, preset=preset)
    capfd.readouterr()
    _refused(path, {"supply_pressure_gauge_Pa": 4.4e5})
    assert (f"supply_pressure_gauge_Pa = 440000 Pa: exceeds the muscle's rating rated_pressure_gauge_Pa = "
            f"{rating:g} Pa") in capfd.readouterr().out
    _refused(path, {"rated_pressure_gauge_Pa": 4.5e5, "supply_pressure_gauge_Pa": 4.4e5})
    assert (f"invalid parameters: rated_pressure_gauge_Pa = 450000: above the force table of {table.model_name}, "
            f"which covers gauge pressure 0 to {table.p_max_Pa:g} Pa") in capfd.readouterr().out
    # At its rating the chamber overshoots the supply a little as the load swings back: held at the
    # table's edge, too little to report.
    res = simulate_fmu(str(path), stop_time=2.0, start_values={
        "valve_command": 1.0, "supply_pressure_gauge_Pa": rating, "load_mass_kg": 0.5})
    assert res["p_gauge_Pa"].max() <= rating + 1e-2 * (table.p_max_Pa - table.p_min_Pa)
    assert "left the force table" not in capfd.readouterr().out


def test_a_pressure_beyond_the_table_takes_the_edge_force(smooth_fmus):
    """A load yanked down compresses the chamber far above the supply (the table's top): the force is
    the table's value at its edge, the model's own there, not the edge cell's cubic carried on."""
    from fmpy import simulate_fmu

    names = ("time", "valve_command", "supply_pressure_gauge_Pa", "load_mass_kg", "external_force_N")
    rows = [(0.0, 1.0, RATED_PA, 1.0, 0.0), (1.0, 1.0, RATED_PA, 1.0, 0.0), (1.0, 1.0, RATED_PA, 1.0, -300.0),
            (2.0, 1.0, RATED_PA, 1.0, -300.0)]
    res = simulate_fmu(str(smooth_fmus[2]), stop_time=2.0, output_interval=1e-3, validate=False,
                       input=np.array(rows, dtype=[(n, float) for n in names]),
                       output=["contraction_m", "p_gauge_Pa", "F_static_N"])
    k = int(np.argmax(res["p_gauge_Pa"]))
    x, p = res["contraction_m"][k], res["p_gauge_Pa"][k]
    assert p > 1.5 * RATED_PA
    model = SmoothForce()
    edge = max(float(model.force_N(x, RATED_PA)), 0.0)
    assert res["F_static_N"][k] == pytest.approx(edge, abs=1e-3 * float(model.force_N(0.0, RATED_PA)))
    assert abs(float(model.force_N(x, p)) - edge) > 10.0  # extrapolating would have told another story


def test_a_table_fmu_says_which_model_it_tabulates(smooth_fmus, fmus, tmp_path):
    from fmpy import read_model_description

    from pamsim.fmu.generate import DESCRIPTION
    from pamsim.static_models import REGISTRY

    smooth = read_model_description(str(smooth_fmus[2])).description
    assert "static force polynomial" not in smooth and "static force smooth_test_force, tabulated" in smooth
    preset = _muscle_preset("kothera2009_5a", "kothera_energy")
    table = preset.table
    kothera = read_model_description(str(build(tmp_path / "k.fmu", 3, preset=preset))).description
    spec = REGISTRY["kothera_energy"]
    assert f"static force kothera_energy ({spec.summary}; {spec.source}), tabulated" in kothera
    assert f"over contraction 0 to {table.x_max_m * 1e3:g} mm and gauge pressure 0 to {table.p_max_Pa:g} Pa" in kothera
    assert "static force polynomial" not in kothera and kothera.endswith("built for muscle kothera2009_5a")
    assert read_model_description(str(fmus[2])).description == DESCRIPTION
