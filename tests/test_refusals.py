"""Bad input is refused with the one-line message that names the key and the value, and the first of two
mistakes is the one reported.

The tables hold the exact messages (the scenario's ``[controller]``, the RL environment's arguments, a force-map
CSV, ``pamsim atlas``'s muscle, models and pressures, a measured-point file, a muscle file and its parameter
entries, a signal table, a trace CSV, an assembly's signal wiring, ``pamsim fmu build``'s options, an
identification measurement file and an uncertainty study's distribution), so a change in what is checked, in which
order, or in how it is said fails here. The messages are those that were given before the checks were split into
small functions; the other test files check parts of most of them.
"""

from __future__ import annotations

import copy
import math
import tomllib

import pytest

import pamsim
from conftest import SCENARIOS
from pamsim.atlas import build_atlas, measured_points
from pamsim.control.closed_loop import ControllerConfig
from pamsim.errors import InputError
from pamsim.modeling import Assembly, AssemblyError, Var
from pamsim.muscles import MuscleError, muscle_from_dict
from pamsim.static_models.force_map import ForceMapError, read_force_map
from test_modeling import Body, FloatForce, Gain, Spring

CLOSED_LOOP = tomllib.loads((SCENARIOS / "closed_loop_position.toml").read_text())
FIG4 = tomllib.loads((SCENARIOS / "acra2012_fig4.toml").read_text())
SPRING = tomllib.loads((SCENARIOS / "parallel_spring.toml").read_text())
SHADOW = tomllib.loads((pamsim.muscles.load_muscle("shadow_6x300_acra2012").origin).read_text())


def _message(err: pytest.ExceptionInfo, tmp_path=None) -> str:
    text = str(err.value)
    assert "\n" not in text
    return text.replace(str(tmp_path), "TMP") if tmp_path else text


# ----------------------------------------------------------------------------- [controller]
_CONTROL_SPEC = ("rise_time_max_s, overshoot_max_percent, settling_time_max_s, settling_band_mm, "
                 "steady_state_error_max_mm")


def _controller(changes=None, drop=(), spec=None, table=None, top=None) -> ControllerConfig:
    scenario = copy.deepcopy(CLOSED_LOOP)
    if table is not None:
        scenario["controller"] = table
    else:
        scenario["controller"].update(changes or {})
    for key in drop:
        scenario["controller"].pop(key)
    if spec is not None:
        scenario["controller"]["spec"] = spec
    scenario.update(top or {})
    if table == "none":
        del scenario["controller"]
    return ControllerConfig.from_scenario(pamsim.Scenario.from_dict(scenario, base_dir=SCENARIOS, origin="cl.toml"))


@pytest.mark.parametrize("kwargs, message", [
    ({"table": "none"}, "missing table [controller] (see docs/control.md)"),
    ({"changes": {"gain": 1.0}}, "unknown key controller.gain (known: kind, target_contraction_mm, step_time_s, "
     "design_contraction_mm, max_position_error_mm, max_velocity_mm_s, max_pressure_error_bar, max_integral_mm_s, "
     "max_command, velocity_filter_time_s, integrator_deadband_mm, antiwindup_time_s, spec)"),
    ({"changes": {"kind": "pid"}}, "controller.kind = 'pid': only 'lqr_integral' is implemented"),
    ({"drop": ("antiwindup_time_s",)}, "missing key controller.antiwindup_time_s"),
    # a missing key before a bad one later in the table's order
    ({"drop": ("target_contraction_mm",), "changes": {"max_velocity_mm_s": -1}},
     "missing key controller.target_contraction_mm"),
    ({"changes": {"max_velocity_mm_s": -1, "target_contraction_mm": "x"}},
     "controller.target_contraction_mm = 'x': must be a number, not a string"),
    ({"changes": {"max_command": True}}, "controller.max_command = true: must be a number, not a boolean"),
    ({"changes": {"max_command": math.nan}}, "controller.max_command = nan: must be a finite number"),
    ({"changes": {"max_command": [1]}}, "controller.max_command = [1]: must be a number, not a list"),
    ({"changes": {"max_command": 0}}, "controller.max_command = 0: must be positive"),
    ({"changes": {"integrator_deadband_mm": -1.0}}, "controller.integrator_deadband_mm = -1.0: must be positive"),
    ({"spec": 3}, f"controller.spec must be a table with keys from {_CONTROL_SPEC}"),
    ({"spec": {"rise_time_s": 1.0}}, f"controller.spec must be a table with keys from {_CONTROL_SPEC}"),
    ({"spec": {"rise_time_max_s": True}}, "controller.spec.rise_time_max_s = true: must be a number, not a boolean"),
    ({"spec": {"settling_band_mm": "x"}}, "controller.spec.settling_band_mm = 'x': must be a number, not a string"),
    ({"spec": {"rise_time_max_s": 0}}, "controller.spec.rise_time_max_s = 0: must be positive"),
    ({"changes": {"step_time_s": 3.0}}, "controller.step_time_s = 3: must lie inside the simulation (0, 3) s"),
    # the spec is checked before the step time
    ({"changes": {"step_time_s": 5}, "spec": {"x": 1}}, f"controller.spec must be a table with keys from {_CONTROL_SPEC}"),
    ({"top": {"component": SPRING["component"]}}, "component: the closed loop's controller design takes the rig "
     "alone, not the components added to it ('spring'); run the scenario with `pamsim run` (python or native backend)"),
])
def test_a_bad_controller_table_is_refused_naming_the_key(kwargs, message):
    with pytest.raises(InputError) as err:
        _controller(**kwargs)
    assert _message(err) == f"cl.toml: {message}"


