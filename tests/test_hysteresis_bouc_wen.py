"""Bouc-Wen (pamsim.hysteresis.bouc_wen): the integration along the input against the closed form for
n = 1 and against a tight reference for other n, rate independence to that tolerance, and refused parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pamsim.errors import InputError
from pamsim.hysteresis.bouc_wen import BoucWen

PATH_M = np.array([0.0, 0.03, 0.005, 0.025, 0.012, 0.03, -0.01, 0.0])
TOLERANCE = 1e-5
"""The stated accuracy of z, as a fraction of its saturation value z_u (pamsim.hysteresis.bouc_wen.STEP_FRACTION)."""


def closed_form_n1(z: float, dx: float, beta: float, gamma: float) -> float:
    """z after the input moves by dx for n = 1: the law is linear in z on each side of z = 0, an exponential
    approach on each side, switching where z crosses 0."""
    s = 1.0 if dx > 0 else -1.0
    remaining = abs(dx)
    # dz/dx = 1 - beta s |z|^0 z - gamma |z| = 1 - (beta s + gamma sgn z) z; in the travel variable
    # q = s x (dq > 0): dw/dq = 1 - c w with w = s z, c = beta + gamma (w >= 0) or beta - gamma (w < 0).
    w = s * z
    if w < 0:
        c = beta - gamma
        to_zero = (-w if c == 0 else math.log((1 / c - w) / (1 / c)) / c)
        if to_zero >= remaining:
            return s * (w + remaining if c == 0 else 1 / c + (w - 1 / c) * math.exp(-c * remaining))
        remaining -= to_zero
        w = 0.0
    c = beta + gamma
    return s * (1 / c + (w - 1 / c) * math.exp(-c * remaining))


@pytest.mark.parametrize("beta, gamma", [(300.0, 100.0), (100.0, 300.0), (200.0, -100.0), (50.0, 50.0)])
def test_n1_against_the_closed_form(beta, gamma):
    bw = BoucWen(1.0, beta, gamma, 1.0)
    z, expected = 0.0, [0.0]
    for dx in np.diff(PATH_M):
        z = closed_form_n1(z, dx, beta, gamma)
        expected.append(z)
    assert np.max(np.abs(bw.run(PATH_M).z_m - expected)) < TOLERANCE * bw.z_saturation_m


@pytest.mark.parametrize("beta, gamma, n", [(2e4, 1e4, 2.0), (1e6, 0.0, 3.0), (300.0, 100.0, 1.0)])
def test_against_a_tight_reference_integration(beta, gamma, n):
    bw = BoucWen(1.0, beta, gamma, n)
    z, expected = 0.0, [0.0]
    for dx in np.diff(PATH_M):
        s = math.copysign(1.0, dx)

        def rhs(x, v):
            return [1.0 - beta * s * abs(v[0]) ** (n - 1) * v[0] - gamma * abs(v[0]) ** n]
        z = solve_ivp(rhs, (0.0, dx), [z], method="DOP853", rtol=1e-12, atol=1e-15).y[0, -1]
        expected.append(z)
    assert np.max(np.abs(bw.run(PATH_M).z_m - expected)) < TOLERANCE * bw.z_saturation_m


def test_rate_independent_to_the_tolerance():
    bw = BoucWen(2e3, 300.0, 100.0, 1.5, -2500.0, 160.0)
    coarse = bw.run(PATH_M)
    x = np.concatenate([np.linspace(a, b, 31)[:-1] for a, b in zip(PATH_M[:-1], PATH_M[1:])] + [PATH_M[-1:]])
    fine = bw.run(x)
    assert np.max(np.abs(fine.z_m[::30] - coarse.z_m)) < TOLERANCE * bw.z_saturation_m


def test_force_is_the_documented_combination():
    bw = BoucWen(2e3, 300.0, 100.0, 1.0, -2500.0, 160.0)
    run = bw.run(PATH_M)
    assert np.allclose(run.force_N, 160.0 - 2500.0 * PATH_M + 2e3 * run.z_m, rtol=0, atol=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    (dict(exponent=0.0), "exponent = 0.0: must be above 0"),
    (dict(exponent=-1.0), "exponent = -1.0: must be above 0"),
    (dict(gamma_per_m_n=-300.0), "gamma_per_m_n = -300.0: beta + gamma must be above 0"),
    (dict(alpha_N_per_m=float("inf")), "alpha_N_per_m = inf: must be a finite number"),
])
def test_bad_parameters_are_refused_naming_the_key(kwargs, message):
    with pytest.raises(InputError) as info:
        BoucWen(**{**dict(alpha_N_per_m=1.0, beta_per_m_n=300.0, gamma_per_m_n=100.0), **kwargs})
    assert message in str(info.value)
