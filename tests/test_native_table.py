"""One table for the rig's constants and choices: Python reads its constants from it, every Python
registry entry runs natively or is refused cleanly by the native and FMU backends, and the engine's
libraries are cached and their compiler named."""

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
from pamsim.fmu.generate import c_source_dir
from pamsim.fmu.runner import start_values
from pamsim.native.backend import case_inputs
from pamsim.parameters import get_parameter_set
from pamsim.static_models.geometry import Braid

from conftest import SCENARIOS

REGISTRIES = {"static_force": STATIC_FORCE_MODELS, "friction": FRICTION_MODELS, "damping": DAMPING_MODELS,
              "friction_negative_level": dict.fromkeys(NEGATIVE_LEVEL_CHOICES), "source": {"valve": 0, "prescribed": 0}}


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


def _assert_refused_by_the_c_backends(scenario: pamsim.Scenario, key: str, value: str) -> bool:
    """The one-muscle FMU refuses a choice it does not offer, naming it, except a static force, which it
    runs through its force table; the native backend runs a static model written in symbols as generated
    C on the engine.  Returns whether the native case's static force is the model's own generated C."""
    where = core_table.SCENARIO_KEYS[key]
    if key == "static_force":
        table = core_table.C_CHOICES["static_force_model"].index("table")
        assert start_values(scenario)["static_force_model"] == table
        case = case_inputs(scenario)
        muscle = next(c for c in case.assembly.components if c.name == "muscle")
        return bool(muscle.traces)
    with pytest.raises(InputError, match=rf"{re.escape(where)} = {value!r}"):
        pamsim.simulate(scenario, backend="native")
    with pytest.raises(InputError, match=rf"{re.escape(where)} = {value!r}"):
        start_values(scenario)
    return False


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
    as the constant choice, bit for bit); the one-muscle FMU, whose run-time choices are a fixed set,
    refuses it by name rather than run another element (or zero friction) silently."""
    monkeypatch.setitem(registry, "added_in_python_only", builder)
    scenario = _scenario(key, "added_in_python_only")
    added = pamsim.simulate(scenario, backend="native")
    known = pamsim.simulate(_scenario(key, "constant"), backend="native")
    assert np.array_equal(added.x_m, known.x_m) and added.transitions == known.transitions
    where = core_table.SCENARIO_KEYS[key]
    with pytest.raises(InputError, match=rf"{re.escape(where)} = 'added_in_python_only'"):
        start_values(scenario)


def test_order_checks_are_shared_by_the_parameter_set_and_the_fmu(unzipped, capfd):
    from test_fmu import _initialise_with

    p = get_parameter_set("shadow_6x300_acra2012")
    for a, b in core_table.ORDER_CHECKS:
        bad = p.with_overrides({a: p[b]}, source="test")
        assert any(name == a and f"below {b}" in why for name, _, why in bad.violations())
        # The FMU's generated checks refuse the same pairs.
        capfd.readouterr()
        assert _initialise_with(unzipped, 2, {a: p[b]}) != 0
        assert f"invalid parameters: {a} = {p[b]:g}: must be below {b}" in capfd.readouterr().out


def test_engine_library_is_cached_where_documented_and_rebuilt_when_a_source_changes(tmp_path, monkeypatch):
    """``$PAMSIM_NATIVE_CACHE/engine/TAG/``: the same sources give the same file, an edited source a new one."""
    import shutil

    from pamsim.assemblies import scenario_assembly
    from pamsim.native import build, engine

    monkeypatch.setenv(build.CACHE_ENV, str(tmp_path / "cache"))
    monkeypatch.setattr(engine, "_LOADED", {})
    assembly = scenario_assembly(pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml"))
    first = engine.engine_library(assembly).path
    assert first.is_file() and first.parent.parent.parent == tmp_path / "cache"
    monkeypatch.setattr(engine, "_LOADED", {})
    assert engine.engine_library(assembly).path == first  # cached on disk: not rebuilt
    sources = tmp_path / "sources"
    shutil.copytree(c_source_dir(), sources)
    with open(sources / "src" / "pam_engine.c", "a") as fh:
        fh.write("\n/* an edit */\n")
    monkeypatch.setattr(engine, "c_source_dir", lambda: sources)
    monkeypatch.setattr(build, "c_source_dir", lambda: sources)
    monkeypatch.setattr(engine, "_LOADED", {})
    second = engine.engine_library(assembly).path
    assert second.is_file() and second.parent != first.parent


def test_missing_compiler_is_an_input_error(monkeypatch):
    from pamsim.native import build

    monkeypatch.setenv("CC", "")
    monkeypatch.setattr("shutil.which", lambda name: None)
    with pytest.raises(InputError, match="needs a C compiler"):
        build.compiler()


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
