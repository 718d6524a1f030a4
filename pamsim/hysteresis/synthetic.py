"""Synthetic loops from known parameters, for recovery tests and the documentation's example: a
prescribed-length cycle with minor loops, the pull of a model with a linear static part, seeded noise."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ..errors import InputError
from . import checks
from .bouc_wen import BoucWen
from .loop_data import LoopData
from .maxwell_slip import MaxwellSlip
from .prandtl_ishlinskii import PrandtlIshlinskii

CYCLE_M = (0.0, 0.03, 0.005, 0.025, 0.012, 0.03, 0.0)
"""The contraction's turning points [m] of the default cycle: a major loop with two minor loops inside it,
ending where it started."""


def contraction_path(points_m=CYCLE_M, step_m: float = 1e-4, rate_m_per_s: float = 0.005) -> tuple[np.ndarray, np.ndarray]:
    """``(t_s, x_m)``: straight lines through ``points_m`` sampled every ``step_m`` (turning points
    included) at the constant rate ``rate_m_per_s``."""
    pieces = [np.array([points_m[0]], dtype=float)]
    for a, b in zip(points_m[:-1], points_m[1:]):
        n = max(1, int(round(abs(b - a) / step_m)))
        pieces.append(np.linspace(a, b, n + 1)[1:])
    x = np.concatenate(pieces)
    travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(x)))])
    return travel / rate_m_per_s, x


def synthetic_loop(pull_N: Callable[[np.ndarray], np.ndarray], noise_N: float = 0.0, seed: int = 0,
                   pressure_Pa: float = 300e3, points_m=CYCLE_M, label: str = "synthetic") -> LoopData:
    """A loop of the pull ``pull_N(x)`` [N] over the cycle ``points_m``, with Gaussian noise of standard
    deviation ``noise_N`` on the force (seeded by ``seed``), at the constant pressure ``pressure_Pa``."""
    t, x = contraction_path(points_m)
    noise = np.random.default_rng(seed).normal(0.0, noise_N, x.size) if noise_N > 0 else 0.0
    return LoopData(t, np.full(x.size, pressure_Pa), x, pull_N(x) + noise, f"<{label} seed {seed}>")


def maxwell_slip_pull(stiffness_N_per_m, slip_force_N, offset_N: float, k0_N_per_m: float):
    """The pull ``F0 + k0 x - sum k_i d_i`` of Maxwell-slip elements relaxed at the first sample."""
    model = MaxwellSlip(stiffness_N_per_m, slip_force_N)
    return lambda x: offset_N + k0_N_per_m * x - model.run(x).force_N


def pull_from_parameters(model: str, parameters: dict[str, float], thresholds_m=None) -> Callable:
    """The pull ``x -> F`` of ``model`` with ``parameters`` named as :func:`pamsim.hysteresis.fit_hysteresis`
    reports them (the relation of :mod:`pamsim.hysteresis.fit`, relaxed at the first sample).

    Maxwell-slip: ``F0_N``, ``k0_N_per_m`` and ``k<i>_N_per_m``, ``F<i>_N`` for ``i = 1..N``; Prandtl-Ishlinskii:
    ``F0_N``, ``w<j>_N_per_m`` for ``j = 0..m-1`` (one per threshold of ``thresholds_m``) and optionally
    ``envelope_scale_m``; Bouc-Wen: ``F0_N``, ``k_e_N_per_m``, ``alpha_N_per_m``, ``beta_per_m_n``,
    ``gamma_per_m_n``, ``n``.  A missing, unknown or out-of-range value raises :class:`InputError` naming it.
    """
    builders = {"maxwell_slip": _maxwell_slip_pull, "pi": _pi_pull, "bouc_wen": _bouc_wen_pull}
    if model not in builders:
        raise InputError(f"model = {model!r}: choose from {', '.join(builders)}")
    params = dict(parameters)
    pull, used = builders[model](params, thresholds_m)
    unknown = sorted(set(params) - used)
    if unknown:
        raise InputError(f"{unknown[0]} = {params[unknown[0]]!r}: not a parameter of {model} "
                         f"(its parameters: {', '.join(sorted(used))})")
    return pull


def _take(params: dict, key: str, minimum: float | None = None, strict: bool = False, default=None) -> float:
    if key not in params and default is None:
        raise InputError(f"{key}: missing (give {key}=VALUE)")
    return checks.number(key, params.get(key, default), minimum, strict, infinite=default == math.inf)


def _maxwell_slip_pull(params: dict, thresholds_m) -> tuple[Callable, set[str]]:
    n = sum(1 for k in params if k.startswith("k") and k.endswith("_N_per_m") and k[1:-8].isdigit() and int(k[1:-8]))
    checks.count("elements (the number of k<i>_N_per_m)", n)
    stiffness = [_take(params, f"k{i}_N_per_m", 0.0, strict=True) for i in range(1, n + 1)]
    slip = [_take(params, f"F{i}_N", 0.0) for i in range(1, n + 1)]
    pull = maxwell_slip_pull(stiffness, slip, _take(params, "F0_N"), _take(params, "k0_N_per_m"))
    return pull, {"F0_N", "k0_N_per_m", *(f"k{i}_N_per_m" for i in range(1, n + 1)),
                  *(f"F{i}_N" for i in range(1, n + 1))}


def _pi_pull(params: dict, thresholds_m) -> tuple[Callable, set[str]]:
    if thresholds_m is None:
        raise InputError("thresholds: missing: a Prandtl-Ishlinskii loop needs its thresholds")
    r = np.asarray(thresholds_m, dtype=float)
    weights = [_take(params, f"w{j}_N_per_m") for j in range(r.size)]
    pi = PrandtlIshlinskii(r, weights, _take(params, "F0_N"), _take(params, "envelope_scale_m", 0.0, True, math.inf))
    pull = lambda x: pi.run(x, np.full(r.size, float(pi.envelope(x[0])))).output  # noqa: E731 -- relaxed at x[0]
    return pull, {"F0_N", "envelope_scale_m", *(f"w{j}_N_per_m" for j in range(r.size))}


def _bouc_wen_pull(params: dict, thresholds_m) -> tuple[Callable, set[str]]:
    names = ("F0_N", "k_e_N_per_m", "alpha_N_per_m", "beta_per_m_n", "gamma_per_m_n")
    f0, ke, alpha, beta, gamma = (_take(params, k) for k in names)
    bw = BoucWen(-alpha, beta, gamma, _take(params, "n", 0.0, strict=True), ke, f0)  # the pull's -alpha z
    return (lambda x: bw.run(x).force_N), {*names, "n"}


RECOVERY_CASES = {
    "maxwell_slip_3": ("maxwell_slip", {"F0_N": 150.0, "k0_N_per_m": -3000.0, "k1_N_per_m": 2e4, "F1_N": 10.0,
                                        "k2_N_per_m": 5e3, "F2_N": 20.0, "k3_N_per_m": 2e3, "F3_N": 25.0}, None),
    "maxwell_slip_2": ("maxwell_slip", {"F0_N": 220.0, "k0_N_per_m": -5000.0, "k1_N_per_m": 8e3, "F1_N": 6.0,
                                        "k2_N_per_m": 1.5e3, "F2_N": 15.0}, None),
    "pi_envelope": ("pi", {"F0_N": 150.0, "w0_N_per_m": -6500.0, "w1_N_per_m": 1500.0, "w2_N_per_m": 1000.0,
                           "envelope_scale_m": 0.04}, [0.0, 0.003, 0.008]),
    "bouc_wen": ("bouc_wen", {"F0_N": 160.0, "k_e_N_per_m": -2500.0, "alpha_N_per_m": 2000.0, "beta_per_m_n": 150.0,
                              "gamma_per_m_n": 50.0, "n": 1.5}, None),
}
"""Hidden parameter sets of the recovery tests and of ``examples/hysteresis_recovery.py``: ``name: (model,
parameters, PI thresholds [m])``.  Invented, not measured (no licensed hysteresis loop of these muscles is
known to pamsim): pulls of 5 to 250 N over 30 mm of contraction, loops 10 to 60 N wide, traversed the way
friction makes them (the pull lower while the muscle contracts than while it is stretched)."""


def recovery_loop(name: str, noise_N: float, seed: int) -> LoopData:
    """The loop of :data:`RECOVERY_CASES` ``[name]`` with force noise ``noise_N`` seeded by ``seed``."""
    model, params, thresholds = RECOVERY_CASES[name]
    return synthetic_loop(pull_from_parameters(model, params, thresholds), noise_N, seed, label=name)


def fit_known_structure(name: str, data: LoopData):
    """Fit ``data`` with the structure of :data:`RECOVERY_CASES` ``[name]`` (its model, its N, its thresholds),
    so that every fitted parameter has a true value to compare with; returns the :class:`~.fit.ModelFit`."""
    from .fit import fit_bouc_wen, fit_maxwell_slip, fit_pi

    model, params, thresholds = RECOVERY_CASES[name]
    if model == "maxwell_slip":
        return fit_maxwell_slip(data, sum(1 for k in params if k.startswith("F") and k != "F0_N"))
    if model == "pi":
        return fit_pi(data, thresholds_m=thresholds)
    return fit_bouc_wen(data)
