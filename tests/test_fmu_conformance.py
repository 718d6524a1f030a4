"""FMI conformance of the FMU beyond agreement with the Python simulator: directional
derivatives, outputs at communication points, doStep arguments, failed steps, long steps and
exported symbols.  The references are the Python model (an independent implementation of the
equations), finite differences and the FMI standards' rules.
"""

from __future__ import annotations

import csv
import ctypes
import math
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.fmu.runner import set_values
from pamsim.fmu.variables import STATES, VARIABLES, value_reference
from test_fmu import _Api, _error_status, _inputs_and_starts, _instance, _start_fig4, n_states

DERIVATIVES = tuple(f"der({s})" for s in STATES)


def _ptr(a):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


class _Sliding:
    """A Model Exchange instance driven into the slip-up mode at a chosen state, with Fig. 4's inputs."""

    def __init__(self, fmus, version, y):
        self.n = n_states(fmus[version])
        self.fmu = _instance(fmus, version, "me")
        self.api = _Api(self.fmu, version)
        self.v = version
        _start_fig4(self.api)
        self.api.init()
        self._update()
        self.fmu.enterContinuousTimeMode()
        # Lifted off the stop by a high pressure, then moved to the state under test.
        self.set_states([0.0, 0.0, 4.6e5, y[3]])
        self.fmu.enterEventMode()
        self._update()
        assert self.api.mode() == 1
        self.fmu.enterContinuousTimeMode()
        self.set_states(y)

    def _update(self):
        return self.fmu.newDiscreteStates() if self.v == 2 else self.fmu.updateDiscreteStates()

    def set_states(self, y):
        """The four states of the model (the work integrals, states after them, as they are)."""
        a = np.zeros(self.n)
        self.fmu.getContinuousStates(_ptr(a), self.n)
        a[:4] = y
        self.fmu.setContinuousStates(_ptr(a), self.n)

    def derivatives(self):
        dx = np.zeros(self.n)
        (self.fmu.getDerivatives if self.v == 2 else self.fmu.getContinuousStateDerivatives)(_ptr(dx), self.n)
        return dx[:4]

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def _python_state_jacobian(y, mode=1.0):
    """d(der of the four states)/d(states) of the Python model (Fig. 4, valve open), by central
    differences with a step per state."""
    sc, _, _ = _inputs_and_starts("acra2012_fig4")
    model = sc.build_model()
    inputs = model.source.inputs(2.0)

    def f(yy):
        return np.asarray(model.slip_rhs(np.r_[yy, 0.0, 0.0, 0.0, 0.0], mode, inputs, 2.0)[:4], dtype=float)

    J = np.zeros((4, 4))
    for j, scale in enumerate((0.01, 0.1, 1e5, 1e-5)):
        h = 1e-6 * max(abs(y[j]), scale)
        e = np.zeros(4)
        e[j] = h
        J[:, j] = (f(np.asarray(y) + e) - f(np.asarray(y) - e)) / (2 * h)
    return J


# A sliding state of Fig. 4: 30 mm, rising at 50 mm/s, 3 bar gauge, air mass at 20 degC.
Y_SLIDING = [0.030, 0.05, 4.0e5, 4.0e5 * 9.0e-6 / (287.05 * 293.15)]


def _close(actual, expected, scale):
    return np.all(np.abs(np.asarray(actual) - np.asarray(expected)) <= 1e-5 * scale + 1e-9)


@pytest.mark.parametrize("version", [2, 3])
def test_directional_derivative_jacobian_columns_and_seeds_match_python_model(fmus, version):
    """The FMI 2.0-style column call passes all four states as knowns with a unit seed; columns
    and arbitrary seeds must match the Python model's Jacobian."""
    s = _Sliding(fmus, version, Y_SLIDING)
    J = _python_state_jacobian(Y_SLIDING)
    unknowns = [value_reference(n) for n in DERIVATIVES]
    knowns = [value_reference(n) for n in STATES]
    scale = np.abs(J).max(axis=1)  # per row: the largest entry sets the tolerance
    for j in range(4):
        seed = [0.0] * 4
        seed[j] = 1.0
        col = np.array(s.fmu.getDirectionalDerivative(unknowns, knowns, seed))
        assert np.all(np.isfinite(col)), col
        assert _close(col, J[:, j], scale), (j, col, J[:, j])
    rng = np.random.default_rng(11)
    for seed in [np.ones(4), rng.normal(size=4) * [0.01, 0.1, 1e5, 1e-5], rng.normal(size=4)]:
        got = np.array(s.fmu.getDirectionalDerivative(unknowns, knowns, list(seed)))
        assert _close(got, J @ seed, np.abs(J) @ np.abs(seed)), (seed, got, J @ seed)
    s.free()