def test_the_controller_table_is_read_in_si_with_its_defaults():
    config = _controller(drop=("max_command", "integrator_deadband_mm", "spec", "kind"))
    # closed_loop_position.toml: 40 mm, 0.2 bar, 50 mm/s, 0.3 mm s; the defaults: command 1, no deadband
    assert config.target_contraction_m == pytest.approx(0.040, rel=1e-15)
    assert config.max_pressure_error_Pa == pytest.approx(0.2e5, rel=1e-15)
    assert config.max_velocity_m_s == pytest.approx(0.050, rel=1e-15)
    assert config.max_integral_m_s == pytest.approx(0.3e-3, rel=1e-15)
    assert (config.max_command, config.integrator_deadband_m, dict(config.spec)) == (1.0, 0.0, {})
    assert _controller({"integrator_deadband_mm": 0}).integrator_deadband_m == 0.0


# ----------------------------------------------------------------------------- MusclePosition-v0
def _fig4(**sections) -> pamsim.Scenario:
    spec = copy.deepcopy(FIG4)
    for section, values in sections.items():
        spec[section] = values if section == "pressure" else {**spec[section], **values}
    return pamsim.Scenario.from_dict(spec, base_dir=SCENARIOS, origin="s.toml")


@pytest.mark.parametrize("kwargs, message", [
    # the first argument in the signature's order is named
    ({"render_mode": "rgb", "command": "x"}, "render_mode = 'rgb': MusclePosition-v0 renders nothing (render_modes: [])"),
    ({"command": "force", "backend": "fmu"}, "command = 'force': must be one of 'valve', 'pressure'"),
    ({"backend": "fmu", "weight_N": 1.0, "mass_kg": 1.0}, "backend = 'fmu': must be one of 'native', 'python'"),
    ({"weight_N": 1.0, "mass_kg": 1.0, "control_rate_Hz": -1}, "weight_N and mass_kg: give at most one of the two"),
    ({"control_rate_Hz": "a"}, "control_rate_Hz = 'a': must be a positive number"),
    ({"control_rate_Hz": math.inf}, "control_rate_Hz = inf: must be a positive finite number"),
    ({"episode_duration_s": None}, "episode_duration_s = None: must be a positive number"),
    ({"episode_duration_s": -1.0, "reference_margin": 2}, "episode_duration_s = -1.0: must be a positive finite number"),
    ({"episode_duration_s": 0.004}, "episode_duration_s = 0.004: shorter than one control step "
     "(1 / control_rate_Hz = 0.01 s)"),
    ({"reference_margin": True}, "reference_margin = True: must lie in [0, 0.5)"),
    ({"reference_margin": "a"}, "reference_margin = 'a': must lie in [0, 0.5)"),
    ({"reference_margin": -0.1, "scenario": 5}, "reference_margin = -0.1: must lie in [0, 0.5)"),
    ({"scenario": 5}, "scenario = 5: must be a scenario file's path or a pamsim.Scenario"),
    ({"supply_gauge_Pa": [1]}, "supply_gauge_Pa = [1]: must be a positive number"),
    ({"supply_gauge_Pa": 0.0}, "supply_gauge_Pa = 0.0: must be a positive finite number"),
    ({"weight_N": 1e5}, "<MusclePosition-v0 default scenario>: the muscle cannot lift 100000 N at 360000 Pa gauge: "
     "no contraction to track"),
])
def test_bad_environment_arguments_are_refused_with_the_first_named(kwargs, message):
    from pamsim.envs.muscle_position import MusclePositionEnv

    with pytest.raises(InputError) as err:
        MusclePositionEnv(**{"backend": "python", **kwargs})
    assert _message(err) == message


@pytest.mark.parametrize("sections, message", [
    ({"load": {"external_force": {"kind": "step", "time_s": 0.1, "final_N": 1.0}}},
     "s.toml: load.external_force: kind = 'step': the environment's time restarts every episode, so it takes only "
     "a constant external force"),
    ({"pressure": {"source": "prescribed", "prescribed": {"kind": "constant", "value_gauge_bar": 0.0}}},
     "s.toml: the scenario's pressure is 0 Pa gauge: give supply_gauge_Pa > 0"),
])
def test_a_scenario_the_environment_cannot_run_is_refused(sections, message):
    from pamsim.envs.muscle_position import MusclePositionEnv

    with pytest.raises(InputError) as err:
        MusclePositionEnv(_fig4(**sections), backend="python")
    assert _message(err) == message


# ----------------------------------------------------------------------------- force map CSV
_HEADER = "contraction_m,pressure_gauge_Pa,force_N\n"


