"""Dynamic identification, the ACRA 2012 paper's eq. (13): find the coefficients that minimise the
sum of squared differences between simulated and measured contraction over a time window, summed
over traces, with the exact hybrid stick/slip simulator inside.

Each trace is simulated from rest at its first sample.  With a recorded pressure the simulation is
driven by it (thinned to knots, :mod:`.pressure_input`), as the paper did; without one, by the
scenario's own pressure source (its valve).  The load of a trace is its ``weight_N`` column, a
value given by the caller, or the scenario's.

The simulations of one optimiser iteration (every trace, and every finite-difference column of the
Jacobian) are independent tasks sent to a :class:`concurrent.futures.Executor`, as sweeps do.  On
the native backend (``backend="native"``, :mod:`.native_fit`) they are one library call instead (the
generic engine running the generated model, or the C core for a force table), split into one chunk
per worker when there is an executor.

Finite differences: the residuals are exact simulations, but each carries integration error of
about ``rtol`` times the state scale and event times located to the solver's tolerance.  A step of
``fd_relative_step`` (default 1e-3) times the coefficient changes the trajectory by orders of
magnitude more than that noise, while staying small enough for a linear model of the response
(docs/identification.md has the measured figures).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.optimize import differential_evolution, least_squares

from ..errors import InputError
from ..parameters import ParameterSet
from ..scenario import Scenario
from .choices import DYNAMIC_BACKENDS, DYNAMIC_DEFAULT_FREE, FD_RELATIVE_STEP
from .columns import TraceData
from .dynamic_starts import (SCREEN_POINTS_PER_START, global_box, hop_point, random_points, sign_bounds,
                             typical_scales)
from .fit_quality import noise_level_mm, quality_warnings
from .plausibility import check_trace
from .pressure_input import KNOT_TOLERANCE_PA, PiecewiseLinearInput, thinned_input
from .trials import FIT_RTOL, PythonTrials, SimulationTask, run_simulation, trace_scenario
from .uncertainty import Uncertainty, linearised_uncertainty


def make_trials(problem: "DynamicProblem", backend: str):
    """The simulations of ``problem`` on ``backend``; refuses (``InputError``) a backend name or a
    scenario setting the backend cannot honour, before anything runs."""
    if backend == "python":
        return PythonTrials(problem)
    if backend == "native":
        from .native_fit import NativeTrials  # the C library only when asked for

        return NativeTrials(problem, FIT_RTOL)
    raise InputError(f"--backend = {backend!r}: choose from {', '.join(DYNAMIC_BACKENDS)}")


@dataclass(frozen=True)
class DynamicProblem:
    """Traces, scenario, free coefficients and windows of a dynamic fit."""

    scenario: Scenario
    traces: tuple[TraceData, ...]
    loads_N: tuple[float, ...]
    windows: tuple[np.ndarray, ...]
    free: tuple[str, ...]
    bounds: tuple[np.ndarray, np.ndarray]
    inputs: tuple[PiecewiseLinearInput | None, ...]

    def tasks(self, theta: np.ndarray) -> list[SimulationTask]:
        """One simulation task per trace with the coefficients ``theta`` (in the order of ``free``)."""
        overrides = dict(zip(self.free, map(float, theta)))
        out = []
        for tr, w, sig in zip(self.traces, self.loads_N, self.inputs):
            t_rel = tr.t_s - tr.t_s[0]
            pt, pv = (sig.t_s, sig.values) if sig is not None else (None, None)
            out.append(SimulationTask(self.scenario, overrides, w, float(t_rel[-1]), pt, pv, t_rel))
        return out

    def residuals_from(self, simulated: Sequence[np.ndarray]) -> np.ndarray:
        """Window residuals [mm] of every trace, concatenated (eq. 13 in mm^2)."""
        parts = [(x - tr.x_m)[m] * 1e3 for x, tr, m in zip(simulated, self.traces, self.windows)]
        r = np.concatenate(parts)
        return np.where(np.isfinite(r), r, 1e3)  # a failed simulation: 1 m off at every sample


class _Objective:
    """Residuals and Jacobian with one batch of parallel simulations each; counts simulations."""

    def __init__(self, problem: DynamicProblem, executor, fd_step: float, trials=None):
        self.problem = problem
        self.trials = trials if trials is not None else PythonTrials(problem)
        self.executor = executor
        self.fd_step = fd_step
        self.n_simulations = 0
        self._cache: tuple[bytes, list[np.ndarray]] | None = None

    def simulate(self, theta: np.ndarray) -> list[np.ndarray]:
        key = np.asarray(theta, dtype=float).tobytes()
        if self._cache is None or self._cache[0] != key:
            self.n_simulations += len(self.problem.traces)
            self._cache = (key, self.trials(np.asarray(theta, dtype=float), self.executor))
        return self._cache[1]

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        return self.problem.residuals_from(self.simulate(theta))

    def steps(self, theta: np.ndarray) -> np.ndarray:
        return self.fd_step * np.maximum(np.abs(theta), 1.0)

    def jacobian(self, theta: np.ndarray) -> np.ndarray:
        """Forward differences, every column's simulations in one parallel batch."""
        r0 = self.residuals(theta)
        h = self.steps(theta)
        lo, hi = self.problem.bounds
        h = np.where(theta + h > hi, -h, h)  # step inward at an upper bound
        thetas = []
        for j in range(len(theta)):
            t = np.array(theta, dtype=float)
            t[j] += h[j]
            thetas.append(t)
        n_tr = len(self.problem.traces)
        self.n_simulations += len(thetas) * n_tr
        sims = self.trials(np.array(thetas), self.executor)
        J = np.empty((r0.size, len(theta)))
        for j in range(len(theta)):
            J[:, j] = (self.problem.residuals_from(sims[j * n_tr:(j + 1) * n_tr]) - r0) / h[j]
        return J


