"""Fuzzing of the scenario and sweep parsers with hypothesis (parse and validate only, no simulation).

Documents are mutated valid files (a key dropped, a value replaced by a random
TOML value of any type, NaN, infinity or a huge number, an unknown key added),
random tables, and TOML text with random edits.  The only outcomes allowed are
a scenario (or sweep) that builds its model, or an :class:`InputError` whose
message is one line; anything else fails the test.  About 2,050 documents in
all (see ``EXAMPLES``), derandomised so a run is reproducible.
"""

from __future__ import annotations

import copy
import math
import tomllib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import pamsim
from pamsim.errors import InputError
from pamsim.sweep import sweep_from_dict

from conftest import SCENARIOS

from pamsim.joints import JointScenario, is_joint_spec

EXAMPLES = {"joint_mutations": 900, "scenario_mutations": 1000, "scenario_random": 350, "scenario_text": 300, "sweep_mutations": 400}
FUZZ = settings(derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])

VALID = {p.stem: tomllib.loads(p.read_text()) for p in sorted(SCENARIOS.glob("*.toml"))
         if "base_scenario" not in p.read_text()}

SMALL_SWEEP = {"name": "fuzz", "base_scenario": str(SCENARIOS / "acra2012_fig4.toml"),
               "friction_models": ["load_dependent", "constant"],
               "axes": {"pressure_bar": [2.8, 3.6], "weight_N": [12.74, 22.74]},
               "frequency": {"pressure_bar": 3.6, "weight_N": [12.74, 22.74],
                             "pressure": {"source": "prescribed",
                                          "prescribed": {"kind": "lag", "time_s": 0.5, "tau_s": 0.01,
                                                         "final_gauge_bar": 3.6}}}}

# Values of every TOML type, with the awkward numbers a user can type.
NUMBERS = st.one_of(st.integers(min_value=-(2 ** 63), max_value=2 ** 63 - 1),
                    st.floats(allow_nan=True, allow_infinity=True),
                    st.sampled_from([0, -1, 1e308, -1e308, 1e-308, 5e-324, math.nan, math.inf, -math.inf, 2 ** 62]))
SCALARS = st.one_of(NUMBERS, st.booleans(), st.text(max_size=12),
                    st.sampled_from(["valve", "prescribed", "step", "trace", "LSODA", "../x", "", "constant"]))
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(st.text(max_size=8), inner, max_size=4)),
                      max_leaves=8)


def _paths(doc, prefix=()):
    """Every (path, value) in a nested dict, tables included."""
    for key, value in doc.items():
        yield prefix + (key,), value
        if isinstance(value, dict):
            yield from _paths(value, prefix + (key,))


def _mutate(doc: dict, data) -> dict:
    doc = copy.deepcopy(doc)
    for _ in range(data.draw(st.integers(1, 3), label="mutations")):
        paths = [p for p, _ in _paths(doc)]
        if not paths:
            break
        path = data.draw(st.sampled_from(paths), label="path")
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        action = data.draw(st.sampled_from(["drop", "replace", "replace", "add"]), label="action")
        if action == "drop":
            del parent[path[-1]]
        elif action == "replace":
            parent[path[-1]] = data.draw(VALUES, label="value")
        else:
            parent[data.draw(st.text(max_size=10), label="new key")] = data.draw(VALUES, label="new value")
    return doc


def _outcome_scenario(doc: dict) -> None:
    """A valid setup, or a one-line InputError; any other exception propagates and fails the test.  A
    document with joint tables is read as muscles on a joint."""
    if is_joint_spec(doc):
        try:
            joint = JointScenario.from_dict(doc, base_dir=SCENARIOS, origin="fuzz.toml")
        except InputError as exc:
            _one_line(exc)
            return
        assert joint.assembly().flatten().states and joint.duration_s > 0
        return
    try:
        sc = pamsim.Scenario.from_dict(doc, base_dir=SCENARIOS, origin="fuzz.toml")
    except InputError as exc:
        _one_line(exc)
        return
    model = sc.build_model()
    y0 = model.initial_state(sc.initial_contraction_m, sc.initial_pressure_gauge_Pa)
    assert np.all(np.isfinite(y0)), y0
    assert sc.duration_s > 0 and math.isfinite(sc.duration_s)


def _one_line(exc: InputError) -> None:
    message = str(exc)
    assert message and "\n" not in message, repr(message)


@settings(FUZZ, max_examples=EXAMPLES["scenario_mutations"])
@given(name=st.sampled_from(sorted(VALID)), data=st.data())
def test_mutated_scenarios_are_valid_or_one_line_errors(name, data):
    _outcome_scenario(_mutate(VALID[name], data))


JOINTS = sorted(name for name, doc in VALID.items() if is_joint_spec(doc))


@settings(FUZZ, max_examples=EXAMPLES["joint_mutations"])
@given(name=st.sampled_from(JOINTS), data=st.data())
def test_mutated_joint_scenarios_are_valid_or_one_line_errors(name, data):
    _outcome_scenario(_mutate(VALID[name], data))


@settings(FUZZ, max_examples=EXAMPLES["scenario_random"])
@given(doc=st.dictionaries(st.sampled_from(["name", "model", "parameters", "load", "pressure", "simulation",
                                            "solver", "controller", "x"]), VALUES, max_size=6))
def test_random_tables_are_valid_or_one_line_errors(doc):
    _outcome_scenario(doc)


@settings(FUZZ, max_examples=EXAMPLES["scenario_text"])
@given(name=st.sampled_from(sorted(VALID)), data=st.data())
def test_edited_toml_text_is_valid_or_one_line_errors(tmp_path_factory, name, data):
    text = (SCENARIOS / f"{name}.toml").read_text()
    for _ in range(data.draw(st.integers(1, 3), label="edits")):
        i = data.draw(st.integers(0, len(text)), label="at")
        j = data.draw(st.integers(i, min(len(text), i + 8)), label="to")
        text = text[:i] + data.draw(st.text(alphabet="=[]\"'.,-+0123456789eEnaifx_ \n#{}", max_size=6),
                                    label="insert") + text[j:]
    path = tmp_path_factory.mktemp("fuzz") / "doc.toml"
    path.write_text(text)
    try:
        sc = pamsim.load_scenario(path)
    except InputError as exc:
        _one_line(exc)
        return
    sc.build_model()


@settings(FUZZ, max_examples=EXAMPLES["sweep_mutations"])
@given(data=st.data())
def test_mutated_sweeps_are_valid_or_one_line_errors(data):
    doc = _mutate(SMALL_SWEEP, data)
    try:
        spec = sweep_from_dict(doc, base_dir=SCENARIOS, origin="fuzz_sweep.toml")
    except InputError as exc:
        _one_line(exc)
        return
    assert spec.cases


def test_the_fuzzing_covers_at_least_2000_documents():
    assert sum(EXAMPLES.values()) >= 2000


@pytest.mark.parametrize("name", sorted(VALID))
def test_the_unmutated_files_are_valid(name):
    """The seeds of the mutations are themselves valid (else every mutation would be an error)."""
    if is_joint_spec(VALID[name]):
        JointScenario.from_dict(VALID[name], base_dir=SCENARIOS, origin=name).assembly()
    else:
        pamsim.Scenario.from_dict(VALID[name], base_dir=SCENARIOS, origin=name).build_model()


def test_the_unmutated_sweep_is_valid():
    spec = sweep_from_dict(SMALL_SWEEP, base_dir=SCENARIOS, origin="fuzz_sweep.toml")
    assert len(spec.cases) == 4 and spec.frequency is not None