@pytest.mark.parametrize("data, message", [
    (b"\xff\xfe\x00bad", "cannot read the force map: 'utf-8' codec can't decode byte 0xff in position 0: "
     "invalid start byte"),
    (b"# only a comment\n", "header = None: missing column(s) contraction_m, pressure_gauge_Pa, force_N "
     "(need contraction_m, pressure_gauge_Pa, force_N)"),
    (b"a,b,force_N\n0,0,1\n", "header = ['a', 'b', 'force_N']: missing column(s) contraction_m, pressure_gauge_Pa "
     "(need contraction_m, pressure_gauge_Pa, force_N)"),
    (_HEADER.encode() + b"0,0\n", "row 2: force_N = None: not a number"),
    (_HEADER.encode() + b"b,inf,1\n", "row 2: contraction_m = 'b': not a number"),
    (_HEADER.encode() + b"0,inf,1\n", "row 2: pressure_gauge_Pa = 'inf': must be finite"),
    (_HEADER.encode() + b"0,0,1\n0,1,2\n1,0,x\n", "row 4: force_N = 'x': not a number"),
    (_HEADER.encode(), "grid = 0 x 0: needs at least two contractions and two pressures"),
    (_HEADER.encode() + b"0,0,1\n1,0,2\n", "grid = 2 x 1: needs at least two contractions and two pressures"),
    # the first absent point of the grid, contraction by contraction
    (_HEADER.encode() + b"0,0,1\n0,1,2\n1,0,1\n2,1,1\n", "(contraction_m, pressure_gauge_Pa) = (1, 1): missing "
     "point (the table must be a full 3 x 2 grid)"),
])
def test_a_bad_force_map_is_refused_naming_row_and_value(tmp_path, data, message):
    path = tmp_path / "map.csv"
    path.write_bytes(data)
    with pytest.raises(ForceMapError) as err:
        read_force_map(path)
    assert _message(err, tmp_path) == f"TMP/map.csv: {message}"


def test_a_missing_force_map_is_refused(tmp_path):
    with pytest.raises(ForceMapError) as err:
        read_force_map(tmp_path / "nope.csv")
    assert _message(err, tmp_path) == ("TMP/nope.csv: cannot read the force map: [Errno 2] No such file or "
                                       "directory: 'TMP/nope.csv'")


# ----------------------------------------------------------------------------- atlas
@pytest.fixture
def force_map_muscle(tmp_path):
    """A muscle with a measured force map to 2 bar only (rated 4.5 bar), and one with neither map nor model."""
    (tmp_path / "map.csv").write_text(_HEADER + "".join(f"{x},{p},{x * 10 + p * 1e-5}\n" for x in (0, 0.005, 0.01)
                                                        for p in (0, 2e5)))
    lines = ['name = "mapped"', 'description = "d"', 'citation = "c"', 'default_static_force = "force_map"']
    for key in ("rated_pressure_gauge_Pa", "L0_m", "p_atm_Pa"):
        entry = SHADOW["parameters"][key]
        lines += [f"[parameters.{key}]", f"value = {entry['value']!r}", f"source = {entry['source']!r}"]
    (tmp_path / "none.toml").write_text("\n".join(lines) + "\n")
    (tmp_path / "mapped.toml").write_text('force_map = "map.csv"\n' + "\n".join(lines) + "\n")
    return tmp_path


@pytest.mark.parametrize("muscle, kwargs, message", [
    ("kothera2009_5a", {"pressures_bar": [1.0, 100.0, 0.0]},
     "pressure 100 bar: must lie in (0, 4.13685] bar (the muscle's rating)"),
    ("kothera2009_5a", {"pressures_bar": [0.0]}, "pressure 0 bar: must lie in (0, 4.13685] bar (the muscle's rating)"),
    # the models before the pressures
    ("kothera2009_5a", {"models": ["nope"], "pressures_bar": [0.0]},
     "model = 'nope': unknown static force model (`pamsim models` lists them)"),
    ("shadow_6x300_acra2012", {"models": ["force_map"]}, "model = 'force_map': needs parameter(s) force_map_file, "
     "which muscle 'shadow_6x300_acra2012' does not give (set them or choose another model)"),
    ("none.toml", {}, "muscle 'mapped': no static model applies: its default model 'force_map' needs "
     "force_map_file, not given: nothing to draw"),
    ("mapped.toml", {"pressures_bar": [3.0]},
     "muscle 'mapped': no curve to draw: the pressures 3 bar lie outside the domain of force_map"),
])
def test_an_atlas_that_cannot_be_drawn_is_refused(force_map_muscle, muscle, kwargs, message):
    name = str(force_map_muscle / muscle) if muscle.endswith(".toml") else muscle
    with pytest.raises(InputError) as err:
        build_atlas(name, **kwargs)
    assert _message(err) == message