class _SumOfSquares:
    """Scalar eq. (13) cost for differential evolution (picklable; simulations run in this process)."""

    def __init__(self, problem: DynamicProblem):
        self.problem = problem

    def __call__(self, theta: np.ndarray) -> float:
        r = self.problem.residuals_from([run_simulation(t) for t in self.problem.tasks(theta)])
        return float(r @ r)


class _PopulationSumOfSquares:
    """Eq. (13) cost of a whole population at once (differential evolution's ``vectorized`` form):
    one batch of simulations per generation, for the native backend; counts its simulations (scipy's
    ``nfev`` counts calls when vectorized)."""

    def __init__(self, problem: DynamicProblem, trials, executor):
        self.problem, self.trials, self.executor = problem, trials, executor
        self.n_simulations = 0

    def __call__(self, thetas: np.ndarray) -> np.ndarray:
        thetas = np.atleast_2d(np.asarray(thetas, dtype=float).T)  # scipy passes (n_coefficients, S)
        sims = self.trials(thetas, self.executor)
        self.n_simulations += len(sims)
        n_tr = len(self.problem.traces)
        costs = [self.problem.residuals_from(sims[k * n_tr:(k + 1) * n_tr]) for k in range(len(thetas))]
        return np.array([r @ r for r in costs])


@dataclass
class DynamicFit:
    """Result of a dynamic fit; ``to_json()`` gives ``fit.json``."""

    problem: DynamicProblem
    theta: np.ndarray
    start: np.ndarray
    uncertainty: Uncertainty
    simulated_m: list[np.ndarray]
    start_simulated_m: list[np.ndarray]
    rms_contraction_mm: list[float]
    rms_pooled_mm: float
    n_simulations: int
    wall_time_s: float
    success: bool
    message: str
    per_trace: list[dict] | None = None
    backend: str = "python"
    n_starts: int = 0
    noise_mm: list[float] = field(default_factory=list)
    """Each trace's contraction noise in the window, estimated from the trace alone (:mod:`.fit_quality`)."""
    warnings: list[str] = field(default_factory=list)
    """How the fit misses the noise level; ``success`` is False when there are any."""
    converged: bool = True
    """Whether the local optimiser reported convergence."""

    @property
    def traces(self) -> tuple[TraceData, ...]:
        """The measured traces fitted."""
        return self.problem.traces

    @property
    def windows(self) -> tuple[np.ndarray, ...]:
        """Boolean mask of each trace's samples inside the fitting window."""
        return self.problem.windows

    @property
    def loads_N(self) -> tuple[float, ...]:
        """Hanging load [N] of each trace."""
        return self.problem.loads_N

    @property
    def parameters(self) -> dict[str, float]:
        """The fitted coefficients by name."""
        return dict(zip(self.problem.free, map(float, self.theta)))

    def to_json(self) -> dict:
        """The fit as JSON-ready values: traces and their hashes, coefficients with start values, standard
        errors and correlations, and the errors.
        """
        u = self.uncertainty
        names = [tr.origin for tr in self.traces]
        body = {"scenario": self.problem.scenario.origin, "traces": names,
                "traces_sha256": [tr.sha256 for tr in self.traces], "loads_N": list(self.loads_N),
                "pressure_recorded": [tr.p_gauge_Pa is not None for tr in self.traces],
                "parameters": self.parameters,
                "start": dict(zip(self.problem.free, map(float, self.start))),
                "standard_errors": dict(zip(u.names, map(float, u.standard_errors))),
                "correlation": u.correlation_table(),
                "inseparable_pairs": [[a, b, r] for a, b, r in u.inseparable_pairs()],
                "not_identified": list(u.not_identified()),
                "rms_contraction_mm": {"per_trace": dict(zip(names, self.rms_contraction_mm)),
                                       "pooled": self.rms_pooled_mm},
                "n_simulations": self.n_simulations, "wall_time_s": self.wall_time_s, "backend": self.backend,
                "noise_mm": dict(zip(names, self.noise_mm)), "n_starts": self.n_starts,
                "warnings": list(self.warnings), "converged": self.converged,
                "success": self.success, "message": self.message}
        if self.per_trace is not None:
            body["per_trace"] = self.per_trace
        return body