@pytest.mark.parametrize("version", [2, 3])
def test_directional_derivative_with_mixed_knowns_matches_finite_differences(fmus, version):
    """States, inputs and a parameter of very different scales as knowns: the result must be the
    Jacobian (by finite differences through the FMU's own setters) times the seed."""
    s = _Sliding(fmus, version, Y_SLIDING)
    names = ["contraction_m", "chamber_pressure_abs_Pa", "supply_pressure_gauge_Pa", "load_mass_kg",
             "external_force_N"]
    outputs = list(DERIVATIVES) + ["p_gauge_Pa", "F_static_N", "F_friction_N"]
    y0 = np.array(Y_SLIDING)

    def evaluate():
        return np.r_[s.derivatives(), s.api.get(*outputs[4:])]

    base = {n: s.api.get(n)[0] for n in names}
    J = np.zeros((len(outputs), len(names)))
    for j, n in enumerate(names):
        h = 1e-6 * max(abs(base[n]), 1.0)
        cols = []
        for sign in (1, -1):
            if n in STATES:
                y = y0.copy()
                y[STATES.index(n)] += sign * h
                s.set_states(y)
            else:
                s.api.set(n, base[n] + sign * h)
            cols.append(evaluate())
            s.set_states(y0)
            if n not in STATES:
                s.api.set(n, base[n])
        J[:, j] = (cols[0] - cols[1]) / (2 * h)
    unknowns = [value_reference(n) for n in outputs]
    knowns = [value_reference(n) for n in names]
    rng = np.random.default_rng(5)
    for seed in [np.ones(5), rng.normal(size=5), [0.0, 0.0, 1.0, 0.0, 0.0]]:
        got = np.array(s.fmu.getDirectionalDerivative(unknowns, knowns, list(seed)))
        assert _close(got, J @ seed, np.abs(J) @ np.abs(seed) + 1e-12), (seed, got, J @ seed)
    s.free()


def _cs(fmus, version, **start):
    fmu = _instance(fmus, version, "cs")
    api = _Api(fmu, version)
    set_values(fmu, version, start)
    api.init()
    return fmu, api


@pytest.mark.parametrize("version", [2, 3])
def test_co_simulation_outputs_follow_inputs_set_at_a_communication_point(fmus, version):
    """A prescribed pressure set between steps shows at once in the pressure and static-force
    outputs; the friction that holds a load follows a new external force."""
    sc, _, _ = _inputs_and_starts("acra2012_fig4")
    model = sc.build_model()
    fmu, api = _cs(fmus, version, pressure_source=1, initial_contraction_m=0.02, prescribed_pressure_gauge_Pa=1e5)
    api.step(0.0, 0.1)
    x = api.get("contraction_m")[0]
    api.set("prescribed_pressure_gauge_Pa", 3e5)
    p, F_s = api.get("p_gauge_Pa", "F_static_N")
    assert p == 3e5
    assert F_s == pytest.approx(float(model.static_force.force_N(x, 3e5)), rel=1e-12)
    fmu.terminate()
    fmu.freeInstance()

    # A 12.74 N load held at 20 mm by 1.42 bar and 2.5 N of constant friction (net force 0.13 N).
    mass = 12.74 / 9.81
    fmu, api = _cs(fmus, version, pressure_source=1, friction_model=1, initial_contraction_m=0.02,
                   prescribed_pressure_gauge_Pa=1.42e5, load_mass_kg=mass)
    api.step(0.0, 0.1)
    assert api.mode() == 0
    for F_ext in (0.5, -0.5):
        api.set("external_force_N", F_ext)
        net = float(model.static_force.force_N(0.02, 1.42e5)) - mass * 9.81 + F_ext
        assert api.get("F_friction_N")[0] == pytest.approx(-net, rel=1e-12)
    fmu.terminate()
    fmu.freeInstance()