def test_an_atlas_leaves_out_the_pressures_outside_a_models_domain(force_map_muscle):
    atlas = build_atlas(str(force_map_muscle / "mapped.toml"), pressures_bar=[1.0, 3.0], n_points=3)
    (curve,) = atlas.curves
    # the map is F = 10 x + 1e-5 p, linear in each variable, so its spline is exact: 1 N + 10 N/m * x
    assert curve.pressure_Pa == 1e5 and curve.x_m.tolist() == [0.0, 0.005, 0.01]
    assert curve.F_N == pytest.approx([1.0, 1.05, 1.1], abs=1e-12)
    assert curve.blocked_force_N == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("text, message", [
    ("pressure_bar,contraction_mm,force_N\n1,x,3\n",
     "a measured point is not a number (columns pressure_bar, contraction_mm, force_N)"),
    ("pressure_bar,contraction_mm,force_N\n1,2\n",
     "a measured point is not a number (columns pressure_bar, contraction_mm, force_N)"),
    ("pressure_atm,contraction_mm\n1,2\n", "no measured points: need a pressure column (pressure* or p_* ending in "
     "_gauge_Pa / _Pa / _kPa / _gauge_bar / _bar / _psi), a force or hung weight column (force* or weight* or load* "
     "ending in _N) (columns: pressure_atm, contraction_mm)"),
])
def test_a_bad_measured_point_file_is_refused(tmp_path, text, message):
    (tmp_path / "points.csv").write_text(text)
    with pytest.raises(InputError) as err:
        measured_points(tmp_path / "points.csv")
    assert _message(err, tmp_path) == f"TMP/points.csv: {message}"


# ----------------------------------------------------------------------------- muscle file
def _muscle(**changes) -> pamsim.muscles.Muscle:
    raw = copy.deepcopy(SHADOW)
    raw.pop("data")
    for key, value in changes.items():
        if value is None:
            raw.pop(key, None)
        else:
            raw[key] = value
    return muscle_from_dict(raw, "dir/bad.toml")


@pytest.mark.parametrize("changes, message", [
    ({"nmae": "x"}, "nmae = 'x': unknown key (did you mean 'name'?)"),
    ({"zzz": 1, "name": ""}, "zzz = 1: unknown key"),
    ({"name": None}, "missing key name: required, a non-empty string"),
    ({"description": "  ", "citation": 3}, "description = '  ': required, a non-empty string"),
    ({"default_static_force": 3}, "default_static_force = 3: required, a non-empty string"),
    ({"gaps": ["a", 1]}, "gaps = ['a', 1]: must be a list of strings"),
    ({"parameters": [1]}, "parameters = [1]: must be a table of [parameters.NAME] tables"),
    ({"rated_pressure_gauge_Pa": 5e5},
     "rated_pressure_gauge_Pa = 500000.0: given both at the top level and under [parameters]"),
    ({"force_map": 3, "data": 4}, "force_map = 3: must name a CSV file next to the muscle file"),
    ({"force_map": "nomap.csv"}, "force_map = 'nomap.csv': must name a CSV file next to the muscle file"),
    ({"data": "x.csv"}, "data = 'x.csv': must be a table with one key, file = \"NAME.csv\""),
    ({"data": {"file": "x.csv", "y": 1}}, "data = {'file': 'x.csv', 'y': 1}: must be a table with one key, "
     "file = \"NAME.csv\""),
    ({"data": 3, "upper_stop": []}, "data = 3: must be a table with one key, file = \"NAME.csv\""),
    ({"upper_stop": []}, "upper_stop = []: must be a table: at = \"CHOICE\", source = \"where it comes from\""),
    ({"upper_stop": {"at": "braid_lock", "sourc": "x"}}, "upper_stop.sourc = 'x': unknown key (did you mean "
     "'source'?)"),
    ({"upper_stop": {"at": "nowhere", "source": "x"}},
     "upper_stop.at = 'nowhere': must be one of auto, jam, domain_end, braid_lock"),
    ({"upper_stop": {"at": "braid_lock"}},
     "missing key upper_stop.source: required: why the stop stands there (or \"assumed: <reason>\")"),
])
def test_a_bad_muscle_file_is_refused_with_its_first_mistake(changes, message):
    with pytest.raises(MuscleError) as err:
        _muscle(**changes)
    assert _message(err) == f"dir/bad.toml: {message}"


@pytest.mark.parametrize("name, table, message", [
    ("L0_m", 3, "parameters.L0_m = 3: must be a table with value and source"),
    ("colour", {"value": 1}, "parameters.colour: unknown parameter"),
    ("L0_m", {"value": "x", "source": 3, "zz": 1}, "parameters.L0_m.zz = 1: unknown key"),
    ("L0_m", {"value": math.nan, "source": 3}, "parameters.L0_m.value = nan: must be a finite number"),
    ("L0_m", {"value": 0.3, "source": 3}, "parameters.L0_m.source = 3: required: where the value comes from (paper + "
     "table/equation, or \"assumed: <reason>\")"),
    ("L0_m", {"value": 0.3, "source": "x", "unit": "mm", "description": 3},
     "parameters.L0_m.unit = 'mm': does not match the unit of the name's suffix ('m')"),
    ("L0_m", {"value": -0.3, "source": "x", "description": 3}, "parameters.L0_m.description = 3: must be a string"),
    ("L0_m", {"value": 0, "source": "x"}, "parameters.L0_m = 0.0: must be > 0"),
    ("alpha_radial_deg", {"value": 95.0, "source": "x"}, "parameters.alpha_radial_deg = 95.0: must lie in (0, 90)"),
])
def test_a_bad_parameter_entry_is_refused_with_its_first_mistake(name, table, message):
    with pytest.raises(MuscleError) as err:
        _muscle(parameters={**SHADOW["parameters"], name: table})
    assert _message(err) == f"dir/bad.toml: {message}"


