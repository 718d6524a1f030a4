"""One table for what Python and C share: the committed C header is the generated one, Python reads
its constants from the table, and every Python registry entry either has a C counterpart or is
refused cleanly by the native and FMU backends."""

from __future__ import annotations

import re

import numpy as np

import pytest

import pamsim
from pamsim import core_table
from pamsim.elements.damping import DAMPING_MODELS
from pamsim.elements.friction import FRICTION_MODELS, NEGATIVE_LEVEL_CHOICES, ConstantCoulomb
from pamsim.elements.static_force import STATIC_FORCE_MODELS
from pamsim.elements.stops import EndStops
from pamsim.errors import InputError
from pamsim.fmu.generate import c_source_dir, shared_header
from pamsim.fmu.runner import start_values
from pamsim.model import Mode
from pamsim.native import library
from pamsim.native.backend import case_inputs
from pamsim.parameters import get_parameter_set
from pamsim.static_models.geometry import Braid

from conftest import SCENARIOS

REGISTRIES = {"static_force": STATIC_FORCE_MODELS, "friction": FRICTION_MODELS, "damping": DAMPING_MODELS,
              "friction_negative_level": dict.fromkeys(NEGATIVE_LEVEL_CHOICES), "source": {"valve": 0, "prescribed": 0}}


def test_committed_shared_header_is_the_generated_one():
    committed = (c_source_dir() / "src" / "pam_shared.h").read_text()
    assert committed == shared_header(), "run: python -m pamsim.fmu.generate --shared-header"


def test_header_carries_every_shared_constant_mode_and_choice():
    text = shared_header()
    for const in core_table.CONSTANTS:
        assert re.search(rf"#define {const.c_name} {re.escape(repr(const.value))} ", text)
    for m in Mode:
        assert f"PAM_{m.name} = {int(m)}" in text
    for key, choices in core_table.C_CHOICES.items():
        for i, choice in enumerate(choices):
            assert f"PAM_{core_table.c_identifier(key)}_{core_table.c_identifier(choice)} = {i}" in text


def test_the_core_uses_the_generated_names_not_literals():
    """The C core takes its constants and choice codes from pam_shared.h: no copies of the numbers."""
    core = (c_source_dir() / "src" / "pam_core.c").read_text()
    assert not re.search(r"case [0-9]+:", core)
    assert "sqrt(3.0)" not in core
    for literal in ("1e-9", "1e-3", "1.0e5"):
        assert not re.search(rf"#define \w+ {re.escape(literal)}\b", core)


def test_the_core_takes_its_inputs_in_the_order_python_sends_them():
    """``segment_u``'s columns are the variable table's inputs in table order; the C side lists them by hand."""
    source = (c_source_dir() / "src" / "pam_native.c").read_text()
    for prefix in ("R", "VR"):
        listed = re.search(rf"INPUT_{prefix}\[PAM_NATIVE_NU\] = \{{([^}}]*)\}}", source).group(1)
        assert tuple(n.strip().removeprefix(f"{prefix}_") for n in listed.split(",")) == library.INPUTS


def test_python_reads_the_same_constants():
    p = get_parameter_set("shadow_6x300_acra2012")
    stops = EndStops.from_parameters(p)
    assert stops.min_rebound_speed_m_s == core_table.MIN_REBOUND_SPEED_M_S
    b = Braid.from_parameters(p).b
    assert stops.x_high_m == pytest.approx(p["L0_m"] - b / core_table.BRAID_LOCK_SEC2 ** 0.5, rel=1e-15)


def _scenario(key: str, value: str) -> pamsim.Scenario:
    base = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    where = core_table.SCENARIO_KEYS[key]
    section, name = where.split(".")
    if where == "pressure.source":
        return base.with_changes({"pressure": {"source": value, "prescribed": {"kind": "constant", "value_gauge_bar": 3}}})
    if key == "static_force":
        # A library model runs on a shipped muscle that gives its parameters (None: no shipped muscle does).
        from pamsim import static_models
        from pamsim.muscles import load_muscle, shipped_names

        spec = static_models.get(value)
        muscle = next((m for m in ["shadow_6x300_acra2012", *shipped_names()]
                       if not spec.missing(load_muscle(m).parameters)), None)
        if muscle is None:
            return None
        return base.with_changes({"model": {"muscle": muscle, "static_force": value}})
    return base.with_changes({section: {name: value}})


def _assert_refused_by_the_c_backends(scenario: pamsim.Scenario, key: str, value: str) -> None:
    """Native and FMU refuse the choice naming it, except a static force, which the FMU runs through
    the force table (the C counterpart of any static model): its nodes hold the model's own force.  The
    native backend runs a static model written in symbols as generated C on the engine (no table), and
    any other through the table.  Returns whether the native case is the engine's."""
    where = core_table.SCENARIO_KEYS[key]
    if key == "static_force":
        table = core_table.C_CHOICES["static_force_model"].index("table")
        assert start_values(scenario)["static_force_model"] == table
        case = case_inputs(scenario)
        if case.assembly is not None:
            muscle = next(c for c in case.assembly.components if c.name == "muscle")
            assert case.table is None and muscle.traces
            return True
        assert case.ints[library.INT_INDEX["static_force_model"]] == table
        t = case.table
        i, j = t.shape[0] // 2, t.shape[1] // 2
        x = t.x_min_m + i * (t.x_max_m - t.x_min_m) / (t.shape[0] - 1)
        p = t.p_min_Pa + j * (t.p_max_Pa - t.p_min_Pa) / (t.shape[1] - 1)
        assert t.values[i, j, 0] == pytest.approx(float(scenario.static_model().force_N(x, p)), rel=1e-12, abs=1e-9)
        return False
    with pytest.raises(InputError, match=rf"{re.escape(where)} = {value!r}"):
        pamsim.simulate(scenario, backend="native")
    with pytest.raises(InputError, match=rf"{re.escape(where)} = {value!r}"):
        start_values(scenario)