def _fmi3_do_step(fmu, t, h):
    """fmi3DoStep called directly (fmpy's doStep does not return lastSuccessfulTime on an error):
    (status, lastSuccessfulTime)."""
    flags = [ctypes.c_bool(False) for _ in range(3)]
    last = ctypes.c_double(-1.0)
    status = fmu.dll.fmi3DoStep(ctypes.c_void_p(fmu.component), ctypes.c_double(t), ctypes.c_double(h),
                                ctypes.c_bool(False), *[ctypes.byref(f) for f in flags], ctypes.byref(last))
    return status, last.value


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("t,h,message", [
    (0.1, float("inf"), "step size inf"),
    (0.1, float("nan"), "step size nan"),
    (0.1, -0.01, "step size -0.01"),
    (0.2, 0.1, "currentCommunicationPoint = 0.2 s is not the FMU's time 0.1 s"),
    (float("nan"), 0.1, "currentCommunicationPoint = nan s is not the FMU's time 0.1 s"),
])
def test_do_step_refuses_invalid_time_arguments(fmus, version, t, h, message, capfd):
    fmu, api = _cs(fmus, version)
    api.step(0.0, 0.1)
    before = api.get("contraction_m", "p_gauge_Pa")
    capfd.readouterr()
    assert _error_status(lambda: api.step(t, h)) == 3
    assert message in capfd.readouterr().out
    # Refused, not half done: the instance is where it was and steps on from there.
    assert api.get("contraction_m", "p_gauge_Pa") == before
    if version == 2:
        assert fmu.getRealStatus(2) == 0.1  # fmi2LastSuccessfulTime
    else:
        assert _fmi3_do_step(fmu, t, h) == (3, 0.1)
    api.step(0.1, 0.1)
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_failed_step_leaves_outputs_mode_and_time_at_one_instant(fmus, version, capfd):
    """A step that runs out of internal steps after the load was released: the outputs, the
    mode and the last successful time are those of one instant, which a fresh instance stepped
    to that time reproduces."""
    starts = dict(cs_max_internal_steps=40, supply_pressure_gauge_Pa=3.6e5, valve_command=1.0)
    fmu, api = _cs(fmus, version, **starts)
    if version == 2:
        assert _error_status(lambda: api.step(0.0, 3.0)) == 3
        t_ok = fmu.getRealStatus(2)
    else:
        status, t_ok = _fmi3_do_step(fmu, 0.0, 3.0)
        assert status == 3
    assert "more than 40 internal steps" in capfd.readouterr().out
    assert 0.0 < t_ok < 3.0
    got = api.get("contraction_m", "velocity_m_s", "p_gauge_Pa") + [api.mode()]
    assert got[0] > 0.0  # released from the stop before the failure
    fmu.freeInstance()
    fresh, fapi = _cs(fmus, version, supply_pressure_gauge_Pa=3.6e5, valve_command=1.0)
    fapi.step(0.0, t_ok)
    want = fapi.get("contraction_m", "velocity_m_s", "p_gauge_Pa") + [fapi.mode()]
    assert got[3] == want[3]
    assert got[:3] == pytest.approx(want[:3], rel=1e-6, abs=1e-9)
    fresh.terminate()
    fresh.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_long_step_of_a_load_at_rest(fmus, version):
    """1e6 s in one step: a load resting on its stop, and Fig. 4's load held at the end of its
    transient with the valve still open."""
    fmu, api = _cs(fmus, version)
    before = api.get("contraction_m", "p_gauge_Pa")
    api.step(0.0, 1e6)
    assert api.get("contraction_m", "p_gauge_Pa") == before and api.mode() == 2
    fmu.terminate()
    fmu.freeInstance()

    fmu, api = _cs(fmus, version, supply_pressure_gauge_Pa=3.6e5, valve_command=1.0)
    api.step(0.0, 8.0)
    x8, mode8 = api.get("contraction_m")[0], api.mode()
    assert mode8 == 0
    api.step(8.0, 1e6)
    assert api.get("contraction_m")[0] == x8 and api.mode() == 0
    assert api.get("p_gauge_Pa")[0] == pytest.approx(3.6e5, rel=1e-9)
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_absurd_load_mass_is_refused_by_its_range(fmus, version, capfd):
    from pamsim.parameters import LOAD_MASS

    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    assert _error_status(lambda: api.set("load_mass_kg", 1e-12)) == 3
    assert f"load_mass_kg = 1e-12: must be >= {LOAD_MASS.lower:g}" in capfd.readouterr().out
    api.set("load_mass_kg", LOAD_MASS.lower)
    fmu.freeInstance()
    # pamsim.Scenario refuses the same mass, from the same range.
    spec = {"load": {"mass_kg": 1e-12}, "pressure": {"source": "valve", "supply_gauge_bar": 3.6},
            "simulation": {"duration_s": 1.0}}
    with pytest.raises(pamsim.ScenarioError, match=f"load.mass_kg = 1e-12: .* must be >= {LOAD_MASS.lower:g} kg"):
        pamsim.Scenario.from_dict(spec)