def test_a_top_level_rating_is_a_parameter_with_its_origin_as_source():
    params = {k: v for k, v in SHADOW["parameters"].items() if k != "rated_pressure_gauge_Pa"}
    muscle = _muscle(parameters=params, rated_pressure_gauge_Pa=4e5, upper_stop={"at": "jam", "source": "s"})
    rating = muscle.parameters.entries["rated_pressure_gauge_Pa"]
    assert (rating.value, rating.source) == (4e5, "bad.toml: top-level rating (no source given)")
    assert (muscle.upper_stop, muscle.upper_stop_source, muscle.data_file) == ("jam", "s", None)


# ----------------------------------------------------------------------------- signal tables
def _prescribed(table):
    spec = copy.deepcopy(FIG4)
    spec["pressure"] = {"source": "prescribed", "prescribed": table}
    return pamsim.Scenario.from_dict(spec, base_dir=SCENARIOS, origin="s.toml")


@pytest.mark.parametrize("table, message", [
    ({"kind": "stp"}, "pressure.prescribed.kind = 'stp': unknown signal kind (did you mean 'step'?)"),
    ({"kind": 3}, "pressure.prescribed.kind = 3: unknown signal kind (choose from constant, step, ramp, lag, trace, "
     "steps, linear, pwm)"),
    ({"kind": "constant", "value": 1.0}, "unknown key pressure.prescribed.value for kind = 'constant' (known: kind, "
     "value_gauge_bar, value_gauge_Pa)"),
    ({"kind": "step", "time_s": 1, "final_gauge_bar": 2, "tau_s": 1}, "unknown key pressure.prescribed.tau_s for "
     "kind = 'step' (known: kind, time_s, initial_gauge_bar, initial_gauge_Pa, final_gauge_bar, final_gauge_Pa)"),
    ({"kind": "constant"}, "missing key pressure.prescribed.value_gauge_bar"),
    ({"kind": "step", "time_s": -1.0}, "pressure.prescribed.time_s = -1.0: must not be negative"),
    ({"kind": "ramp", "start_s": 0.5, "end_s": 0.5, "final_gauge_bar": 2.0},
     "pressure.prescribed.end_s = 0.5: must be after start_s = 0.5"),
    ({"kind": "ramp", "end_s": 0.1}, "missing key pressure.prescribed.start_s"),
    # a lag's time constant is read before its time
    ({"kind": "lag", "time_s": -0.1, "tau_s": 0.0}, "pressure.prescribed.tau_s = 0.0: must be positive"),
    ({"kind": "lag", "time_s": 0.1, "tau_s": 0.2}, "missing key pressure.prescribed.final_gauge_bar"),
    ({"kind": "steps", "times_s": [0, 1], "values_gauge_bar": [1]},
     "pressure.prescribed.values_gauge_bar = '1 values': must be as many as times_s (2)"),
    ({"kind": "linear", "times_s": [0, 2, 1], "values_gauge_bar": [1, 2, 1]},
     "pressure.prescribed.times_s[2] = 1.0: must be after times_s[1] = 2"),
])
def test_a_bad_signal_table_is_refused_naming_the_key(table, message):
    with pytest.raises(InputError) as err:
        _prescribed(table)
    assert _message(err) == f"s.toml: {message}"


def test_a_signal_table_takes_its_values_in_either_unit():
    # bar first: 3 bar = 3e5 Pa; the step starts at 1 Pa given in Pa
    step = _prescribed({"kind": "step", "time_s": 0.5, "initial_gauge_Pa": 1.0, "final_gauge_bar": 3.0})
    signal = step.build_model().source.p_gauge_Pa
    assert (signal.time_s, signal.initial, signal.final) == (0.5, 1.0, 3e5)
    lag = _prescribed({"kind": "lag", "time_s": 0.1, "tau_s": 0.2, "final_gauge_Pa": 2e5}).build_model().source.p_gauge_Pa
    assert (lag.time_s, lag.initial, lag.final, lag.tau_s) == (0.1, 0.0, 2e5, 0.2)


# ----------------------------------------------------------------------------- trace CSV
def _trace(tmp_path, text, **table):
    if text is not None:
        (tmp_path / "tr.csv").write_text(text)
    spec = copy.deepcopy(FIG4)
    spec["pressure"] = {"source": "prescribed", "prescribed": {"kind": "trace", "file": "tr.csv", **table}}
    return pamsim.Scenario.from_dict(spec, base_dir=tmp_path, origin="s.toml")


_NEEDS = "tr.csv needs a column ending in _gauge_bar or a column ending in _gauge_Pa"


