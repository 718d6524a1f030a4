"""The ``steps`` signal (pamsim.signals.PiecewiseConstant): a sampled command held between its samples.

Read from a scenario with every mistake refused by key; held exactly by the native backend (no
midpoint holds: its segments are the signal's steps); the same runs on both backends; the FMU's knots
give the same values.
"""

from __future__ import annotations

import numpy as np
import pytest

import pamsim
from pamsim.fmu.preset import input_signal
from pamsim.scenario import ScenarioError
from pamsim.signals import PiecewiseConstant


def _scenario(command=None, prescribed=None, duration_s=1.0):
    pressure = ({"source": "valve", "supply_gauge_bar": 3.6, "command": command} if prescribed is None
                else {"source": "prescribed", "prescribed": prescribed})
    return pamsim.Scenario.from_dict({"load": {"weight_N": 22.74}, "pressure": pressure,
                                      "simulation": {"duration_s": duration_s, "sample_rate_Hz": 100.0}})


def test_values_between_and_at_the_times_and_the_breakpoints():
    sig = PiecewiseConstant((0.1, 0.2, 0.5), (0.3, -1.0, 0.7))
    t = np.array([0.0, 0.0999, 0.1, 0.15, 0.2, 0.49, 0.5, 3.0])
    expected = [0.3, 0.3, 0.3, 0.3, -1.0, -1.0, 0.7, 0.7]
    assert sig(t).tolist() == expected
    assert [sig(float(x)) for x in t] == expected
    assert sig.breakpoints == (0.1, 0.2, 0.5) and sig.final_value == 0.7


def test_a_scenario_reads_a_steps_command_and_a_steps_pressure():
    sc = _scenario({"kind": "steps", "times_s": [0, 0.25, 0.5], "values": [1.0, 0.0, -0.5]})
    assert sc.build_model().source.command == PiecewiseConstant((0.0, 0.25, 0.5), (1.0, 0.0, -0.5))
    sc = _scenario(prescribed={"kind": "steps", "times_s": [0.0, 0.5], "values_gauge_bar": [2.0, 3.0]})
    assert sc.build_model().source.p_gauge_Pa == PiecewiseConstant((0.0, 0.5), (2e5, 3e5))
    assert sc.final_pressure_gauge_Pa == 3e5


@pytest.mark.parametrize("command, message", [
    ({"kind": "steps", "times_s": [0.0, 0.5], "values": [1.0]}, "pressure.command.values = '1 values': must be as many"),
    ({"kind": "steps", "times_s": [0.0, 0.5, 0.5], "values": [1, 0, 1]}, r"times_s\[2\] = 0.5: must be after"),
    ({"kind": "steps", "times_s": [-0.1, 0.5], "values": [1, 0]}, r"times_s\[0\] = -0.1: must not be negative"),
    ({"kind": "steps", "times_s": [], "values": []}, "times_s = \\[\\]: must be a non-empty list"),
    ({"kind": "steps", "times_s": 0.5, "values": [1]}, "times_s = 0.5: must be a non-empty list"),
    ({"kind": "steps", "times_s": [0.0, "1"], "values": [1, 0]}, r"times_s\[1\] = '1': must be a number"),
    ({"kind": "steps", "times_s": [0.0, 1.0], "values": [1, float("nan")]}, r"values\[1\] = nan: must be a finite"),
    ({"kind": "steps", "times_s": [0.0, 1.0], "values": [1, 1.5]}, "valve command must stay within"),
    ({"kind": "steps", "times_s": [0.0]}, "missing key pressure.command.values"),
    ({"kind": "steps", "times_s": [0.0], "values": [0.0], "value": 1}, "unknown key pressure.command.value "),
])
def test_mistakes_are_refused_by_key(command, message):
    with pytest.raises(ScenarioError, match=message):
        _scenario(command)


def test_a_prescribed_steps_pressure_beyond_the_rating_is_refused():
    with pytest.raises(ScenarioError, match="exceeds the muscle's rating"):
        _scenario(prescribed={"kind": "steps", "times_s": [0.0, 0.5], "values_gauge_bar": [2.0, 5.0]})


def test_native_holds_the_steps_exactly_and_agrees_with_python():
    times = [k * 0.05 for k in range(20)]
    values = np.random.default_rng(0).uniform(-1.0, 1.0, 20).tolist()
    sc = _scenario({"kind": "steps", "times_s": times, "values": values})
    native, python = pamsim.simulate(sc, backend="native"), pamsim.simulate(sc, backend="python")
    # one segment per step (a midpoint hold would cut one per output sample: 100 of them)
    assert native.stats["segments"] == 20 + native.stats["events"]
    assert [e.kind for e in native.transitions] == [e.kind for e in python.transitions]
    assert np.abs(native.x_m - python.x_m).max() < 5e-6
    held = PiecewiseConstant(tuple(times), tuple(values))
    assert np.array_equal(python.signals["valve_command"], held(python.t_s))


def test_the_fmu_carries_a_steps_signal_as_repeated_knots():
    sig = PiecewiseConstant((0.0, 0.1, 0.2, 0.5), (0.3, -1.0, 0.2, 0.7))
    fmu = input_signal(sig, "")
    t = np.concatenate([np.linspace(0.0, 1.0, 101), [0.1, 0.2, 0.5, np.nextafter(0.2, 0.0)]])
    assert [fmu(float(x)) for x in t] == [sig(float(x)) for x in t]