def make_problem(scenario: Scenario, traces: Sequence[TraceData], free: Sequence[str] | None = None,
                 window_s: tuple[float, float] | None = None, loads_N: Sequence[float | None] | None = None,
                 knot_tolerance_Pa: float = KNOT_TOLERANCE_PA) -> DynamicProblem:
    """Check the choices of a dynamic fit and bundle them.

    The load of trace i is ``loads_N[i]`` if given, else its ``weight_N`` column, else the
    scenario's load.  ``window_s`` (times of the traces' own clock) defaults to the whole trace.
    """
    if not traces:
        raise InputError("fit dynamic: give at least one trace")
    free = tuple(free) if free else DYNAMIC_DEFAULT_FREE
    params = scenario.parameters
    _check_free(free, params)
    loads = _trace_loads(scenario, traces, loads_N)
    windows = [_window(tr, window_s, len(free)) for tr in traces]
    if not knot_tolerance_Pa > 0:
        raise InputError(f"--knot-tolerance-Pa = {knot_tolerance_Pa!r}: must be positive")
    lower = sign_bounds(free, [params.entries[n].lower for n in free])
    upper = np.array([params.entries[n].upper for n in free], dtype=float)
    inputs = tuple(None if tr.p_gauge_Pa is None else thinned_input(tr.t_s, tr.p_gauge_Pa, knot_tolerance_Pa)
                   for tr in traces)
    return DynamicProblem(scenario, tuple(traces), tuple(loads), tuple(windows), free, (lower, upper), inputs)


def check_data(scenario: Scenario, traces: Sequence[TraceData],
               loads_N: Sequence[float | None] | None = None) -> list[str]:
    """Refuse step responses no rig can give for the scenario's muscle; return one-line warnings on implausible
    ones (:func:`pamsim.identification.plausibility.check_trace`, on the scale of the scenario's muscle: its rest
    length, upper stop, rating and blocked force)."""
    params = scenario.parameters
    loads = _trace_loads(scenario, traces, loads_N)
    model = scenario.build_model()
    x_max = model.stops.x_high_m  # where the scenario's simulations stop, not the braid lock
    rated = params["rated_pressure_gauge_Pa"] if "rated_pressure_gauge_Pa" in params else math.inf
    static = model.static_force

    def blocked(p_gauge_Pa):
        return static.force_N(0.0, scenario.final_pressure_gauge_Pa if p_gauge_Pa is None else p_gauge_Pa)

    with np.errstate(all="ignore"):  # a force table or polynomial far outside its range: a number, not a warning
        return [line for tr, w in zip(traces, loads) for line in check_trace(tr, w, params["L0_m"], x_max, rated,
                                                                               blocked)]


def _check_free(free: tuple[str, ...], params: ParameterSet) -> None:
    for n in free:
        if n not in params:
            raise InputError(f"--free: {n!r} is not a parameter of the scenario's parameter set {params.name!r}")
    if len(set(free)) != len(free):
        raise InputError(f"--free = {','.join(free)}: a name appears twice")