@pytest.mark.parametrize("key", sorted(REGISTRIES))
def test_every_registry_entry_has_a_c_counterpart_or_is_refused_cleanly(key):
    checked, on_engine = 0, 0
    for value in REGISTRIES[key]:
        if value in core_table.C_CHOICES[key]:
            continue  # implemented in C: the conformance suite compares it with Python
        scenario = _scenario(key, value)
        if scenario is None:
            continue  # a static model no shipped muscle gives the parameters of
        on_engine += bool(_assert_refused_by_the_c_backends(scenario, key, value))
        checked += 1
    if key == "static_force":
        assert checked >= 10 and on_engine >= 10  # every closed-form model a shipped muscle gives


# Static forces live in the library registry, read-only; the library's own models that C lacks are the
# case of test_every_registry_entry_has_a_c_counterpart_or_is_refused_cleanly[static_force] above.
@pytest.mark.parametrize("key, registry, builder", [
    ("friction", FRICTION_MODELS, ConstantCoulomb.from_parameters),
])
def test_a_new_python_element_runs_natively_from_its_symbols_and_the_fmu_refuses_it(monkeypatch, key, registry,
                                                                                     builder):
    """An element added to a Python registry alone: the native backend generates it from its own
    functions on symbols (here the constant law under a new name: the same code, so the same numbers
    as the constant choice, bit for bit); the FMU, whose core is hand-written, refuses it by name
    rather than run another element (or zero friction) silently."""
    monkeypatch.setitem(registry, "added_in_python_only", builder)
    scenario = _scenario(key, "added_in_python_only")
    added = pamsim.simulate(scenario, backend="native")
    known = pamsim.simulate(_scenario(key, "constant"), backend="native")
    assert np.array_equal(added.x_m, known.x_m) and added.transitions == known.transitions
    where = core_table.SCENARIO_KEYS[key]
    with pytest.raises(InputError, match=rf"{re.escape(where)} = 'added_in_python_only'"):
        start_values(scenario)


def test_order_checks_are_shared_by_the_parameter_set_and_the_core():
    from pamsim.native import library

    p = get_parameter_set("shadow_6x300_acra2012")
    for a, b in core_table.ORDER_CHECKS:
        bad = p.with_overrides({a: p[b]}, source="test")
        assert any(name == a and f"below {b}" in why for name, _, why in bad.violations())
    # The core checks the same pairs: a scenario's parameters swapped past each other are refused.
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
    from pamsim.native.backend import _run_core, case_inputs

    case = case_inputs(sc)
    for a, b in core_table.ORDER_CHECKS:
        reals = case.reals.copy()
        reals[library.REAL_INDEX[a]] = reals[library.REAL_INDEX[b]]
        out = _run_core([case.__class__(reals, case.ints, case.duration_s, case.n_samples, case.segment_t_s,
                                   case.segment_u, case.max_events, case.model)], [10])
        assert out["status"][0] == 1 and out["messages"][0].startswith(f"invalid parameters: {a} = ")
        assert f"must be below {b}" in out["messages"][0]


def test_library_is_cached_where_documented_and_rebuilt_when_a_source_changes(tmp_path, monkeypatch):
    """``$PAMSIM_NATIVE_CACHE/TOKEN/``: the same sources give the same file, an edited source a new one."""
    import shutil

    from pamsim.native import build

    monkeypatch.setenv(build.CACHE_ENV, str(tmp_path / "cache"))
    first = build.library_path()
    assert first.is_file() and first.parent.parent == tmp_path / "cache"
    assert build.library_path() == first  # cached: not rebuilt
    sources = tmp_path / "sources"
    shutil.copytree(c_source_dir(), sources)
    with open(sources / "src" / "pam_native.c", "a") as fh:
        fh.write("\n/* an edit */\n")
    monkeypatch.setattr(build, "c_source_dir", lambda: sources)
    second = build.library_path()
    assert second.is_file() and second.parent != first.parent


def test_missing_compiler_is_an_input_error(monkeypatch):
    from pamsim.native import build

    monkeypatch.setenv("CC", "")
    monkeypatch.setattr("shutil.which", lambda name: None)
    with pytest.raises(InputError, match="needs a C compiler"):
        build.library_path()


@pytest.mark.parametrize("args", [
    ["run", "{fig4}", "--backend", "native", "-o", "{out}"],
    ["fmu", "build", "-o", "{out}/m.fmu"],
])
def test_a_cc_that_does_not_exist_is_named_as_the_c_compiler(monkeypatch, tmp_path, args):
    from conftest import SCENARIOS, run_cli

    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setenv("PAMSIM_NATIVE_CACHE", str(tmp_path / "cache"))  # no library built earlier to reuse
    out = tmp_path / "out"
    # A new process: this one may hold the library loaded by an earlier test.
    r = run_cli(*[a.format(fig4=SCENARIOS / "acra2012_fig4.toml", out=out) for a in args])
    assert r.returncode == 2
    line = r.stderr.strip()
    assert "\n" not in line and "Traceback" not in line
    assert "CC = '/nonexistent/cc'" in line and "C compiler" in line
    assert not out.exists()