@pytest.mark.parametrize("version", [2, 3])
def test_only_fmi_functions_are_exported(fmus, version, tmp_path):
    if not shutil.which("nm"):
        pytest.skip("nm (binutils) is not installed")
    with zipfile.ZipFile(fmus[version]) as zf:
        name = next(n for n in zf.namelist() if n.endswith(".so"))
        lib = tmp_path / "lib.so"
        lib.write_bytes(zf.read(name))
    out = subprocess.run(["nm", "-D", "--defined-only", str(lib)], capture_output=True, text=True, check=True).stdout
    symbols = [line.split()[-1] for line in out.splitlines() if line.strip()]
    assert symbols and all(s.startswith(f"fmi{version}") for s in symbols), symbols


# ------------------------------------------------------------------ value references

REFERENCE_LIST = Path(__file__).with_name("data") / "fmu_value_references.csv"


def _committed_value_references():
    with open(REFERENCE_LIST) as fh:
        return {row["name"]: int(row["value_reference"]) for row in csv.DictReader(fh)}


def test_value_references_are_the_committed_ones():
    """Existing variables keep their numbers; a new one (not yet in the list) gets a number above
    all listed ones."""
    committed = _committed_value_references()
    current = {v.name: value_reference(v.name) for v in VARIABLES}
    assert len(set(current.values())) == len(current)
    for name, vr in committed.items():
        assert current.get(name) == vr, f"{name}: value reference {current.get(name)}, committed {vr}"
    assert all(vr > max(committed.values()) for name, vr in current.items() if name not in committed)


def test_adding_a_parameter_does_not_renumber_the_others(monkeypatch):
    import pamsim.fmu.variables as variables
    from pamsim.parameters import Parameter, ParameterSet, get_parameter_set

    params = get_parameter_set(variables.PARAMETER_SET)
    extra = ParameterSet(params.name, params.citation,
                         {"A_new_parameter_N": Parameter(1.0, "N", "test", "a parameter added first"),
                          **params.entries})
    monkeypatch.setattr(variables, "get_parameter_set", lambda name: extra)
    table = variables._table()
    assert table[0].name == "A_new_parameter_N"
    vrs = variables.assign_value_references(table, variables.VALUE_REFERENCES)
    committed = _committed_value_references()
    assert {n: vrs[n] for n in committed} == committed
    assert vrs["A_new_parameter_N"] == max(committed.values()) + 1


# ------------------------------------------------------------------ model description


def _model_description(fmus, version):
    return ET.fromstring(zipfile.ZipFile(fmus[version]).read("modelDescription.xml"))


def _declared_dependencies(fmus, version):
    """{(section, unknown name): set of known names or None} from ModelStructure."""
    root = _model_description(fmus, version)
    if version == 2:
        names = [e.get("name") for e in root.find("ModelVariables")]
        name_of = lambda ref: names[int(ref) - 1]  # noqa: E731  (FMI 2.0: 1-based index)
        pairs = [(sec.tag, u) for sec in root.find("ModelStructure") for u in sec]
        attr = "index"
    else:
        by_vr = {e.get("valueReference"): e.get("name") for e in root.find("ModelVariables")}
        name_of = by_vr.__getitem__  # noqa: E731
        pairs = [(u.tag, u) for u in root.find("ModelStructure")]
        attr = "valueReference"
    out = {}
    for section, u in pairs:
        deps = u.get("dependencies")
        out[section, name_of(u.get(attr))] = None if deps is None else {name_of(d) for d in deps.split()}
    return out


