"""Components kept by the exact key of their arguments (``pamsim.components.element.kept_component``): one
component for arguments equal to the last bit and of the same types, a new one wherever ``==`` would mislead
(``0.0 == -0.0``, ``1 == 1.0 == True``), and assemblies of kept components equal to those made anew."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from pamsim.assemblies import scenario_assembly
from pamsim.assemblies import one_muscle
from pamsim.components import ViscousDamping
from pamsim.components import element as E
from pamsim.paperdata import acra2012_steady_state
from pamsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
FIG4 = ROOT / "scenarios" / "acra2012_fig4.toml"


# An element of another element and numbers of any type (frozen dataclasses, as the elements are).
_Inner = dataclasses.make_dataclass("_Inner", [("a", object), ("name", str, dataclasses.field(default="inner"))],
                                    frozen=True)
_Outer = dataclasses.make_dataclass("_Outer", [("inner", object), ("b", object, dataclasses.field(default=1.0))],
                                    frozen=True)


@pytest.mark.parametrize("x, y", [(0.0, -0.0), (1, 1.0), (1, True), (1.0, True), (float("nan"), -float("nan")),
                                  ((1.0,), [1.0]), ("1.0", 1.0), (None, 0.0)])
def test_exact_key_tells_apart_what_equality_takes_for_equal(x, y):
    assert E.exact_key(x) != E.exact_key(y)
    assert E.exact_key(_Outer(_Inner(x))) != E.exact_key(_Outer(_Inner(y)))
    assert E.exact_key({"k": x}) != E.exact_key({"k": y})


def test_exact_key_equal_for_equal_bits_in_other_objects():
    x = 0.1 + 0.2  # a float object made afresh each time
    assert E.exact_key(_Outer(_Inner(x), (2, "s", None))) == E.exact_key(_Outer(_Inner(0.1 + 0.2), (2, "s", None)))
    assert E.exact_key(_Outer(_Inner(x))) != E.exact_key(_Outer(_Inner(0.30000000000000004 + 1e-16)))


@pytest.mark.parametrize("value", [np.zeros(2), np.float64(1.0), lambda t: t, object(), {1: 2.0}])
def test_exact_key_refuses_what_it_cannot_tell_apart(value):
    assert E.exact_key(_Outer(_Inner(value))) is E._NO_KEY


def test_kept_component_shared_only_for_exactly_equal_arguments():
    damping = load_scenario(FIG4).build_model().damping
    same = dataclasses.replace(damping)  # another object, equal bits
    kept = E.kept_component(ViscousDamping, "damping", damping)
    assert E.kept_component(ViscousDamping, "damping", same) is kept
    assert E.kept_component(ViscousDamping, "other", damping) is not kept
    first = dataclasses.fields(damping)[0].name
    zero = dataclasses.replace(damping, **{first: 0.0})
    minus_zero = dataclasses.replace(damping, **{first: -0.0})
    a, b = E.kept_component(ViscousDamping, "damping", zero), E.kept_component(ViscousDamping, "damping", minus_zero)
    assert a is not b
    assert np.signbit(a.values[first]) != np.signbit(b.values[first])


def test_assemblies_of_kept_components_equal_those_made_anew(monkeypatch):
    """The 66 paper cases' assemblies: the same structure keys and parameter vectors (to the bit) as with
    every component made anew (``kept_component`` replaced by the plain constructor)."""
    base = load_scenario(FIG4)
    cases = [base.with_changes({"load": {"weight_N": float(r["weight_N"])},
                                "pressure": {"supply_gauge_bar": float(r["pressure_stable_bar"])}})
             for r in acra2012_steady_state()]
    kept = [scenario_assembly(s) for s in cases]
    monkeypatch.setattr(one_muscle, "kept_component", lambda cls, *args: cls(*args))
    anew = [scenario_assembly(s) for s in cases]
    assert len({id(a.by_name["muscle"]) for a in kept}) == 1  # shared, where made anew they are not
    for a, b in zip(kept, anew):
        assert a.structure_key() == b.structure_key()
        assert np.array_equal(np.array(a.parameter_values()).view(np.int64), np.array(b.parameter_values()).view(np.int64))
        assert [type(c) for c in a.components] == [type(c) for c in b.components]