@pytest.mark.parametrize("text, table, message", [
    (None, {"file": 3}, "file = 3: must be a string (a CSV path)"),
    (None, {"file": "nope.csv"}, "file = 'nope.csv': trace file not found at TMP/nope.csv"),
    ("t_s,p_gauge_bar\n0,a\n1,2\n", {}, "file = 'tr.csv': cannot read as CSV with a header row: could not convert "
     "string 'a' to float64 at row 0, column 2."),
    ("time,p\n0,0\n1,2\n", {}, "time_column = 't_s': no such column in tr.csv (columns: time, p)"),
    ("t_s,p_gauge_bar\n0,0\n1,2\n", {"time_column": "T", "value_column": "zz"},
     "time_column = 'T': no such column in tr.csv (columns: t_s, p_gauge_bar)"),
    ("t_s,p_gauge_bar\n0,0\n1,2\n", {"value_column": "q_gauge_bar"}, f"value_column = 'q_gauge_bar': {_NEEDS}"),
    ("t_s,p_gauge_bar\n0,0\n1,2\n", {"value_column": 3}, f"value_column = 3: {_NEEDS}"),
    # without value_column: the first column after the time's, whatever its name
    ("t_s,x,p_gauge_bar\n0,5,0\n1,6,2\n", {}, f"value_column = 'x': {_NEEDS}"),
    ("t_s\n0\n1\n", {}, f"value_column = None: {_NEEDS}"),
    ("t_s,p_gauge_bar\n0,1\n", {}, "file = 'tr.csv': a trace needs at least two rows"),
    ("t_s,p_gauge_bar\n0,1\n1,nan\n2,3\n", {}, "file = 'tr.csv': non-finite value on line 3"),
    ("t_s,p_gauge_bar\n0,1\n1,1\n1,3\n", {}, "file = 'tr.csv': time must increase strictly; line 4 has t = 1 after 1"),
    ("t_s,p_gauge_bar\n0,1\n2,1\n1,3\n", {}, "file = 'tr.csv': time must increase strictly; line 4 has t = 1 after 2"),
])
def test_a_bad_trace_is_refused_naming_key_and_line(tmp_path, text, table, message):
    with pytest.raises(InputError) as err:
        _trace(tmp_path, text, **table)
    assert _message(err, tmp_path) == f"s.toml: pressure.prescribed.{message}"


@pytest.mark.parametrize("text, message", [
    ("t_s,p_gauge_bar\n", "a trace needs at least two rows"),
    ("t_s,p_gauge_bar\n0\n1\n", "cannot read as CSV with a header row: its rows have 1 column(s), too few to hold "
     "'p_gauge_bar' (column 2 of its header)"),
    ("p_gauge_bar,t_s\n0\n1\n", "cannot read as CSV with a header row: its rows have 1 column(s), too few to hold "
     "'t_s' (column 2 of its header)"),
])
def test_a_trace_without_the_rows_its_header_names_is_refused_at_the_command_line(tmp_path, cli, text, message):
    # these once ended in an IndexError's traceback (exit 1)
    spec = (SCENARIOS / "acra2012_fig4.toml").read_text()
    start, end = spec.index("[pressure]"), spec.index("[simulation]")
    (tmp_path / "s.toml").write_text(spec[:start] + '[pressure]\nsource = "prescribed"\n'
                                     'prescribed = { kind = "trace", file = "tr.csv" }\n\n' + spec[end:])
    (tmp_path / "tr.csv").write_text(text)
    proc = cli("run", tmp_path / "s.toml", "-o", tmp_path / "out", "--no-plot", "--no-progress")
    assert proc.returncode == 2
    assert proc.stderr == f"pamsim: error: {tmp_path / 's.toml'}: pressure.prescribed.file = 'tr.csv': {message}\n"
    assert not (tmp_path / "out").exists()


def test_a_trace_with_more_columns_in_its_rows_or_header_than_it_uses_is_read(tmp_path):
    for text in ("t_s,p_gauge_bar\n0,1,9\n1,2,9\n", "t_s,p_gauge_bar,note\n0,1\n1,2\n"):
        signal = _trace(tmp_path, text).build_model().source.p_gauge_Pa
        assert signal.t_s.tolist() == [0.0, 1.0] and signal.values.tolist() == [1e5, 2e5]


def test_a_trace_takes_its_named_column_in_its_unit(tmp_path):
    sc = _trace(tmp_path, "time,p_gauge_bar,q_gauge_Pa\n0,0,1000\n0.5,1,2000\n", time_column="time",
                value_column="q_gauge_Pa")
    signal = sc.build_model().source.p_gauge_Pa
    assert signal.t_s.tolist() == [0.0, 0.5] and signal.values.tolist() == [1000.0, 2000.0]
    signal = _trace(tmp_path, "t_s,p_gauge_bar\n0,0\n0.5,1.5\n").build_model().source.p_gauge_Pa
    assert signal.values.tolist() == [0.0, 1.5e5]  # bar to Pa


# ----------------------------------------------------------------------------- signal wiring
class _TwoUnits(Gain):
    inputs = (Var("u_N", "N"), Var("w_m", "m"))