KNOWNS = list(STATES) + ["valve_command", "supply_pressure_gauge_Pa", "prescribed_pressure_gauge_Pa", "load_mass_kg",
                         "external_force_N"]
UNKNOWNS = ["contraction_m", "velocity_m_s", "p_gauge_Pa", "F_static_N", "F_friction_N", *DERIVATIVES,
            "event_indicator_1", "event_indicator_2"]


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("source", ["valve", "prescribed"])
def test_declared_dependencies_cover_every_true_dependency(fmus, version, source):
    """Perturb each state and input of a sliding load; every output, derivative and event indicator
    that changes must declare that known (and friction_mode, a discrete state, none)."""
    declared = _declared_dependencies(fmus, version)
    section = {2: ("Outputs", "Derivatives"), 3: ("Output", "ContinuousStateDerivative", "EventIndicator")}[version]
    deps = {name: d for (sec, name), d in declared.items() if sec in section}
    assert set(deps) >= set(UNKNOWNS + ["friction_mode"]) - ({"event_indicator_1", "event_indicator_2"}
                                                            if version == 2 else set())
    unknowns = UNKNOWNS + sorted(set(deps) - set(UNKNOWNS) - {"friction_mode"})  # the generated model's, too
    assert deps["friction_mode"] == set()
    if source == "valve":
        s = _Sliding(fmus, version, Y_SLIDING)
    else:
        s = _Sliding.__new__(_Sliding)
        s.fmu, s.v, s.n = _instance(fmus, version, "me"), version, n_states(fmus[version])
        s.api = _Api(s.fmu, version)
        set_values(s.fmu, version, {"pressure_source": 1, "prescribed_pressure_gauge_Pa": 3.6e5, "valve_command": 0.5,
                                    "supply_pressure_gauge_Pa": 3e5})
        s.api.init()
        s._update()
        s.fmu.enterContinuousTimeMode()
        s.set_states(Y_SLIDING)
    assert s.api.mode() == 1

    def read():
        return np.array(s.api.get(*unknowns))

    base = read()
    y0 = np.array(Y_SLIDING)
    found = 0
    for known in KNOWNS:
        value = s.api.get(known)[0]
        h = 1e-4 * max(abs(value), 1.0)
        if known == "valve_command":
            h = -0.25
        if known in STATES:
            y = y0.copy()
            y[STATES.index(known)] += h
            s.set_states(y)
        else:
            s.api.set(known, value + h)
        changed = np.abs(read() - base) > 1e-12 * (1.0 + np.abs(base))
        mode = s.api.mode()
        s.set_states(y0) if known in STATES else s.api.set(known, value)
        assert mode == 1
        for name in np.array(unknowns)[changed]:
            if version == 2 and name.startswith("event_indicator"):
                continue  # FMI 2.0 declares no dependencies of event indicators
            assert deps[name] is not None and known in deps[name], f"{name} depends on {known}: not declared"
            found += 1
    assert found >= (15 if source == "valve" else 10)
    s.free()


@pytest.mark.parametrize("version", [2, 3])
def test_declared_initial_dependencies_of_the_states_cover_every_parameter_they_depend_on(fmus, version):
    declared = _declared_dependencies(fmus, version)
    section = "InitialUnknowns" if version == 2 else "InitialUnknown"
    fmu = _instance(fmus, version)
    api = _Api(fmu, version)
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    api.set("initial_contraction_m", 0.02)
    api.set("initial_pressure_gauge_Pa", 1e5)
    base = np.array(api.get(*STATES))
    params = [v.name for v in VARIABLES if v.causality in ("parameter", "input") and v.kind == "real"]
    for name in params:
        value = api.get(name)[0]
        api.set(name, value * (1 + 1e-6) if value else 1e-9)
        changed = np.abs(np.array(api.get(*STATES)) - base) > 1e-13 * np.abs(base)
        api.set(name, value)
        for state in np.array(STATES)[changed]:
            assert name in declared[section, state], f"the initial {state} depends on {name}: not declared"
    fmu.exitInitializationMode()
    fmu.terminate()
    fmu.freeInstance()


COMPANIONS = {("valve_laminar_ratio", -math.inf): {"valve_b": 0.0},
              ("release_margin_N", -math.inf): {"stick_margin_N": 0.0}}
"""Values a bound needs of other parameters to pass the checks between parameters."""


