"""Generalized Prandtl-Ishlinskii operators (pamsim.hysteresis.prandtl_ishlinskii) against analytic
statements: rate independence, return-point memory and wiping-out, the area of a play's loop, the
analytic inverse composed with the operator (both ways) the identity to 1e-9 on random inputs, and
refused parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pamsim.errors import InputError
from pamsim.hysteresis.play import play, stop
from pamsim.hysteresis.prandtl_ishlinskii import PrandtlIshlinskii

from hysteresis_paths import resample

# thresholds, weights, offset, envelope scale (inf: the classical operator)
OPERATORS = {
    "classical": ([0.0, 0.1, 0.25, 0.5], [1.0, 0.4, 0.3, 0.2], 0.0, math.inf),
    "envelope": ([0.0, 0.1, 0.25, 0.5], [1.0, 0.4, 0.3, 0.2], 0.5, 2.0),
    "negative_weights": ([0.0, 0.05, 0.2, 0.4, 0.7], [2.0, -0.3, -0.4, -0.2, -0.3], -1.0, math.inf),
    "decreasing": ([0.0, 0.1, 0.3], [-3.0, -1.0, 0.5], 2.0, 1.5),
}
VERTICES = np.array([0.0, 1.0, -0.6, 0.7, 0.1, 1.0, -1.0, 0.0])


def pi_of(name):
    return PrandtlIshlinskii(*OPERATORS[name])


def sequential_play(u, r):
    """A second implementation of the play: ``z <- clip(z, u - r, u + r)`` sample by sample, from 0."""
    z, out = np.zeros(len(r)), []
    for x in u:
        z = np.minimum(np.maximum(z, x - np.asarray(r)), x + np.asarray(r))
        out.append(z.copy())
    return np.array(out)


def test_play_and_stop_against_the_sample_by_sample_update():
    rng = np.random.default_rng(0)
    u = np.concatenate([[0.0], np.cumsum(rng.normal(0, 0.2, 500))])
    u[100:110] = u[100]  # a flat stretch
    r = [0.0, 0.05, 0.3, 1.0]
    assert np.max(np.abs(play(u, r) - sequential_play(u, r))) < 1e-12
    assert np.max(np.abs(stop(u, r) - (u[:, None] - sequential_play(u, r)))) < 1e-12


@pytest.mark.parametrize("name", OPERATORS)
def test_rate_independent(name):
    # The path's vertices alone and denser samplings of it, as input at another rate would give: the same
    # output at the vertices.  (With an envelope the operator is exact for g(u) linear between samples,
    # so the classical operators are resampled and the envelope ones are compared on g's samples.)
    pi = pi_of(name)
    coarse = pi.run(VERTICES).output
    for per_segment, rng in ((40, None), (23, np.random.default_rng(5))):
        u, idx = resample(VERTICES, per_segment, rng)
        if not math.isinf(pi.envelope_scale):
            u, idx = pi.envelope_inverse(resample(pi.envelope(VERTICES), per_segment, rng)[0]), idx
        assert np.max(np.abs(pi.run(u).output[idx] - coarse)) < 1e-12


@pytest.mark.parametrize("name", OPERATORS)
def test_return_point_memory_and_wiping_out(name):
    pi = pi_of(name)
    with_minor = np.array([0.0, 0.8, 0.1, 0.8, 1.0, -0.5])
    without = np.array([0.0, 0.8, 1.0, -0.5])
    a, b = pi.run(with_minor), pi.run(without)
    assert np.max(np.abs(a.states[3] - a.states[1])) < 1e-15
    assert np.max(np.abs(a.output[3:] - b.output[1:])) < 1e-12


@pytest.mark.parametrize("amplitude", [0.3, 0.8, 1.2])
def test_loop_area_is_the_sum_of_the_plays_parallelograms(amplitude):
    # A play of half-width r on a cycle of span A > 2 r encloses a parallelogram of area 2 r (A - 2 r) in the
    # (u, z) plane, traversed counterclockwise (rising below, falling above), so the integral of z du is minus
    # that area; the operator's is the weighted sum (a negative weight, a loop the other way round).  The output is linear
    # between samples that include every corner (steps of 1e-3 divide r and A), so the trapezoid is exact.
    r, w, offset, _ = OPERATORS["negative_weights"]
    pi = PrandtlIshlinskii(r, w, offset)
    n = int(round(amplitude / 1e-3))
    u = np.concatenate([np.linspace(0, amplitude, n + 1), np.linspace(amplitude, -amplitude, 2 * n + 1)[1:],
                        np.linspace(-amplitude, amplitude, 2 * n + 1)[1:]])
    y = pi.run(u).output[n:]
    cycle = u[n:]
    area = -float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(cycle)))
    span = 2 * amplitude
    rr, ww = np.asarray(r), np.asarray(w)
    analytic = float(np.sum(np.where(span > 2 * rr, ww * 2 * rr * (span - 2 * rr), 0.0)))
    assert area == pytest.approx(analytic, rel=1e-9, abs=1e-12)


def test_inverse_thresholds_are_the_virgin_curve_at_the_thresholds():
    # Kuhnen's r'_j = sum_{i<=j} w_i (r_j - r_i) is the output on the first loading from rest at u = r_j,
    # and the inverse's slopes 1 / W_j: checked against the forward operator's own run.
    pi = PrandtlIshlinskii(*OPERATORS["classical"][:2])
    inv = pi.inverse().core
    assert np.allclose(inv.thresholds, pi.run(pi.thresholds).output, rtol=0, atol=1e-15)
    assert np.allclose(np.cumsum(inv.weights), 1 / np.cumsum(pi.weights), rtol=1e-15)


def random_operator(rng, sign, envelope):
    m = int(rng.integers(1, 12))
    r = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, m - 1))])
    w = np.concatenate([[1.0], rng.uniform(-0.5, 1.0, m - 1) / m])
    w[1:] = np.maximum(w[1:], -0.9 / m)  # every slope stays positive
    return PrandtlIshlinskii(r, sign * w * rng.uniform(0.5, 5), rng.normal(), envelope and rng.uniform(2.0, 4.0) or math.inf)


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("sign, envelope", [(1, False), (1, True), (-1, False), (-1, True)])
def test_inverse_composed_with_the_operator_is_the_identity(seed, sign, envelope):
    # From a state reached by a random history, a random input through the operator then its inverse (the
    # inverse's states from the operator's), and a random wanted output through the inverse then the
    # operator: both give their input back to 1e-9.
    rng = np.random.default_rng(seed)
    pi = random_operator(rng, sign, envelope)
    history = np.clip(np.cumsum(rng.normal(0, 0.4, 60)), -1.5, 1.5)
    p0 = pi.run(history).states[-1]
    u = np.concatenate([[history[-1]], np.clip(history[-1] + np.cumsum(rng.normal(0, 0.3, 400)), -1.5, 1.5)])
    forward = pi.run(u, p0)
    inverse = pi.inverse()
    q0 = pi.inverse_states(p0)
    assert np.max(np.abs(inverse.run(forward.output, q0).output - u)) < 1e-9
    y = forward.output[0] + np.concatenate([[0.0], np.cumsum(rng.normal(0, 0.1, 400))])
    y = np.clip(y, forward.output.min(), forward.output.max())  # within the operator's reach
    u_back = inverse.run(y, q0).output
    assert np.max(np.abs(pi.run(u_back, inverse.forward_states(q0)).output - y)) < 1e-9


@pytest.mark.parametrize("kwargs, message", [
    (dict(thresholds=[0.0, 0.2, 0.1], weights=[1, 1, 1]), "thresholds[2] = 0.1: thresholds must increase strictly"),
    (dict(thresholds=[0.0, 0.2, 0.2], weights=[1, 1, 1]), "thresholds[2] = 0.2: thresholds must increase strictly"),
    (dict(thresholds=[-0.1, 0.2], weights=[1, 1]), "thresholds[0] = -0.1: must be at least 0"),
    (dict(thresholds=[0.0, 0.2], weights=[1]), "weights: 1 values for 2 thresholds"),
    (dict(thresholds=[0.0], weights=[1], envelope_scale=0.0), "envelope_scale = 0.0: must be above 0"),
    (dict(thresholds=[0.0] + list(np.arange(1, 101) * 0.1), weights=[1] * 101), "thresholds: 101 values"),
])
def test_bad_parameters_are_refused_naming_the_key(kwargs, message):
    with pytest.raises(InputError) as info:
        PrandtlIshlinskii(**kwargs)
    assert message in str(info.value)


@pytest.mark.parametrize("r, w, message", [
    ([0.1, 0.2], [1.0, 1.0], "thresholds[0] = 0.1: the inverse needs r_0 = 0"),
    ([0.0, 0.2, 0.4], [1.0, -0.5, -0.5], "weights[2] = -0.5: the slope w_0 + ... + w_2 = 0.0"),
    ([0.0, 0.2], [1.0, -2.0], "weights[1] = -2.0: the slope w_0 + ... + w_1 = -1.0"),
])
def test_an_operator_without_inverse_is_refused(r, w, message):
    with pytest.raises(InputError) as info:
        PrandtlIshlinskii(r, w).inverse()
    assert message in str(info.value)


def test_the_inverse_refuses_an_output_beyond_the_envelope():
    pi = PrandtlIshlinskii([0.0], [1.0], 0.0, 1.0)  # y = tanh(u): |y| < 1
    with pytest.raises(InputError, match="envelope_scale = 1.0: the inverse asks for g"):
        pi.inverse().run(np.array([0.0, 0.5, 1.2]))


@pytest.mark.parametrize("k, f, k0", [([2e4, 5e3, 2e3], [10.0, 20.0, 25.0], -3000.0), ([8e3], [6.0], 500.0)])
def test_maxwell_slip_is_the_operator_with_the_slip_deflections_as_thresholds(k, f, k0):
    # k0 x - sum k_i d_i with d_i = x - P_{F_i/k_i}[x]: a Prandtl-Ishlinskii operator with thresholds 0 and F_i/k_i,
    # weights k0 - sum k_i and k_i, both relaxed at the first sample.
    from pamsim.hysteresis.maxwell_slip import MaxwellSlip

    x, _ = resample(np.array([0.01, 0.03, 0.005, 0.025, 0.012, 0.03, -0.01]), 17)
    delta = np.asarray(f) / np.asarray(k)
    order = np.argsort(delta)
    pi = PrandtlIshlinskii(np.concatenate([[0.0], delta[order]]),
                           np.concatenate([[k0 - sum(k)], np.asarray(k)[order]]))
    pull = k0 * x - MaxwellSlip(k, f).run(x).force_N
    assert np.max(np.abs(pi.run(x, np.full(len(k) + 1, x[0])).output - pull)) < 1e-9