def _trace_loads(scenario: Scenario, traces: Sequence[TraceData],
                 loads_N: Sequence[float | None] | None) -> list[float]:
    """The hung weight of each trace [N]: given, else the trace's ``weight_N`` column, else the scenario's load."""
    if loads_N is not None and len(loads_N) != len(traces):
        raise InputError(f"--load-N: {len(loads_N)} values for {len(traces)} traces")
    loads = []
    for i, tr in enumerate(traces):
        given = loads_N[i] if loads_N is not None else None
        w = given if given is not None else tr.weight_N
        if w is None:
            w = scenario.mass_kg * scenario.parameters["g_m_s2"]
        if not w > 0:
            raise InputError(f"--load-N = {w!r}: must be positive")
        loads.append(float(w))
    return loads


def _window(trace: TraceData, window_s: tuple[float, float] | None, n_free: int) -> np.ndarray:
    """The trace's samples inside the window (its whole span without one), which must outnumber the free
    coefficients."""
    t0, t1 = window_s if window_s is not None else (trace.t_s[0], trace.t_s[-1])
    mask = trace.window(t0, t1)
    if mask.sum() < n_free + 1:
        raise InputError(f"--window = {t0:g}:{t1:g}: only {int(mask.sum())} samples of {trace.origin} inside "
                         f"(trace spans {trace.t_s[0]:g}..{trace.t_s[-1]:g} s)")
    return mask


def _rms_per_trace(problem: DynamicProblem, sims: Sequence[np.ndarray]) -> list[float]:
    return [float(np.sqrt(np.mean(((x - tr.x_m)[m] * 1e3) ** 2))) for x, tr, m in
            zip(sims, problem.traces, problem.windows)]


def _local(problem: DynamicProblem, theta0: np.ndarray, executor, fd_step: float, max_iterations: int, trials,
           typical: np.ndarray | None = None):
    obj = _Objective(problem, executor, fd_step, trials)
    # The optimiser works in coefficients over their start values; a start of 0 has no size of its own
    # and takes its typical scale, so that a unit step means as much for it as for the others.
    scale = np.where(np.abs(theta0) > 0, np.abs(theta0), 1.0 if typical is None else typical)
    lo, hi = problem.bounds
    res = least_squares(lambda z: obj.residuals(z * scale), np.clip(theta0, lo, hi) / scale,
                        jac=lambda z: obj.jacobian(z * scale) * scale, bounds=(lo / scale, hi / scale),
                        method="trf", x_scale=1.0, max_nfev=max_iterations, xtol=1e-8, ftol=1e-10, gtol=1e-10)
    theta = res.x * scale
    J = obj.jacobian(theta)
    return theta, res, obj, J


DEFAULT_STARTS = {"python": 0, "native": 16}
"""Extra starts of a dynamic fit by backend: on native a local fit takes a few tenths of a second, and
sixteen (eight screened random points, then eight hops from the best fit so far) reached the RMS at the
truth in every synthetic case of docs/identification.md but one, which the noise flag marks; on Python
each start costs as much as the whole fit."""
GLOBAL_POPSIZE = 15
"""Differential evolution's population per free coefficient (scipy's default)."""


