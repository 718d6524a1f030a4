"""An element's form and numbers (``pamsim.components.element``) taken in one walk equal what two
separate walks give: a second implementation, the two walks as they were written before, run here on
every element the shipped scenarios and the registries build and on elements of unusual shapes."""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np
import pytest

from pamsim.components import element as E
from pamsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
FIG4 = ROOT / "scenarios" / "acra2012_fig4.toml"
SCENARIOS = ("acra2012_fig3", "acra2012_fig4", "acra2012_fig4_chou_hannaford", "acra2012_fig5", "acra2012_fig6a",
             "acra2012_fig6b", "closed_loop_position", "parallel_spring")
"""The shipped one-muscle scenarios (the sweep and joint files build theirs from these)."""


# ---------------------------------------------------------------- the reference: two walks
def _ref_numbers(element, out, path):
    for f in dataclasses.fields(element):
        value = getattr(element, f.name)
        if f.name in E.STRUCTURAL:
            continue
        if E._is_instance_of_dataclass(value):
            _ref_numbers(value, out, f"{path}{f.name}.")
        elif E._is_number(value):
            out[f.name if f.name not in out else f"{path}{f.name}"] = float(value)


def _ref_parameters(element):
    out = {}
    if E._is_instance_of_dataclass(element):
        _ref_numbers(element, out, "")
    return out


def _ref_key(element, baked=False):
    if E._is_instance_of_dataclass(element):
        items = []
        for f in dataclasses.fields(element):
            value = getattr(element, f.name)
            if f.name in E.STRUCTURAL or baked or not E._is_number(value):
                items.append((f.name, _ref_stable(value, baked or f.name in E.STRUCTURAL)))
        return (type(element).__module__, type(element).__qualname__, tuple(items))
    return _ref_stable(element, True)


def _ref_stable(value, baked):
    # E._stable, except that a dataclass is keyed by the reference walk
    if not isinstance(value, type) and callable(getattr(value, "code_key", None)):
        return value.code_key()
    if E._is_instance_of_dataclass(value):
        return _ref_key(value, baked)
    if isinstance(value, (tuple, list)):
        return (type(value).__name__, tuple(_ref_stable(v, True) for v in value))
    return E._stable(value, baked)


# ---------------------------------------------------------------- elements of unusual shapes
@dataclasses.dataclass(frozen=True)
class _Inner:
    k_N: float
    name: str = "inner"


@dataclasses.dataclass(frozen=True)
class _Keyed:
    """An element that says itself what its code depends on (as a spline surface does)."""

    a_m: float
    grid: np.ndarray = dataclasses.field(default_factory=lambda: np.arange(4.0))

    def code_key(self):
        return ("keyed", self.grid.shape)


@dataclasses.dataclass(frozen=True)
class _Odd:
    """Ints, bools, numpy scalars, None, a number in a choice field, a nested name met twice, a tuple of
    dataclasses, an array, a function, a partial, a class, an element keyed by itself."""

    k_N: int
    flag: bool
    scale: np.float64
    nothing: object
    negative_level: float
    inner: _Inner
    other: _Inner
    terms: tuple
    table: np.ndarray
    fn: object
    part: object
    cls: type
    keyed: _Keyed
    name: str = "odd"


def _odd(sign=1.0):
    return _Odd(3, True, np.float64(-0.0 * sign), None, 0.5, _Inner(1.0), _Inner(-0.0), (_Inner(2.0), 1, 2.5),
                np.linspace(0.0, 1.0, 5), np.exp, functools.partial(max, 1.0), _Inner, _Keyed(0.1))


def _shipped_elements():
    """Every element of the shipped one-muscle scenarios' models and of a few element choices on the Fig. 4 scenario."""
    fig4 = load_scenario(FIG4)
    scenarios = [load_scenario(ROOT / "scenarios" / f"{name}.toml") for name in SCENARIOS]
    scenarios += [fig4.with_changes(c) for c in (
        {"model": {"friction": "constant", "damping": "linear"}}, {"model": {"friction_negative_level": "abs"}},
        {"model": {"static_force": "gaylord"}},
        {"pressure": {"source": "prescribed", "prescribed": {"kind": "lag", "time_s": 0.5, "tau_s": 0.01,
                                                             "final_gauge_bar": 3.0}}})]
    for sc in scenarios:
        m = sc.build_model()
        yield from (m.static_force, m.friction, m.damping, m.stops, m.load)
        yield from (getattr(m.source, k) for k in ("valve", "chamber") if hasattr(m.source, k))


@pytest.mark.parametrize("element", [*_shipped_elements(), _odd(), _odd(-1.0), _Inner(-0.0), 1.5, None],
                         ids=lambda e: type(e).__name__)
def test_one_walk_gives_the_key_and_numbers_of_two(element):
    key, numbers = E.form_and_numbers(element)
    want = _ref_parameters(element)
    assert key == _ref_key(element)
    assert E.structure_key(element) == key
    assert list(numbers.items()) == list(want.items())  # the same names, in the same order
    assert [np.copysign(1.0, v) for v in numbers.values()] == [np.copysign(1.0, v) for v in want.values()]
    assert E.element_parameters(element) == want
    assert E.structure_key(element, baked=True) == _ref_key(element, baked=True)


def test_elements_that_differ_in_a_choice_or_a_baked_number_differ_in_form():
    base = _odd()
    for change in ({"negative_level": 0.25}, {"terms": (_Inner(2.0), 1, 2.0)}, {"table": np.zeros(5)},
                   {"keyed": _Keyed(0.1, np.arange(3.0))}):
        assert E.form_and_numbers(dataclasses.replace(base, **change))[0] != E.form_and_numbers(base)[0], change
    # A parameter's value is not form: it is a number of the flat model.
    moved = dataclasses.replace(base, k_N=4, inner=_Inner(7.0), keyed=_Keyed(0.2))
    assert E.form_and_numbers(moved)[0] == E.form_and_numbers(base)[0]
    assert E.form_and_numbers(moved)[1] == {**E.form_and_numbers(base)[1], "k_N": 4.0, "inner.k_N": 7.0, "a_m": 0.2}