@pytest.mark.parametrize("version", [2, 3])
def test_min_max_are_the_ranges_the_fmu_enforces(fmus, unzipped, version, capfd):
    """Every variable with a checked range declares it; the declared bound is accepted and the next
    double beyond it refused (inputs when set, parameters at the end of initialisation)."""
    from test_fmu import _initialise_with

    root = _model_description(fmus, version)
    elements = {e.get("name"): (e[0] if version == 2 else e) for e in root.find("ModelVariables")}
    checked = 0
    for v in VARIABLES:
        e = elements[v.name]
        lo, hi = e.get("min"), e.get("max")
        assert (lo is not None) == math.isfinite(v.lower) and (hi is not None) == math.isfinite(v.upper), v.name
        for bound, outward in ((lo, -math.inf), (hi, math.inf)):
            if bound is None or v.choices:
                continue
            value = int(bound) if v.kind == "integer" else float(bound)
            beyond = value + (1 if outward > 0 else -1) if v.kind == "integer" else math.nextafter(value, outward)
            if v.causality == "parameter":
                # valve_b's own upper bound is unreachable: it must also stay below valve_laminar_ratio < 1.
                if (v.name, outward) != ("valve_b", math.inf):
                    values = {v.name: value, **COMPANIONS.get((v.name, outward), {})}
                    assert _initialise_with(unzipped, version, values) == 0, (v.name, value)
                assert _initialise_with(unzipped, version, {v.name: beyond}) == 3, (v.name, beyond)
            else:
                fmu = _instance(fmus, version)
                api = _Api(fmu, version)
                api.set(v.name, value)
                assert _error_status(lambda: api.set(v.name, beyond)) == 3, (v.name, beyond)
                fmu.freeInstance()
            checked += 1
    capfd.readouterr()
    assert checked >= 25


@pytest.mark.parametrize("version", [2, 3])
def test_integer_choices_are_enumerations(fmus, version, capfd):
    from pamsim.fmu.variables import DAMPING_CHOICES, FRICTION_CHOICES, NEGATIVE_LEVEL, SOURCE_CHOICES

    root = _model_description(fmus, version)
    types = root.find("TypeDefinitions")
    items = {}
    for t in types:
        enum = t.find("Enumeration") if version == 2 else t
        items[t.get("name")] = tuple(i.get("name") for i in sorted(enum, key=lambda i: int(i.get("value"))))
    elements = {e.get("name"): e for e in root.find("ModelVariables")}
    for name, choices in (("friction_model", FRICTION_CHOICES), ("damping_model", DAMPING_CHOICES),
                          ("pressure_source", SOURCE_CHOICES), ("friction_negative_level", NEGATIVE_LEVEL)):
        e = elements[name][0] if version == 2 else elements[name]
        assert e.tag == "Enumeration" and items[e.get("declaredType")] == choices
    if version == 3:  # FMI 3.0 reads and writes an Enumeration as Int64, not as Int32
        fmu = _instance(fmus, version)
        vr = [value_reference("damping_model")]
        fmu.setInt64(vr, [2])
        fmu.enterInitializationMode()
        assert fmu.getInt64(vr) == [2]
        assert _error_status(lambda: fmu.setInt32(vr, [1])) == 3
        assert "no Int32 variable with value reference" in capfd.readouterr().out
        fmu.exitInitializationMode()
        fmu.terminate()
        fmu.freeInstance()
        # A value beyond int32 is not wrapped into range: it is refused as out of range.
        fmu = _instance(fmus, version)
        fmu.setInt64(vr, [2**32 + 1])
        fmu.enterInitializationMode()
        assert _error_status(fmu.exitInitializationMode) == 3
        assert "invalid parameters: damping_model = 2147483647: must lie in [0, 2]" in capfd.readouterr().out
        fmu.freeInstance()


