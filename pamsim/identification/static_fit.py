"""Static identification: fit a static force model's coefficients to static tests.

Two objectives (docs/identification.md):

``force``
    the model's force at the measured pressure and contraction minus the measured force or hung
    weight [N] (the ACRA 2012 paper's training approach, its eq. 10);
``contraction``
    the model's static equilibrium under the load minus the measured contraction [mm].  Tests
    where the load was not lifted (measured contraction at or below ``censor_threshold_m``) are
    censored: they only add a residual when the model predicts a lift above the threshold.

Both go to :func:`scipy.optimize.least_squares` in coefficients scaled by their starting values,
with bounds from the parameter ranges, an optional robust loss and an optional seeded multi-start.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Mapping, Sequence

import numpy as np
from scipy.optimize import least_squares

from ..elements.stops import EndStops
from ..errors import InputError
from ..muscles import DERIVED, WALL_PAIR, geometry_violation, rederive
from ..parameter_schema import LOCK_DEG, UPPER_STOP_DEFAULT
from ..parameters import ParameterSet, dynamics_parameters, known_parameter
from .choices import CENSOR_THRESHOLD_M, LOSSES, OBJECTIVES
from .columns import StaticData
from .crossval import cross_validate
from .equilibrium import equilibrium_m, slope_N_per_m
from .models import build_static, check_model, default_free, missing_inputs, optional_defaults, static_parameters
from .plausibility import check_static_data, duplicate_groups
from .profile import profile_intervals, t_quantile
from .uncertainty import Uncertainty, information_criteria, linearised_uncertainty

_FD_REL = 1e-6
"""Relative step of the force sensitivities dF/dtheta (the force is a smooth, cheap function)."""
_PENALTY = 1e6
"""Residual [mm or N] of every test at coefficients outside the muscle's geometry (a wall as thick as the
radius, a braid at its locking angle) or that the model cannot be built from: far above any residual a
real muscle gives, so the optimiser steps back rather than stopping there."""


@dataclass(frozen=True)
class StaticProblem:
    """The data, the model and the free coefficients of one static fit (everything but the values)."""

    data: StaticData
    model: str
    base: ParameterSet
    free: tuple[str, ...]
    objective: str
    censor_threshold_m: float
    upper_stop: tuple[str, str] | None
    """``(at, source)`` of the muscle file's ``[upper_stop]`` table, or None where it names none (the default
    choice, :data:`pamsim.parameter_schema.UPPER_STOP_DEFAULT`)."""
    bounds: tuple[np.ndarray, np.ndarray]

    @cached_property
    def weights(self) -> np.ndarray | None:
        """Per test, the inverse of its standard deviation in the residual's unit (mm or N), or None
        without a ``sigma`` column."""
        d = self.data
        if d.sigma is None:
            return None
        return 1.0 / (d.sigma * (1e3 if self.objective == "contraction" else 1.0))

    @property
    def censored(self) -> np.ndarray:
        """Tests where a hung load was not lifted (only hanging-weight data are censored)."""
        if self.data.kind != "weight":
            return np.zeros(len(self.data), dtype=bool)
        return self.data.contraction_m <= self.censor_threshold_m

    def parameter_set(self, theta: np.ndarray, source: str = "fit trial point") -> ParameterSet:
        """The muscle at ``theta``, its derived values (a wall thickness from the radii, ...) following."""
        moved = self.base.with_overrides(dict(zip(self.free, map(float, theta))), source=source)
        return ParameterSet(moved.name, moved.citation, rederive(moved.entries)) if self.derives else moved

    @cached_property
    def derives(self) -> bool:
        """Whether the base parameter set derives a parameter from others (so the fit re-derives it)."""
        return any(p.source.startswith(DERIVED) for p in self.base.entries.values())

    @property
    def start(self) -> np.ndarray:
        """The free coefficients' starting values."""
        return np.array([self.base[n] for n in self.free], dtype=float)

    def params(self, theta: np.ndarray) -> dict[str, float]:
        """The parameters with the coefficients ``theta`` (in the order of ``free``) in place."""
        return dict(self.parameter_set(theta))

    def force(self, theta: np.ndarray):
        """The static force model with the coefficients ``theta``."""
        return build_static(self.model, self.params(theta))

    def stops(self, theta: np.ndarray) -> EndStops:
        """The end stops of the muscle at ``theta`` with the fit's static model, the upper one where the
        muscle's choice puts it, as in a simulation of the muscle (:meth:`EndStops.for_model`; a
        ValueError if the choice cannot be met there)."""
        values = self.params(theta)
        return self._stops(values, build_static(self.model, values))

    @property
    def upper_stop_choice(self) -> str:
        """Where the muscle's upper stop stands (:data:`pamsim.parameter_schema.UPPER_STOPS`)."""
        return UPPER_STOP_DEFAULT if self.upper_stop is None else self.upper_stop[0]

    def _stops(self, values: Mapping[str, float], model) -> EndStops:
        return EndStops.for_model(values, model.domain.x_max_m, self.upper_stop_choice)

    def feasible(self, theta: np.ndarray):
        """``(model, upper stop [m])`` at ``theta``, or None where the geometry is impossible, the model cannot
        be built or the muscle's upper stop cannot stand."""
        values = self.params(theta)
        if geometry_violation(values):
            return None
        try:
            model = build_static(self.model, values)
            return model, self._stops(values, model).x_high_m
        except (ValueError, ArithmeticError):  # a model refusing its inputs: a bad trial point, not an error
            return None

    def feasible_force(self, theta: np.ndarray):
        """The model at ``theta``, or None where :meth:`feasible` finds none."""
        found = self.feasible(theta)
        return None if found is None else found[0]

    def predict_m(self, theta: np.ndarray, data: StaticData | None = None) -> np.ndarray:
        """Equilibrium contraction [m] of each test under its load, up to the upper stop at ``theta``."""
        d = self.data if data is None else data
        return equilibrium_m(self.force(theta).force_N, d.pressure_gauge_Pa, d.load_N, self.stops(theta).x_high_m)

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        """The objective's residuals (contraction in mm, force in N)."""
        d = self.data
        cens = self.censored
        found = self.feasible(theta)
        if found is None:
            return np.full(len(d), _PENALTY)
        model, x_high = found
        try:
            if self.objective == "force":
                r = model.force_N(d.contraction_m, d.pressure_gauge_Pa) - d.load_N
                r = np.where(cens, np.maximum(r, 0.0), r)
            else:
                x = equilibrium_m(model.force_N, d.pressure_gauge_Pa, d.load_N, x_high)
                r = 1e3 * np.where(cens, np.maximum(x - self.censor_threshold_m, 0.0), x - d.contraction_m)
        except ArithmeticError:  # a Python float overflowing in a model's formula
            return np.full(len(d), _PENALTY)
        r = np.where(np.isfinite(r), r, _PENALTY)
        return r if self.weights is None else r * self.weights

    def jacobian(self, theta: np.ndarray) -> np.ndarray:
        """d residual / d theta (physical units).

        Force: forward differences of the force.  Contraction: the implicit-function derivative
        ``dx*/dtheta = -(dF/dtheta) / (dF/dx)`` at the equilibrium, the stop's own derivative where the
        equilibrium sits on the upper stop (nonzero only when a free coefficient moves the stop), zero on the
        lower one, so no root finding enters a difference quotient.
        """
        d = self.data
        if self.objective == "force":
            J, _ = self._differences(theta, d.contraction_m)
            active = ~self.censored | (self.force(theta).force_N(d.contraction_m, d.pressure_gauge_Pa) - d.load_N > 0.0)
            return self._weighted(J * active[:, None])
        base_x = self.predict_m(theta)
        J, stop_slopes = self._differences(theta, base_x)
        x_high = self.stops(theta).x_high_m
        inside = (base_x > 0.0) & (base_x < x_high)
        slope = slope_N_per_m(self.force(theta).force_N, base_x, d.pressure_gauge_Pa)
        with np.errstate(divide="ignore", invalid="ignore"):
            dx = np.where(inside[:, None], -J / slope[:, None], np.where(base_x[:, None] >= x_high, stop_slopes, 0.0))
        active = ~self.censored | (base_x > self.censor_threshold_m)
        return self._weighted(1e3 * dx * active[:, None])

    def _differences(self, theta: np.ndarray, x_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Forward differences in each coefficient of the force at contractions ``x_m`` [N per unit] and of the
        upper stop [m per unit]; backward where the forward step leaves the feasible coefficients."""
        d = self.data
        f0 = self.force(theta).force_N(x_m, d.pressure_gauge_Pa)
        x_high = self.stops(theta).x_high_m
        J, stop = np.empty((len(d), len(theta))), np.empty(len(theta))
        for j in range(len(theta)):
            h = _FD_REL * max(abs(theta[j]), 1.0)
            t = theta.copy()
            t[j] += h
            found = self.feasible(t)
            if found is None:  # the optimum sits at the edge of the geometry: difference backwards
                h = -h
                t[j] = theta[j] + h
                found = self.force(t), self.stops(t).x_high_m
            J[:, j] = (found[0].force_N(x_m, d.pressure_gauge_Pa) - f0) / h
            stop[j] = (found[1] - x_high) / h
        return J, stop

    def _weighted(self, J: np.ndarray) -> np.ndarray:
        return J if self.weights is None else J * self.weights[:, None]


@dataclass
class StaticFit:
    """Result of a static fit; ``to_json()`` gives the ``fit.json`` content."""

    problem: StaticProblem
    theta: np.ndarray
    fitted: ParameterSet
    uncertainty: Uncertainty
    predicted_m: np.ndarray
    residuals: np.ndarray
    rms_force_N: float
    rms_contraction_mm: float
    cv_rms_contraction_mm: float
    cv_kind: str
    cv_errors_mm: np.ndarray
    aic: float
    bic: float
    loss: str
    n_starts: int
    success: bool
    message: str
    nfev: int
    wall_time_s: float
    muscle: str = ""
    extra: dict = field(default_factory=dict)
    profile_95: np.ndarray | None = None
    """``(k, 2)``: each coefficient's 95 % profile-likelihood interval (:mod:`.profile`); None when not
    computed (a robust loss, whose optimum is not the sum of squares', or ``intervals=False``)."""

    @property
    def wald_95(self) -> np.ndarray:
        """``(k, 2)``: each coefficient's 95 % Wald interval, ``theta +- t se`` with the Student quantile of the
        fit's degrees of freedom (NaN where the standard error is)."""
        half = t_quantile(self.uncertainty.dof) * self.uncertainty.standard_errors
        return np.column_stack([self.theta - half, self.theta + half])

    @property
    def parameters(self) -> dict[str, float]:
        """The fitted coefficients by name."""
        return dict(zip(self.problem.free, map(float, self.theta)))

    @property
    def n_points(self) -> int:
        """Number of static tests fitted."""
        return len(self.problem.data)

    @property
    def n_censored(self) -> int:
        """Number of censored tests: loads the muscle did not lift."""
        return int(self.problem.censored.sum())

    def to_json(self) -> dict:
        """The fit as JSON-ready values: model, data and its hash, coefficients, standard errors,
        correlations, errors and cross-validation.
        """
        u = self.uncertainty
        return {"model": self.problem.model, "muscle": self.muscle, "objective": self.problem.objective,
                "data": self.problem.data.origin, "data_sha256": self.problem.data.sha256,
                "parameters": self.parameters,
                "standard_errors": {n: _num(v) for n, v in zip(u.names, u.standard_errors)},
                "correlation": u.correlation_table(),
                "inseparable_pairs": [[a, b, r] for a, b, r in u.inseparable_pairs()],
                "not_identified": list(u.not_identified()),
                "rms_force_N": _num(self.rms_force_N), "rms_contraction_mm": _num(self.rms_contraction_mm),
                "cv_rms_contraction_mm": _num(self.cv_rms_contraction_mm), "cv_kind": self.cv_kind,
                "n_points": self.n_points, "n_censored": self.n_censored,
                "censor_threshold_mm": self.problem.censor_threshold_m * 1e3,
                "aic": _num(self.aic), "bic": _num(self.bic), "loss": self.loss, "n_starts": self.n_starts,
                "success": self.success, "message": self.message, "nfev": self.nfev,
                "wall_time_s": self.wall_time_s, "intervals_95": self.intervals_json(),
                "upper_stop": self.upper_stop_json(), **self.extra}

    @property
    def on_upper_stop(self) -> np.ndarray:
        """Indices (in the data's order) of the tests whose predicted equilibrium sits on the upper stop: the
        fitted model still pulls harder than the load there (``on_stop = "upper"`` of ``pamsim static``)."""
        return np.flatnonzero(self.predicted_m >= self.problem.stops(self.theta).x_high_m)

    def upper_stop_json(self) -> dict:
        """The fitted muscle's upper stop: the choice, where it stands [m], what placed it, and the tests
        predicted on it."""
        stops = self.problem.stops(self.theta)
        return {"at": self.problem.upper_stop_choice, "x_m": stops.x_high_m, "basis": stops.upper_basis,
                "tests_on_stop": self.on_upper_stop.tolist()}

    def intervals_json(self) -> dict:
        """``{name: {"wald": [lo, hi], "profile": [lo, hi]}}``: an interval that was not computed or that the
        data give none of (not identified, no degrees of freedom) is null, an end the data do not set is
        null in the pair."""
        prof = np.full_like(self.wald_95, math.nan) if self.profile_95 is None else self.profile_95
        return {n: {"wald": _pair(w), "profile": _pair(pr)}
                for n, w, pr in zip(self.problem.free, self.wald_95, prof)}


def _num(v: float):
    return None if not math.isfinite(v) else float(v)


def _pair(ends: np.ndarray) -> list | None:
    """An interval for JSON: null when it is undefined (NaN), its infinite ends null."""
    return None if np.isnan(ends).any() else [_num(v) for v in ends]


def make_problem(data: StaticData, params: ParameterSet, model: str = "acra2012_polynomial",
                 free: Sequence[str] | None = None, objective: str | None = None,
                 censor_threshold_m: float = CENSOR_THRESHOLD_M,
                 upper_stop: tuple[str, str] | None = None) -> StaticProblem:
    """Check the choices of a static fit and bundle them.

    ``params`` may be a muscle's own parameters (``pamsim.load_muscle(path).parameters``): what the
    dynamics need and it does not give takes pamsim's defaults, as ``pamsim fit static --muscle`` does.
    ``objective`` defaults to ``contraction`` for hanging-weight data and ``force`` for force data.
    The search for the equilibrium ends at the muscle's upper stop, where ``upper_stop`` (the muscle file's
    ``[upper_stop]`` table as ``(at, source)``, :func:`.muscle_file.upper_stop_table`; None: the file names
    none) puts it for the fit's static model, as in a simulation of the muscle; a choice the muscle cannot
    meet is refused (``InputError``).
    """
    params = dynamics_parameters(params)
    check_model(model)
    missing = missing_inputs(model, params)
    if missing:
        raise InputError(f"--model = {model!r}: muscle {params.name!r} does not give {', '.join(missing)}")
    free = tuple(free) if free else default_free(model)
    optional = optional_defaults(model)
    _check_free(free, params, model, optional)
    objective = objective or ("contraction" if data.kind == "weight" else "force")
    if objective not in OBJECTIVES:
        raise InputError(f"--objective = {objective!r}: choose from {', '.join(OBJECTIVES)}")
    if not censor_threshold_m >= 0.0:
        raise InputError(f"--censor-threshold-mm = {censor_threshold_m * 1e3:g}: must not be negative")

    params = with_optional(params, {k: v for k, v in optional.items() if k in free}, model)
    params = _independent(params, free, model)
    lower = np.array([params.entries[n].lower for n in free], dtype=float)
    upper = np.array([params.entries[n].upper for n in free], dtype=float)
    for i, name in enumerate(free):
        lower[i], upper[i] = _physical_bounds(name, params, free, lower[i], upper[i])
    problem = StaticProblem(data, model, params, free, objective, censor_threshold_m, upper_stop, (lower, upper))
    _check_upper_stop(problem)
    return problem


def _check_free(free: tuple[str, ...], params: ParameterSet, model: str, optional: Mapping[str, float]) -> None:
    """Refuse a free name that is neither the muscle's parameter nor an optional coefficient of ``model`` with a
    finite default, and a name given twice."""
    for name in free:
        if name not in params and name not in optional:
            raise InputError(f"--free: {name!r} is not a parameter of muscle {params.name!r} nor an optional "
                             f"coefficient of {model!r}")
        if name in optional and not math.isfinite(optional[name]):
            raise InputError(f"--free: {name!r} of {model!r} has no finite default to start from")
    if len(set(free)) != len(free):
        raise InputError(f"--free = {','.join(free)}: a name appears twice")


def _check_upper_stop(problem: StaticProblem) -> None:
    """Refuse a muscle whose upper stop cannot stand where its choice puts it, at the starting values."""
    try:
        problem.stops(problem.start)
    except ValueError as exc:
        raise InputError(f"muscle {problem.base.name!r}: its upper stop {problem.upper_stop_choice!r}: {exc}") from None


def _independent(params: ParameterSet, free: Sequence[str], model: str) -> ParameterSet:
    """``params`` with the free coefficients independent values and, of the bladder's inner radius and
    wall thickness, the one not freed derived from the braid radius (so that a fitted muscle stays
    consistent and its file gives only independent values)."""
    pair_free = [n for n in WALL_PAIR if n in free]
    if len(pair_free) == 2:
        raise InputError(f"--free = {','.join(free)}: free at most one of ri0_m and wall_thickness_m "
                         "(the other is r0_m minus it)")
    if not all(n in params for n in (*WALL_PAIR, "r0_m")) or not (pair_free or "r0_m" in free):
        return params
    if pair_free:
        keep = pair_free[0]
    else:  # the radius moves: keep what the model is built from, derive the other
        keep = "ri0_m" if "ri0_m" in static_parameters(model) else "wall_thickness_m"
    other = next(n for n in WALL_PAIR if n != keep)
    entries = dict(params.entries)
    if entries[keep].source.startswith(DERIVED):
        entries[keep] = replace(entries[keep], source=f"starting value, {entries[keep].source}")
    entries[other] = replace(entries[other], source=f"{DERIVED}r0_m and {keep}")
    return ParameterSet(params.name, params.citation, rederive(entries))


def _physical_bounds(name: str, params: ParameterSet, free: Sequence[str], lower: float, upper: float):
    """Bounds of a free geometric coefficient that keep the muscle physical: a braid below its locking
    angle, a wall thinner and a radius smaller than the values they must stay below while those are fixed
    (when both move, the residuals' penalty keeps them apart)."""
    fixed = {k: v for k, v in params.items() if k not in free}
    if name == "theta0_deg":
        upper = min(upper, LOCK_DEG)
    elif name in WALL_PAIR and "r0_m" in fixed:
        upper = min(upper, fixed["r0_m"])
    elif name == "r0_m":
        if "L0_m" in fixed:
            upper = min(upper, fixed["L0_m"])
        if "wall_thickness_m" in fixed and not params.entries["wall_thickness_m"].source.startswith(DERIVED):
            lower = max(lower, fixed["wall_thickness_m"])
    return lower, upper


def check_information(problem: StaticProblem, exact: bool = False) -> None:
    """Refuse data that cannot fix the free coefficients: no lifted test, or no more tests than
    coefficients (as many are accepted with ``exact``: an exact fit, no uncertainty)."""
    n, k, d = len(problem.data), len(problem.free), problem.data
    if problem.censored.all():
        raise InputError(f"{d.origin}: every one of the {n} tests is censored (contraction at or below "
                         f"{problem.censor_threshold_m * 1e3:g} mm: no load was lifted); they say nothing about "
                         f"{', '.join(problem.free)}")
    if n < k or (n == k and not exact):
        raise InputError(f"{d.origin}: {n} tests for {k} free coefficients ({', '.join(problem.free)}): "
                         "a fit needs more tests than coefficients to say how far to trust it")


def check_sigma(problem: StaticProblem) -> None:
    """Refuse a ``sigma`` column of the other objective's quantity (a contraction's for the force objective)."""
    d = problem.data
    if d.sigma is not None and d.sigma_kind != problem.objective:
        raise InputError(f"{d.origin}: column {d.columns[3][0]} is the standard deviation of each test's "
                         f"{d.sigma_kind}, but the {problem.objective} objective's residuals are "
                         f"{'forces: give sigma_N' if problem.objective == 'force' else 'contractions: give sigma_mm'}")


def check_data(data: StaticData, params: ParameterSet, model: str, upper_stop: tuple[str, str] | None = None) -> list[str]:
    """Refuse static tests no rig can give for this muscle; return one-line warnings on implausible ones
    (:func:`pamsim.identification.plausibility.check_static_data`, on the scale of the starting muscle;
    ``upper_stop`` as :func:`make_problem` takes it)."""
    problem = make_problem(data, params, model, objective="contraction" if data.kind == "weight" else "force",
                           upper_stop=upper_stop)
    with np.errstate(all="ignore"):
        force = problem.feasible_force(problem.start)
    rated = params["rated_pressure_gauge_Pa"] if "rated_pressure_gauge_Pa" in params else math.inf
    blocked = (lambda p: 0.0) if force is None else (lambda p: force.force_N(0.0, p))
    return check_static_data(data, params["L0_m"], problem.stops(problem.start).x_high_m, rated, blocked)


def with_optional(params: ParameterSet, optional: Mapping[str, float], model: str) -> ParameterSet:
    """``params`` plus a model's optional coefficients at their defaults (ranges from the muscle schema),
    so they can be fitted and written to the fitted muscle."""
    extra = {k: known_parameter(k, v, f"default of {model}") for k, v in optional.items() if k not in params}
    return ParameterSet(params.name, params.citation, {**params.entries, **extra}) if extra else params


def _solve(problem: StaticProblem, theta0: np.ndarray, loss: str, f_scale: float, max_nfev: int | None = None):
    scale = np.where(np.abs(theta0) > 0, np.abs(theta0), 1.0)
    lo, hi = problem.bounds
    z0 = np.clip(theta0, lo, hi) / scale
    res = least_squares(lambda z: problem.residuals(z * scale), z0,
                        jac=lambda z: problem.jacobian(z * scale) * scale,
                        bounds=(lo / scale, hi / scale), loss=loss, f_scale=f_scale, method="trf",
                        x_scale=1.0, max_nfev=max_nfev, xtol=1e-12, ftol=1e-12, gtol=1e-12)
    return res.x * scale, res


def fit_static(data: StaticData, params: ParameterSet, model: str = "acra2012_polynomial",
               free: Sequence[str] | None = None, objective: str | None = None, loss: str = "linear",
               f_scale: float = 1.0, n_starts: int = 0, seed: int = 0,
               censor_threshold_m: float = CENSOR_THRESHOLD_M, cv: str | None = "auto", k_folds: int = 10,
               muscle_label: str = "", exact: bool = False, intervals: bool = True,
               upper_stop: tuple[str, str] | None = None) -> StaticFit:
    """Fit the free coefficients of a static force model to static tests.

    Parameters
    ----------
    data : StaticData
        Pressures, contractions and loads (see :func:`~pamsim.identification.read_static_data`).
    params : ParameterSet
        The muscle: starting values, ranges (bounds) and every fixed parameter.
    model : str
        Static force model name.
    free : sequence of str, optional
        Coefficients to fit; default: the model's own fitted coefficients.
    objective : {"force", "contraction"}, optional
        Default ``contraction`` for hung weights, ``force`` for measured forces.
    loss, f_scale : str, float
        Robust loss of :func:`scipy.optimize.least_squares` and its scale (mm or N, as the residuals).
    n_starts : int
        Extra starts, each from the starting values times ``1 + 0.3 N(0, 1)`` (seeded); the best wins.
    seed : int
        Seed of the multi-start and of the k-fold split.
    censor_threshold_m : float
        Contraction [m] at or below which a hung load counts as not lifted.
    cv : {"auto", "loo", "kfold", None}
        Cross-validation: leave-one-out, ``k_folds``-fold, or ``auto`` (leave-one-out up to 100 tests).
    exact : bool
        Accept as many tests as free coefficients (the ACRA paper's training approach): the fit then
        passes through the tests and gives no standard errors.  Without it such data are refused, as
        are fewer tests than coefficients and data where no test lifted its load.
    intervals : bool
        Also compute each coefficient's 95 % profile-likelihood interval (:mod:`.profile`; with the linear
        loss only), about as many refits per coefficient as the fit took evaluations.
    upper_stop : (str, str), optional
        The muscle file's ``[upper_stop]`` table as ``(at, source)`` (:func:`.muscle_file.upper_stop_table`);
        None: the file names none, so the default choice.  The equilibria end at the upper stop it puts for
        the fit's model, as a simulation's do; the fitted muscle file carries the table.

    Returns
    -------
    StaticFit
    """
    # A trial point far from the data may overflow in a model's formula; it is a bad point (its
    # residuals become the penalty), not something to tell the user about.
    with np.errstate(all="ignore"):
        return _fit_static(data, params, model, free, objective, loss, f_scale, n_starts, seed, censor_threshold_m,
                           cv, k_folds, muscle_label, exact, intervals, upper_stop)


def _fit_static(data, params, model, free, objective, loss, f_scale, n_starts, seed, censor_threshold_m, cv,
                k_folds, muscle_label, exact, intervals, upper_stop) -> StaticFit:
    start = time.perf_counter()
    if loss not in LOSSES:
        raise InputError(f"--loss = {loss!r}: choose from {', '.join(LOSSES)}")
    if not (math.isfinite(f_scale) and f_scale > 0):
        raise InputError(f"--f-scale = {f_scale!r}: must be a positive number")
    if n_starts < 0:
        raise InputError(f"--starts = {n_starts}: must not be negative")
    problem = make_problem(data, params, model, free, objective, censor_threshold_m, upper_stop)
    check_information(problem, exact)
    check_sigma(problem)
    theta0 = problem.start
    theta, res = _solve(problem, theta0, loss, f_scale)
    nfev = res.nfev
    rng = np.random.default_rng(seed)
    for _ in range(n_starts):
        t, r = _solve(problem, theta0 * (1.0 + 0.3 * rng.standard_normal(theta0.size)), loss, f_scale)
        nfev += r.nfev
        if r.cost < res.cost:
            theta, res = t, r
    residuals = problem.residuals(theta)
    unc = linearised_uncertainty(problem.free, problem.jacobian(theta), residuals)
    predicted = problem.predict_m(theta)
    err_mm = (predicted - data.contraction_m) * 1e3
    force_err = problem.force(theta).force_N(data.contraction_m, data.pressure_gauge_Pa) - data.load_N
    lifted = ~problem.censored
    rms_force = float(np.sqrt(np.mean(force_err[lifted] ** 2))) if lifted.any() else math.nan
    cv_kind, cv_err = cross_validate(lambda train: _solve(_restrict(problem, train), theta, loss, f_scale)[0],
                                     lambda th, test: problem.predict_m(th, data.subset(test)) - data.contraction_m[test],
                                     len(data), len(theta), cv, k_folds, seed, duplicate_groups(data))
    aic, bic = information_criteria(float(residuals @ residuals), len(data), len(theta))
    fitted = problem.parameter_set(theta, source=f"fitted: pamsim fit static ({problem.objective} objective) on "
                                                 f"{data.origin}")
    return StaticFit(problem, theta, fitted, unc, predicted, residuals, rms_force,
                     float(np.sqrt(np.mean(err_mm ** 2))),
                     float(np.sqrt(np.mean(cv_err ** 2))) * 1e3 if cv_err.size else math.nan, cv_kind,
                     cv_err * 1e3, aic, bic, loss, n_starts, bool(res.success), str(res.message), int(nfev),
                     time.perf_counter() - start, muscle_label,
                     profile_95=_profile(problem, theta, unc, intervals, loss))


def _profile(problem: StaticProblem, theta: np.ndarray, unc: Uncertainty, wanted: bool, loss: str) -> np.ndarray | None:
    """The 95 % profile-likelihood intervals of the fit's coefficients; None unless ``wanted``, or with a robust
    loss (its optimum is not the sum of squares' minimum the profile starts from)."""
    if not wanted or loss != "linear":
        return None
    return profile_intervals(problem.residuals, problem.jacobian, theta, unc.standard_errors, unc.correlation,
                             problem.bounds, unc.dof)


def _restrict(problem: StaticProblem, rows: np.ndarray) -> StaticProblem:
    return replace(problem, data=problem.data.subset(rows))