def fit_dynamic(scenario: Scenario, traces: Sequence[TraceData], free: Sequence[str] | None = None,
                window_s: tuple[float, float] | None = None, loads_N: Sequence[float | None] | None = None,
                executor=None, global_search: bool = False, global_span: float = 1.0,
                global_iterations: int = 30, per_trace: bool = False, seed: int = 0,
                fd_step: float = FD_RELATIVE_STEP, max_iterations: int = 30,
                knot_tolerance_Pa: float = KNOT_TOLERANCE_PA, backend: str = "python",
                n_starts: int | None = None) -> DynamicFit:
    """Fit coefficients (default the paper's D1, D2, N2, N1, N0) to step responses, eq. (13).

    Parameters
    ----------
    scenario : Scenario
        Everything that is not fitted: parameter set, element choices, pressure source (used for
        traces without a recorded pressure), solver.
    traces : sequence of TraceData
    free : sequence of str, optional
        Coefficients to fit; start values are the scenario's.
    window_s : (float, float), optional
        Time window of the residuals, on the traces' clock.
    loads_N : sequence, optional
        Hung weight per trace [N] (None entries: the trace's column or the scenario's load).
    executor : concurrent.futures.Executor, optional
        Runs each iteration's simulations in parallel; None runs them here.
    global_search : bool
        First run differential evolution (seeded with ``seed``, ``global_iterations`` generations of
        :data:`GLOBAL_POPSIZE` points per coefficient) over the start plus or minus ``global_span`` times
        the larger of its size and its typical scale (:mod:`.dynamic_starts`), within the bounds, then the
        local fit from its best point.
    per_trace : bool
        Also fit every trace alone (the paper's Table 4 layout).
    fd_step : float
        Relative forward-difference step of the Jacobian.
    max_iterations : int
        Residual evaluations allowed to each local fit.
    knot_tolerance_Pa : float
        Largest deviation [Pa] of the thinned recorded pressure from the recorded one.
    backend : {"python", "native"}
        Simulator of the fit.  ``native`` runs each optimiser step's simulations (each
        differential-evolution generation's too) in one call of the native library, one per worker
        with an executor; it follows a recorded pressure exactly, as the Python backend does (see
        :mod:`.native_fit`), and refuses, before anything runs, a scenario setting it cannot honour.
    n_starts : int, optional
        Extra local fits: ``n_starts - n_starts // 2`` from the best of 25 times as many seeded random
        points, then ``n_starts // 2`` hops, each from a seeded point near the best fit so far
        (:mod:`.dynamic_starts`); the fit with the lowest cost wins.  Default :data:`DEFAULT_STARTS` of
        the backend.

    Returns
    -------
    DynamicFit
        ``success`` is False when the optimiser did not converge or when the fit misses the traces'
        noise level (``warnings`` says how, :mod:`.fit_quality`).
    """
    start_time = time.perf_counter()
    n_starts = _check_choices(fd_step, max_iterations, n_starts, backend)
    problem = make_problem(scenario, traces, free, window_s, loads_N, knot_tolerance_Pa)
    check_data(scenario, traces, loads_N)  # refuses the impossible; the command line prints the warnings
    trials = make_trials(problem, backend)
    theta0 = np.array([scenario.parameters[n] for n in problem.free], dtype=float)
    scales = typical_scales(problem, theta0)
    start, n_sim = theta0, 0
    if global_search:
        start, n_sim = _global_start(problem, trials, executor, theta0, scales, global_span, global_iterations, seed,
                                     backend)
    n_random, n_hops = _split_starts(n_starts)
    screened, n_screen = _screened_starts(problem, trials, executor, theta0, scales, n_random, seed)
    best = _best_local(problem, np.vstack([start, screened]), scales, executor, fd_step, max_iterations, trials)
    theta, res, obj, J = _hops(problem, best, scales, n_hops, seed, executor, fd_step, max_iterations, trials)
    n_sim += n_screen
    n_sim += obj.n_simulations
    sims = obj.simulate(theta)
    r = problem.residuals_from(sims)
    start_sims = trials(theta0, executor)
    n_sim += len(problem.traces)
    table, n_table = (_per_trace_table(problem, theta, executor, fd_step, max_iterations, backend)
                      if per_trace and len(problem.traces) > 1 else (None, 0))
    rms = _rms_per_trace(problem, sims)
    pooled = float(np.sqrt(np.mean(r ** 2)))
    noise = [noise_level_mm(tr.x_m[m]) for tr, m in zip(problem.traces, problem.windows)]
    flags = quality_warnings([Path(tr.origin).name for tr in problem.traces], rms, noise, pooled)
    return DynamicFit(problem, theta, theta0, linearised_uncertainty(problem.free, J, r), sims, start_sims, rms,
                      pooled, n_sim + n_table, time.perf_counter() - start_time, bool(res.success) and not flags,
                      str(res.message), table, backend, n_starts, noise, flags, bool(res.success))


def _check_choices(fd_step: float, max_iterations: int, n_starts: int | None, backend: str) -> int:
    """Refuse bad options of :func:`fit_dynamic`; the number of extra starts."""
    if not (0 < fd_step < 0.1):
        raise InputError(f"--fd-step = {fd_step!r}: must lie in (0, 0.1)")
    if max_iterations < 1:
        raise InputError(f"--max-iterations = {max_iterations}: must be at least 1")
    if n_starts is None:
        return DEFAULT_STARTS.get(backend, 0)
    if n_starts < 0:
        raise InputError(f"--starts = {n_starts}: must not be negative")
    return int(n_starts)