def test_base_units_against_hand_conversions():
    from pamsim.fmu.units import base_unit

    assert base_unit("N") == (1.0, {"kg": 1, "m": 1, "s": -2})
    assert base_unit("1") == (1.0, {})
    deg = base_unit("deg")
    assert deg[1] == {"rad": 1} and deg[0] == pytest.approx(math.pi / 180)
    # 1 N/(bar m^2) = 1 N / (1e5 N/m^2 * m^2) = 1e-5 (dimensionless).
    f, e = base_unit("N/(bar m^2)")
    assert e == {} and f == pytest.approx(1e-5)
    # 1 bar/kg = 1e5 Pa/kg = 1e5 m^-1 s^-2.
    f, e = base_unit("bar/kg")
    assert e == {"m": -1, "s": -2} and f == pytest.approx(1e5)
    assert base_unit("J/(kg K)") == (1.0, {"m": 2, "s": -2, "K": -1})
    assert base_unit("m^3/(s Pa)") == (1.0, {"kg": -1, "m": 4, "s": 1})
    assert base_unit("N s^2/m^2") == (1.0, {"kg": 1, "m": -1})
    assert base_unit("Hz") == (1.0, {"s": -1}) and base_unit("Pa s") == (1.0, {"kg": 1, "m": -1, "s": -1})


@pytest.mark.parametrize("name, unit", [("frequency_Hz", "Hz"), ("delay_on_s", "s"), ("rise_s", "s"),
                                        ("min_rebound_speed_m_s", "m/s"), ("viscosity_Pa_s", "Pa s"),
                                        ("D1_N_s_per_m", "N s/m"), ("C_m3_per_s_Pa", "m^3/(s Pa)"), ("gamma", "1")])
def test_a_parameters_unit_is_read_from_its_name(name, unit):
    """The suffixes of frequencies, times, speeds and viscosities give their units (they read "1" before, so
    an FMU declared an averaged valve's frequency and delays dimensionless); longer suffixes first."""
    from pamsim.parameter_schema import unit_of

    assert unit_of(name) == unit


@pytest.mark.parametrize("version", [2, 3])
def test_every_unit_definition_has_its_base_unit(fmus, version):
    from pamsim.fmu.units import base_unit

    from pamsim.fmu.muscle_spec import one_muscle_spec

    units = _model_description(fmus, version).find("UnitDefinitions")
    declared = {v.unit for v in one_muscle_spec(version).variables if v.unit}
    assert {u.get("name") for u in units} == declared
    for u in units:
        factor, exponents = base_unit(u.get("name"))
        b = u.find("BaseUnit")
        assert {k: int(x) for k, x in b.attrib.items() if k != "factor"} == exponents
        assert float(b.get("factor", 1.0)) == factor


# ------------------------------------------------------------------ metadata and archive


@pytest.mark.parametrize("version", [2, 3])
def test_metadata_and_documentation(fmus, version):
    from pamsim.fmu.generate import generation_date

    root = _model_description(fmus, version)
    assert root.get("version") == pamsim.__version__
    assert root.get("author") and "MIT" in root.get("license")
    assert root.get("generationDateAndTime") == generation_date()
    assert float(root.find("DefaultExperiment").get("stepSize")) == 1e-3
    # Every category the C code logs under is declared.
    shell = (Path(__file__).resolve().parents[1] / "fmu" / "src" / "fmi_shell.c").read_text()
    used = set(re.search(r"level_category\[\] = \{([^}]*)\}", shell).group(1).replace('"', "").replace(" ", "")
               .split(","))
    assert {c.get("name") for c in root.find("LogCategories")} == used
    with zipfile.ZipFile(fmus[version]) as zf:
        page = zf.read("documentation/index.html").decode()
    for v in VARIABLES:
        assert f"<td>{v.name}</td>" in page.replace("&#x27;", "'")
    assert "Co-Simulation" in page and "Model Exchange" in page


def test_generation_date_comes_from_the_sources_and_the_archive_is_reproducible(tmp_path, monkeypatch):
    from pamsim.fmu import build
    from pamsim.fmu.generate import generation_date

    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    assert generation_date() == "2023-11-14T22:13:20Z"
    first = build(tmp_path / "a.fmu", 2).read_bytes()
    second = build(tmp_path / "b.fmu", 2).read_bytes()
    assert first == second
    with zipfile.ZipFile(tmp_path / "a.fmu") as zf:
        assert {i.date_time for i in zf.infolist()} == {(2023, 11, 14, 22, 13, 20)}
        assert b'generationDateAndTime="2023-11-14T22:13:20Z"' in zf.read("modelDescription.xml")
    monkeypatch.delenv("SOURCE_DATE_EPOCH")
    date = generation_date()
    assert date is None or re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", date)