def _gains(*names):
    return [Gain(n, {"k": 1.0}) for n in names]


@pytest.mark.parametrize("components, connections, inputs, message", [
    (_gains("g1", "g2"), [("g1.y_N", "g2.u_N")], {"u": ("g1.u_N", "g2.u_N")},
     "input g2.u_N is connected twice (g1.y_N and u)"),
    (_gains("g1", "g2", "g3"), [("g1.y_N", "g3.u_N"), ("g2.y_N", "g3.u_N")], {"u": ("g1.u_N", "g2.u_N")},
     "input g3.u_N is connected twice (g1.y_N and g2.y_N)"),
    (_gains("g1"), [], {"u": "g1.u_N", "v": "g1.u_N"}, "input g1.u_N is connected twice (u and v)"),
    (_gains("g1", "g2"), [("g1.y_N", "g2.y_N")], None,
     "cannot connect g1.y_N (output) to g2.y_N (output): a signal connects an output to an input"),
    (_gains("g1", "g2"), [("g1.u_N", "g2.u_N")], None,
     "cannot connect g1.u_N (input) to g2.u_N (input): a signal connects an output to an input"),
    (_gains("g1") + [Body("body", {"m_kg": 1})], [("g1.y_N", "body.flange")], None,
     "cannot connect g1.y_N (output) to body.flange (port): a signal connects an output to an input"),
    ([Body("body", {"m_kg": 1}), Spring("spring", {"k_N_per_m": 1})] + _gains("gain"),
     [("body.flange", "spring.flange"), ("gain.u_N", "body.x_m")], None,
     "cannot connect body.x_m [m] to gain.u_N [N]: the units differ"),
    (_gains("g1"), [], {"u": "g1.y_N"}, "model input 'u': g1.y_N is a output, not an input"),
    ([Body("body", {"m_kg": 1})], [], {"u": "body.flange"}, "model input 'u': body.flange is a port, not an input"),
    ([_TwoUnits("t", {"k": 1.0})], [], {"u": ("t.u_N", "t.w_m")},
     "model input 'u' drives inputs of different units ['N', 'm']"),
    (_gains("g1", "g2"), [("g1.y_N", "g1.u_N")], {}, "input g2.u_N [N] is not connected"),
])
def test_a_bad_signal_wiring_is_refused_naming_the_signals(components, connections, inputs, message):
    with pytest.raises(AssemblyError) as err:
        Assembly(components, connections, inputs)._signal_sources()
    assert _message(err) == message


def test_every_input_is_bound_to_its_source():
    components = _gains("g1", "g2") + [FloatForce("push")]
    sources = Assembly(components, [("g2.u_N", "g1.y_N")], {"u": ("g1.u_N", "push.u_N")})._signal_sources()
    assert sources == {"g2.u_N": ("output", "g1.y_N"), "g1.u_N": ("input", "u"), "push.u_N": ("input", "u")}


# ----------------------------------------------------------------------------- pamsim fmu build
@pytest.mark.parametrize("options, message", [
    (["--fmi", "4"], "--fmi = '4': must be 2 or 3"),
    (["--fmi", "2.0"], "--fmi = '2.0': must be 2 or 3"),
    (["--fmi", "4", "--scenario", "s.toml", "--muscle", "m"], "--fmi = '4': must be 2 or 3"),
    (["--scenario", "s.toml", "--muscle", "kothera2009_5a"],
     "--scenario = 's.toml': give either --scenario or --muscle"),
    (["--scenario", "s.toml", "--static-force", "kothera_energy"],
     "--scenario = 's.toml': give either --scenario or --muscle"),
    (["--scenario", "s.toml", "--static-force-variant", "v"],
     "--scenario = 's.toml': give either --scenario or --muscle"),
    (["--static-force", "kothera_energy"], "--muscle: needed with --static-force"),
    (["--static-force-variant", "v"], "--muscle: needed with --static-force-variant"),
    (["--static-force", "kothera_energy", "--static-force-variant", "v"], "--muscle: needed with --static-force"),
    (["--generated"], "--generated: needs --scenario (the FMU is generated from the scenario's assembly)"),
    (["--generated", "--muscle", "kothera2009_5a"],
     "--generated: needs --scenario (the FMU is generated from the scenario's assembly)"),
    (["--generated", "--static-force", "kothera_energy"], "--muscle: needed with --static-force"),
    (["--scenario", "s.toml", "--generated"], "s.toml: no such scenario file"),
])
def test_fmu_build_options_that_do_not_go_together_are_refused_with_the_first_named(tmp_path, cli, options,
                                                                                    message):
    out = cli("fmu", "build", *options, "-o", tmp_path / "m.fmu")
    assert (out.returncode, out.stdout, out.stderr) == (2, "", f"pamsim: error: {message}\n")
    assert not list(tmp_path.iterdir())