def _global_start(problem, trials, executor, theta0, scales, span, iterations, seed, backend):
    """Differential evolution's best point, and the simulations it took."""
    box = global_box(theta0, scales, problem.bounds, span)
    if backend == "python":
        de_workers = executor.map if executor is not None else 1
        cost, vectorized = _SumOfSquares(problem), False
    else:
        # a whole generation per call, one batch (scipy then evaluates in this process)
        cost, vectorized, de_workers = _PopulationSumOfSquares(problem, trials, executor), True, 1
    de = differential_evolution(cost, box, maxiter=iterations, popsize=GLOBAL_POPSIZE, seed=seed, polish=False,
                                workers=de_workers, updating="deferred", tol=1e-6, x0=np.clip(theta0, *zip(*box)),
                                vectorized=vectorized)
    return de.x, (cost.n_simulations if vectorized else de.nfev * len(problem.traces))


def _screened_starts(problem, trials, executor, theta0, scales, n_starts: int, seed: int) -> tuple[np.ndarray, int]:
    """The ``n_starts`` lowest-cost of ``25 n_starts`` seeded random points (one batch of simulations), and
    the simulations it took."""
    if n_starts == 0:
        return np.empty((0, len(problem.free))), 0
    points = random_points(theta0, scales, problem.bounds, SCREEN_POINTS_PER_START * n_starts, seed)
    cost = _PopulationSumOfSquares(problem, trials, executor)
    order = np.argsort(cost(points.T), kind="stable")
    return points[order[:n_starts]], cost.n_simulations


def _best_local(problem, starts, scales, executor, fd_step, max_iterations, trials):
    """The local fit from every start (rows); the lowest cost wins, its objective counting every start's
    simulations."""
    best, n_sim = None, 0
    for theta0 in starts:
        fit = _local(problem, theta0, executor, fd_step, max_iterations, trials, scales)
        n_sim += fit[2].n_simulations
        if best is None or fit[1].cost < best[1].cost:
            best = fit
    best[2].n_simulations = n_sim
    return best


def _split_starts(n_starts: int) -> tuple[int, int]:
    """The extra starts as screened random points and hops: half each, the odd one a random point."""
    return n_starts - n_starts // 2, n_starts // 2


def _hops(problem, best, scales, n_hops: int, seed: int, executor, fd_step, max_iterations, trials):
    """Basin hopping: ``n_hops`` local fits, each from a seeded point near the best fit so far
    (:func:`.dynamic_starts.hop_point`), which a lower cost replaces; the objective of the best counts
    every fit's simulations."""
    rng = np.random.default_rng([seed, 1])  # a stream apart from the screened points'
    n_sim = best[2].n_simulations
    for _ in range(n_hops):
        fit = _local(problem, hop_point(best[0], scales, problem.bounds, rng), executor, fd_step, max_iterations,
                     trials, scales)
        n_sim += fit[2].n_simulations
        if fit[1].cost < best[1].cost:
            best = fit
    best[2].n_simulations = n_sim
    return best


def _per_trace_table(problem, theta, executor, fd_step, max_iterations, backend) -> tuple[list[dict], int]:
    """Each trace fitted alone from the pooled optimum (the paper's Table 4 layout), and the simulations."""
    table, n_sim = [], 0
    for i, tr in enumerate(problem.traces):
        sub = replace(problem, traces=(tr,), loads_N=(problem.loads_N[i],), windows=(problem.windows[i],),
                      inputs=(problem.inputs[i],))
        th_i, _, obj_i, _ = _local(sub, theta, executor, fd_step, max_iterations, make_trials(sub, backend))
        n_sim += obj_i.n_simulations
        table.append({"trace": tr.origin, "load_N": problem.loads_N[i],
                      "pressure_final_bar": (float(tr.p_gauge_Pa[-1]) / 1e5 if tr.p_gauge_Pa is not None
                                             else problem.scenario.final_pressure_gauge_Pa / 1e5),
                      **dict(zip(problem.free, map(float, th_i))),
                      "rms_contraction_mm": _rms_per_trace(sub, obj_i.simulate(th_i))[0]})
    return table, n_sim


__all__ = ["fit_dynamic", "check_data", "DynamicFit", "DynamicProblem", "make_problem", "make_trials", "run_simulation",
           "SimulationTask", "trace_scenario", "DYNAMIC_BACKENDS", "DYNAMIC_DEFAULT_FREE", "FD_RELATIVE_STEP"]
