"""Maxwell-slip elements (pamsim.hysteresis.maxwell_slip) against analytic statements: exact and rate
independent for piecewise-linear input, return-point memory and wiping-out, the dissipated energy equal to
the loop area, the Coulomb limit, restart from the element states, and refused parameters."""

from __future__ import annotations

import numpy as np
import pytest

from pamsim.errors import InputError
from pamsim.hysteresis.maxwell_slip import MaxwellSlip

from hysteresis_paths import resample

# (stiffness [N/m], slip force [N]) per element: one element, three spread ones, five equal deflections.
MODELS = {
    "one": ([1.0e4], [5.0]),
    "three": ([2.0e4, 5.0e3, 2.0e3], [10.0, 20.0, 25.0]),
    "five_equal_deflection": ([1e3, 2e3, 3e3, 4e3, 5e3], [2.0, 4.0, 6.0, 8.0, 10.0]),
}
VERTICES_M = np.array([0.0, 0.03, 0.005, 0.025, 0.012, 0.03, -0.01, 0.0])


def sequential(k, f, x):
    """A second implementation: each sample's deflection clipped to +-F/k, element by element."""
    k, f = np.asarray(k), np.asarray(f)
    d = np.zeros(k.size)
    out = []
    for a, b in zip(x[:-1], x[1:]):
        d = np.clip(d + (b - a), -f / k, f / k)
        out.append(float(k @ d))
    return np.array([0.0] + out)


@pytest.mark.parametrize("name", MODELS)
def test_rate_independent_and_exact_for_piecewise_linear_input(name):
    # The vertices alone and two denser samplings of the same path give the same force at the vertices: a
    # step update that integrated in time (or clipped late) would not.
    k, f = MODELS[name]
    m = MaxwellSlip(k, f)
    coarse = m.run(VERTICES_M).force_N
    for per_segment, rng in ((50, None), (37, np.random.default_rng(3))):
        x, idx = resample(VERTICES_M, per_segment, rng)
        fine = m.run(x)
        assert np.max(np.abs(fine.force_N[idx] - coarse)) < 1e-9
        assert np.max(np.abs(fine.force_N - sequential(k, f, x))) < 1e-9


@pytest.mark.parametrize("name", MODELS)
def test_return_point_memory_and_wiping_out(name):
    k, f = MODELS[name]
    m = MaxwellSlip(k, f)
    up, minor, on = [0.0, 0.02], [0.02, 0.011, 0.02], [0.02, 0.03, 0.0]
    with_minor = np.array(up[:-1] + minor + on[1:])
    without = np.array(up + on[1:])
    a, b = m.run(with_minor), m.run(without)
    # Back at the reversal point the states are those it left there (return-point memory) ...
    assert np.max(np.abs(a.deflection_m[3] - a.deflection_m[1])) < 1e-15
    # ... and the minor loop is wiped out: the rest of the path is as if it never happened.
    assert np.max(np.abs(a.force_N[3:] - b.force_N[1:])) < 1e-9


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("amplitude_m", [0.004, 0.01])
def test_dissipated_energy_per_cycle_equals_the_loop_area(name, amplitude_m):
    # The run's own count, sum F_i * slip distance, against the area of the closed loop (the trapezoid rule
    # is exact here: the step, 1e-5 m, divides every slip deflection, so the force is linear on each
    # step) and against each element's parallelogram, 2 F_i (A - 2 F_i / k_i) for A > 2 F_i / k_i.
    k, f = MODELS[name]
    m = MaxwellSlip(k, f)
    x = np.concatenate([np.linspace(0, amplitude_m, 401), np.linspace(amplitude_m, -amplitude_m, 801)[1:],
                        np.linspace(-amplitude_m, amplitude_m, 801)[1:]])
    settle = m.run(x[:401])
    cycle = m.run(x[400:], settle.deflection_m[-1])
    area = float(np.sum(0.5 * (cycle.force_N[1:] + cycle.force_N[:-1]) * np.diff(x[400:])))
    span = 2 * amplitude_m
    delta = np.asarray(f) / np.asarray(k)
    analytic = float(np.sum(np.where(span > 2 * delta, 2 * np.asarray(f) * (span - 2 * delta), 0.0)))
    assert cycle.dissipated_J == pytest.approx(area, rel=1e-9)
    assert cycle.dissipated_J == pytest.approx(analytic, rel=1e-9)


@pytest.mark.parametrize("slip_force_N", [0.5, 3.0])
def test_one_stiff_element_is_a_coulomb_element(slip_force_N):
    # N = 1, k -> inf: the force is +-F_1 by the sign of the velocity as soon as the input has moved F/k.
    m = MaxwellSlip([1e12], [slip_force_N])
    t = np.linspace(0, 2, 2001)
    x = 0.01 * np.sin(2 * np.pi * t) + 0.002 * np.sin(7 * np.pi * t)
    run = m.run(x)
    v = np.diff(x)
    assert np.max(np.abs(run.force_N[1:] - slip_force_N * np.sign(v))) <= 1e-15 * slip_force_N
    assert not run.sticking[1:].any()


def test_a_run_restarts_from_its_element_states():
    m = MaxwellSlip(*MODELS["three"])
    x, _ = resample(VERTICES_M, 20)
    whole = m.run(x)
    first = m.run(x[:57])
    rest = m.run(x[56:], first.deflection_m[-1])
    assert np.array_equal(np.concatenate([first.force_N, rest.force_N[1:]]), whole.force_N)


def test_sticking_elements_after_a_reversal():
    # After a reversal every element sticks until the input has come back 2 F_i / k_i: the elements with
    # slip deflections 0.5, 4 and 12.5 mm after 1, 8 and 25 mm of return travel.
    m = MaxwellSlip(*MODELS["three"])
    run = m.run(np.array([0.0, 0.03, 0.0295, 0.025, 0.02]))
    assert run.sticking[1].tolist() == [False, False, False]  # all slide at the end of the loading branch
    assert run.sticking[2].tolist() == [True, True, True]
    assert run.sticking[3].tolist() == [False, True, True]
    assert run.sticking[4].tolist() == [False, False, True]


@pytest.mark.parametrize("k, f, message", [
    ([1e3, -5.0], [1.0, 1.0], "stiffness_N_per_m[1] = -5.0: must be above 0"),
    ([1e3, 0.0], [1.0, 1.0], "stiffness_N_per_m[1] = 0.0: must be above 0"),
    ([1e3], [-1.0], "slip_force_N[0] = -1.0: must be at least 0"),
    ([], [], "stiffness_N_per_m: 0 values: give 1 to 100"),
    ([1.0] * 101, [1.0] * 101, "stiffness_N_per_m: 101 values: give 1 to 100"),
    ([1e3, 2e3], [1.0], "slip_force_N: 1 values for 2 stiffnesses"),
    ([float("nan")], [1.0], "stiffness_N_per_m[0] = nan: must be finite"),
])
def test_bad_parameters_are_refused_naming_the_key(k, f, message):
    with pytest.raises(InputError) as info:
        MaxwellSlip(k, f)
    assert message in str(info.value) and "\n" not in str(info.value)