# ----------------------------------------------------------------------------- identification measurement files
@pytest.mark.parametrize("content, message", [
    (None, "cannot read it: No such file or directory"),
    ("folder", "cannot read it: Is a directory"),
    ("p_bar,x_mm,weight_N\n1,2,\xe9\n".encode("latin-1"), "not a text (UTF-8) CSV file"),
    ("", "no header row (the file is empty or only comments)"),
    ("# only\n\n   \n# comments\n", "no header row (the file is empty or only comments)"),
    ("p_bar,x_mm,weight_N\n# no rows\n\n", "no data rows below the header"),
    ("p_bar,x_mm,weight_N\n1,2,3\n# c\n4,5\n", "line 4 has 2 fields, the header has 3"),
    ("p_bar,x_mm,weight_N\n1,2,3,4\n", "line 2 has 4 fields, the header has 3"),
    ("p_bar,x_mm,weight_N\n1,2,3\n4, five ,6\n", "line 3, column 'x_mm': value 'five' is not a number"),
    ("p_bar,x_mm,weight_N\n1,,3\n", "line 2, column 'x_mm': value '' is not a number"),
    ("p_bar,x_mm,weight_N\n1,x,3,4\n", "line 2 has 4 fields, the header has 3"),  # the count is checked first
])
def test_a_measurement_file_that_is_not_a_numeric_csv_is_refused_naming_file_and_line(tmp_path, content, message):
    from pamsim.identification.columns import DataError, read_static_data

    path = tmp_path / "static.csv"
    if content == "folder":
        path.mkdir()
    elif isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        path.write_text(content)
    with pytest.raises(DataError) as err:
        read_static_data(path)
    assert _message(err, tmp_path) == f"TMP/static.csv: {message}"


def test_a_measurement_file_skips_blank_and_comment_lines_and_hashes_its_bytes(tmp_path):
    import hashlib

    from pamsim.identification.columns import read_static_data

    text = "# tests\n\np_bar , x_mm,weight_N\n# first\n1,2,3\n\n  \n2 , 4,5\n"
    (tmp_path / "static.csv").write_text(text)
    data = read_static_data(tmp_path / "static.csv")
    assert data.pressure_gauge_Pa.tolist() == [1e5, 2e5] and data.contraction_m.tolist() == [2e-3, 4e-3]
    assert data.load_N.tolist() == [3.0, 5.0] and data.sha256 == hashlib.sha256(text.encode()).hexdigest()


# ----------------------------------------------------------------------------- [uncertainty.parameters.NAME]
_LOGNORMAL = {"distribution": "lognormal", "median": 0.3, "sigma": 0.25, "lower": 0.2, "upper": 0.6}
_UNIFORM = {"distribution": "uniform", "lower": 2.0, "upper": 3.0}


@pytest.mark.parametrize("name, entry, message", [
    ("valve_b", {**_LOGNORMAL, "median": 0.0}, "valve_b.median = 0.0: must be positive"),
    ("valve_b", {**_LOGNORMAL, "sigma": -0.1}, "valve_b.sigma = -0.1: must be positive"),
    ("valve_b", {**_LOGNORMAL, "median": -0.3, "sigma": -1.0}, "valve_b.sigma = -1.0: must be positive"),
    ("valve_b", {**_LOGNORMAL, "std": 1.0},
     "valve_b.std = 1.0: does not apply to a lognormal distribution (it takes lower, median, relative, sigma, upper)"),
    ("N0_N_per_bar", {**_UNIFORM, "relative": "yes"},
     "N0_N_per_bar.relative = 'yes': must be true or false, not a string"),
    ("N0_N_per_bar", {**_UNIFORM, "relative": "yes", "upper": 1.0},  # relative is read before the bounds
     "N0_N_per_bar.relative = 'yes': must be true or false, not a string"),
    ("N0_N_per_bar", {**_UNIFORM, "upper": 2.0}, "N0_N_per_bar.upper = 2.0: must be above lower = 2"),
    ("stop_restitution", {**_UNIFORM, "relative": True, "lower": 0.9, "upper": 1.1},
     "stop_restitution.relative = true: the base value is 0, so a factor cannot vary it"),
    ("N1_N_per_bar_m", {**_LOGNORMAL, "lower": -3.0, "upper": -1.0},
     "N1_N_per_bar_m.lower = -3.0: the bounds [-3, -1] exclude the lognormal distribution (probability inside 0)"),
    ("valve_b", {"distribution": "uniform", "relative": True, "lower": 0.5, "upper": 5.0},
     "valve_b.upper = 5.0: gives valve_b = 1.5, which must lie in [0, 1)"),
    ("valve_b", {"distribution": "uniform", "lower": -1.0, "upper": 2.0},
     "valve_b.lower = -1.0: gives valve_b = -1, which must lie in [0, 1)"),
])
def test_a_bad_uncertainty_distribution_is_refused_with_its_first_mistake(name, entry, message):
    from pamsim.sweep import SweepError, sweep_from_dict

    table = {"samples": 5, "seed": 1, "parameters": {name: entry}}
    with pytest.raises(SweepError) as err:
        sweep_from_dict({"base_scenario": str(SCENARIOS / "acra2012_fig4.toml"), "uncertainty": table},
                        origin="study.toml")
    assert _message(err) == f"study.toml: uncertainty.parameters.{message}"
