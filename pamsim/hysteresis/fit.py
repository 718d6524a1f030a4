"""Identification of a hysteresis model from one measured loop (docs/hysteresis.md).

Every model maps the loop's contraction ``x`` [m] (the input the test prescribes) to its pull ``F`` [N] (the
output it measures), with a linear static part, and starts relaxed at the first sample:

- Maxwell-slip, N elements: ``F = F0 + k0 x - sum k_i d_i`` (the elements resist the contraction);
- Prandtl-Ishlinskii: ``F = F0 + sum w_j P_rj[g(x)]``, thresholds on a fixed grid, envelope scale fitted;
- Bouc-Wen: ``F = F0 + k_e x - alpha z``.

The fit separates the parameters the output is linear in (offsets, stiffnesses, weights) from the others
(variable projection): for given slip deflections, envelope scale or Bouc-Wen shape, a linear least-squares
problem gives the rest, and :func:`scipy.optimize.least_squares` searches the few nonlinear ones.  The
confidence intervals come from the Jacobian of the residuals in all the parameters at the optimum
(:func:`pamsim.identification.uncertainty.linearised_uncertainty`); AIC and BIC
(:func:`~pamsim.identification.uncertainty.information_criteria`) compare the models and the number of
Maxwell-slip elements, all on the same residual (the force, in N).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
from scipy import optimize, stats

from ..identification.uncertainty import information_criteria, linearised_uncertainty
from . import MODELS, checks
from .bouc_wen import BoucWen
from .loop_data import LoopData
from .maxwell_slip import MaxwellSlip
from .prandtl_ishlinskii import PrandtlIshlinskii

DEFAULT_MAX_ELEMENTS = 6
"""Maxwell-slip fits tried for the BIC's choice: N = 1 to this."""
DEFAULT_PLAYS = 8
"""Play operators of a Prandtl-Ishlinskii fit: thresholds ``j / m`` of the envelope's largest excursion from its
first sample, ``j = 0..m-1`` (a play of threshold at least that never moves from its relaxed start)."""
CONFIDENCE = 0.95
"""Level of the reported intervals (Student's t on the residual's degrees of freedom)."""
FD_RELATIVE_STEP = 1e-6
"""Relative step of the central differences of the Jacobian of the uncertainty."""
ENVELOPE_SCALE_BOUNDS = (0.2, 1000.0)
"""Search range of the Prandtl-Ishlinskii envelope scale, in spans of the input: at the top ``g`` is the
identity to 4e-7 of the span ((u/s)^2/3), so a fit that ends there says the classical operator is enough."""
BOUC_WEN_EXPONENT_BOUNDS = (0.3, 10.0)
"""Search range of the Bouc-Wen exponent n."""
RESIDUAL_MODELS = ("correlated", "white")
"""How the intervals and the information criteria take the residual: ``correlated`` (the default) as
independent noise unless its lag-1 autocorrelation is significant, and then with the effective samples of its
autocorrelation (:class:`ResidualCorrelation`); ``white`` as independent noise always."""


@dataclass(frozen=True)
class ResidualCorrelation:
    """How correlated a fit's residual is along the loop, and what that does to the intervals.

    A loop's residual is rarely white: model error (a structure the model lacks, the load's dynamics in a
    quasi-static loop) runs along the loop for many samples.  Taken as white, the intervals are too narrow by
    the square root of the residual's integrated autocorrelation time ``tau = 1 + 2 sum_k rho_k`` (in samples)
    and the information criteria count ``n`` independent samples where there are about ``n / tau``.  ``tau``
    is summed over Geyer's initial positive sequence (the sums of pairs of neighbouring lags, up to the first
    that is negative; C. J. Geyer, "Practical Markov chain Monte Carlo", Statistical Science, 1992), so that a
    correlation that lasts longer than one lag is counted, as a first-order autoregressive model of the lag-1
    correlation would not.  The residual counts as correlated when its lag-1 autocorrelation is positive
    beyond the 95 % bound of white noise, ``1.96 / sqrt(n)``: the intervals are then widened by
    ``sqrt(tau)``, their Student-t takes the effective samples' degrees of freedom, and AIC and BIC count the
    effective samples."""

    lag1: float
    integrated_time_samples: float
    """``tau`` [samples], at least 1."""
    samples: int
    residual_model: str = "correlated"

    @property
    def significant(self) -> bool:
        """Whether the residual is correlated beyond what white noise shows (and is treated as such)."""
        return self.residual_model == "correlated" and self.lag1 > 1.96 / math.sqrt(self.samples)

    @property
    def effective_samples(self) -> float:
        """``n / tau`` when :attr:`significant`, else ``n``."""
        return self.samples / self.integrated_time_samples if self.significant else float(self.samples)

    @property
    def widening(self) -> float:
        """The factor on the white-noise standard errors: ``sqrt(n / n_eff)``."""
        return math.sqrt(self.samples / self.effective_samples)

    @classmethod
    def of(cls, residual: np.ndarray, residual_model: str = "correlated") -> "ResidualCorrelation":
        """The correlation of ``residual`` (time order)."""
        r = np.asarray(residual, dtype=float) - np.mean(residual)
        n = r.size
        spectrum = np.fft.rfft(r, 2 * n)
        acov = np.fft.irfft(spectrum * np.conj(spectrum), 2 * n)[:n]
        if not acov[0] > 0:
            return cls(0.0, 1.0, n, residual_model)
        rho = acov / acov[0]
        pairs = rho[:n - n % 2].reshape(-1, 2).sum(axis=1)  # Gamma_m = rho_2m + rho_2m+1
        negative = np.flatnonzero(pairs < 0)
        tau = -1.0 + 2.0 * float(np.sum(pairs[:negative[0] if negative.size else pairs.size]))
        return cls(float(rho[1]), max(tau, 1.0), n, residual_model)

    def to_json(self) -> dict:
        """The correlation as JSON-ready values: what ``fit.json`` gives under each fit's ``residual``."""
        return {"lag1_autocorrelation": self.lag1, "integrated_time_samples": self.integrated_time_samples,
                "treated_as": "correlated" if self.significant else "white",
                "effective_samples": self.effective_samples, "interval_widening": self.widening}


@dataclass(frozen=True)
class ModelFit:
    """One fitted model: parameters with intervals, the fitted force, and its AIC and BIC."""

    model: str
    label: str
    names: tuple[str, ...]
    values: np.ndarray
    standard_errors: np.ndarray
    """NaN where the parameter is not identified."""
    identified: np.ndarray
    force_N: np.ndarray
    """The fitted force at each sample."""
    residual_N: np.ndarray
    """Measured minus fitted force."""
    aic: float
    bic: float
    operator: object = field(repr=False)
    """The fitted :class:`MaxwellSlip`, :class:`PrandtlIshlinskii` or :class:`BoucWen` (its own sign
    convention: :meth:`predict_N` gives the fitted pull)."""
    predictor: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    correlation: ResidualCorrelation
    """The residual's lag-1 autocorrelation and the widening of the intervals it asks for."""
    fixed: dict = field(default_factory=dict)
    """Values that were set, not fitted (the Prandtl-Ishlinskii thresholds, a given Bouc-Wen exponent)."""
    not_counted: int = 0
    """Parameters the data never reach (the weights of plays the loop never moves: their columns are the
    offset's), reported as not identified and left out of the AIC and BIC's count."""

    def predict_N(self, x_m, level_N=None) -> np.ndarray:
        """The fitted model's pull [N] for the contraction ``x_m`` [m], relaxed at its first sample; a
        Maxwell-slip fit whose elements share the friction law's level needs that level [N] at each sample."""
        if level_N is None:
            return self.predictor(np.asarray(x_m, dtype=float))
        return self.predictor(np.asarray(x_m, dtype=float), level_N)

    @property
    def rms_N(self) -> float:
        """Root mean square of the residual [N]."""
        return float(np.sqrt(np.mean(self.residual_N ** 2)))

    @property
    def n_parameters(self) -> int:
        """Fitted parameters the data reach: what the AIC and BIC count."""
        return len(self.names) - self.not_counted

    def intervals(self) -> dict[str, tuple[float, float] | None]:
        """``{name: (low, high)}`` at :data:`CONFIDENCE`; None for a parameter that is not identified.  The
        standard errors are already widened for a correlated residual (:class:`ResidualCorrelation`)."""
        t = _t_quantile(_dof(self.correlation, self.n_parameters))
        return {n: ((v - t * s, v + t * s) if ok else None)
                for n, v, s, ok in zip(self.names, self.values, self.standard_errors, self.identified)}

    def to_json(self) -> dict:
        """The fit as JSON-ready values; an interval that is not identified is the text ``not identified``."""
        intervals = self.intervals()
        return {"model": self.model, "label": self.label, "rms_N": self.rms_N, "aic": self.aic, "bic": self.bic,
                "n_parameters": self.n_parameters, "residual": self.correlation.to_json(),
                "parameters": {n: {"value": float(v), "interval": "not identified" if intervals[n] is None
                                   else [float(intervals[n][0]), float(intervals[n][1])]}
                               for n, v in zip(self.names, self.values)},
                "fixed": {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.fixed.items()}}


@dataclass(frozen=True)
class HysteresisFit:
    """The result of :func:`fit_hysteresis`: the chosen model's fit, the best fit of each model (all three
    are fitted, so that their AIC and BIC can be compared) and the Maxwell-slip fits over N."""

    data: LoopData
    chosen: ModelFit
    models: dict[str, ModelFit]
    elements_scan: list[ModelFit]
    elements_given: bool
    effective_samples: float
    """The samples AIC and BIC count, for every model alike: the effective samples of the residual of the
    fit with the least RMS (all of them when its residual is white or taken as such)."""

    def comparison_rows(self) -> list[dict]:
        """One row per model and per Maxwell-slip N: label, parameters, RMS, AIC, BIC."""
        rows = [*self.elements_scan, *(f for m, f in self.models.items() if m != "maxwell_slip")]
        return [{"label": f.label, "n_parameters": f.n_parameters, "rms_N": f.rms_N, "aic": f.aic, "bic": f.bic}
                for f in rows]

    def to_json(self) -> dict:
        """The chosen fit, each model's best fit, the comparison and the data's provenance."""
        return {"data": {"file": self.data.origin, "sha256": self.data.sha256, "samples": len(self.data),
                         "mean_pressure_Pa": float(np.mean(self.data.p_gauge_Pa)),
                         "columns": dict(self.data.columns), "window_s": self.data.window_s},
                "input": "contraction x_m", "output": "force_N", "fit": self.chosen.to_json(),
                "information_criteria_samples": self.effective_samples,
                "elements": "given" if self.elements_given else "chosen by BIC",
                "models": {name: f.to_json() for name, f in self.models.items()},
                "comparison": self.comparison_rows()}


def fit_hysteresis(data: LoopData, model: str = "maxwell_slip", elements: int | None = None,
                   max_elements: int = DEFAULT_MAX_ELEMENTS, plays: int = DEFAULT_PLAYS,
                   thresholds_m=None, exponent: float | None = None, residual: str = "correlated") -> HysteresisFit:
    """Fit the three models to ``data`` and return the one asked for with the comparison.

    Parameters
    ----------
    data : LoopData
        The loop: contraction in, force out.
    model : str
        ``maxwell_slip``, ``pi`` or ``bouc_wen``: the fit reported in detail.
    elements : int, optional
        Maxwell-slip elements (1 to 100); default: the N of 1..``max_elements`` with the least BIC.
    max_elements : int
        Largest N tried when ``elements`` is not given.
    plays : int
        Play operators of the Prandtl-Ishlinskii fit on the default threshold grid.
    thresholds_m : array_like, optional
        Prandtl-Ishlinskii thresholds in the envelope's input unit (m), at least 0 and strictly increasing;
        default: the grid of ``plays``.
    exponent : float, optional
        Bouc-Wen exponent n (above 0), fixed; default: fitted.
    residual : str
        ``correlated`` (default) or ``white``: :data:`RESIDUAL_MODELS`.

    Returns
    -------
    HysteresisFit
    """
    if model not in MODELS:
        raise checks.InputError(f"model = {model!r}: choose from {', '.join(MODELS)}")
    if residual not in RESIDUAL_MODELS:
        raise checks.InputError(f"residual = {residual!r}: choose from {', '.join(RESIDUAL_MODELS)}")
    counts = [checks.count("elements", elements)] if elements is not None else \
        range(1, checks.count("max_elements", max_elements) + 1)
    plays = checks.count("plays", plays)
    if thresholds_m is not None:  # the operator's own checks: 1 to 100, at least 0, strictly increasing
        thresholds_m = PrandtlIshlinskii(thresholds_m, np.zeros(np.size(thresholds_m))).thresholds
    if exponent is not None:
        exponent = checks.number("exponent", exponent, 0.0, strict=True)
    scan = [fit_maxwell_slip(data, n, residual) for n in counts]
    others = [fit_pi(data, plays, thresholds_m, residual), fit_bouc_wen(data, exponent, residual)]
    # One count of samples for all, so that the criteria compare the models on the same footing.
    samples = min([*scan, *others], key=lambda f: f.rms_N).correlation.effective_samples
    scan, others = ([replace(f, **dict(zip(("aic", "bic"), information_criteria(
        float(f.residual_N @ f.residual_N), f.residual_N.size, f.n_parameters, samples)))) for f in fits]
        for fits in (scan, others))
    models = {"maxwell_slip": min(scan, key=lambda f: f.bic), "pi": others[0], "bouc_wen": others[1]}
    return HysteresisFit(data, models[model], models, scan, elements is not None, samples)


# ------------------------------------------------------------------ the shared steps
def _linear(columns: np.ndarray, y: np.ndarray, lower: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least squares ``columns @ c = y`` with ``c >= lower``; the coefficients and the residual ``y - fit``."""
    scale = np.linalg.norm(columns, axis=0)
    scale[scale == 0] = 1.0
    if np.all(np.isneginf(lower)):
        c = np.linalg.lstsq(columns / scale, y, rcond=None)[0]
    else:
        c = optimize.lsq_linear(columns / scale, y, bounds=(lower * scale, np.inf), method="bvls").x
    c = c / scale
    return c, y - columns @ c


def _t_quantile(dof: float) -> float:
    """Student's t at :data:`CONFIDENCE` (two-sided) for ``dof`` degrees of freedom (at least 1)."""
    return float(stats.t.ppf(0.5 + CONFIDENCE / 2, max(dof, 1)))


def _dof(correlation: ResidualCorrelation, k: int) -> float:
    """The residual's degrees of freedom: its effective samples less the ``k`` fitted parameters."""
    return correlation.effective_samples - k


def _finish(model: str, label: str, data: LoopData, names, theta: np.ndarray, predict, at_bound, positive,
            operator, predictor, fixed=None, residual_model: str = "correlated", unreached=None) -> ModelFit:
    """The :class:`ModelFit` at ``theta``: ``predict(theta)`` the force, its Jacobian by central differences,
    the intervals (widened for a correlated residual).  Not identified: a parameter the Jacobian does not see,
    one on a bound of its search (``at_bound``), one that must be above 0 (``positive``) whose interval reaches
    0, one the data never reach (``unreached``: not counted in the AIC and BIC either), and every one when
    the residual's effective samples do not outnumber the parameters."""
    unreached = np.zeros(theta.size, dtype=bool) if unreached is None else unreached
    k = theta.size - int(np.sum(unreached))
    force = predict(theta)
    residual = data.force_N - force
    jac = np.empty((force.size, theta.size))
    for i, v in enumerate(theta):
        h = FD_RELATIVE_STEP * max(abs(v), 1e-12)
        up, down = theta.copy(), theta.copy()
        up[i], down[i] = v + h, v - h
        jac[:, i] = (predict(up) - predict(down)) / (2 * h)
    unc = linearised_uncertainty(names, jac, residual)
    correlation = ResidualCorrelation.of(residual, residual_model)
    se = unc.standard_errors * correlation.widening
    dof = _dof(correlation, k)
    identified = unc.identified & np.isfinite(se) & (se > 0) & ~at_bound & ~unreached & (dof >= 1)
    # A stiffness, slip force or scale whose interval reaches 0 is one the data cannot tell from none.
    reaches_zero = positive & (theta - _t_quantile(dof) * np.nan_to_num(se, nan=np.inf) <= 0)
    identified &= ~reaches_zero
    aic, bic = information_criteria(float(residual @ residual), residual.size, k,
                                    correlation.effective_samples if correlation.significant else None)
    return ModelFit(model, label, tuple(names), theta, np.where(identified, se, np.nan),
                    identified, force, residual, aic, bic, operator, predictor, correlation, fixed or {},
                    int(np.sum(unreached)))


# ------------------------------------------------------------------ Maxwell-slip
def _ms_columns(x: np.ndarray, deflections: np.ndarray, level: np.ndarray | None = None) -> np.ndarray:
    """Columns of ``F0, k0, k_1..k_N`` for the slip deflections ``deflections``: ``1, x, -d_i``; with the
    friction law's ``level``, of ``F0, k0, share_1..share_N``: ``1, x, -level d_i / delta_i``."""
    ms = MaxwellSlip(np.ones(deflections.size), deflections)  # unit stiffness: d_i is the force per N/m
    d = ms.run(x).deflection_m
    if level is not None:
        d = d * (level[:, None] / deflections)
    return np.column_stack([np.ones_like(x), x, -d])


def _ms_lower(n: int) -> np.ndarray:
    return np.concatenate([[-np.inf, -np.inf], np.zeros(n)])


def fit_maxwell_slip(data: LoopData, n: int, residual: str = "correlated") -> ModelFit:
    """Fit ``n`` Maxwell-slip elements (with ``F0`` and ``k0``) to ``data``.

    Where the data carry the rig's friction level (a loop at a hanging load), the elements are the rig's:
    element i slips at ``share_i`` times the level, ``delta_i`` its slip displacement, and the fit reports
    ``share<i>`` and ``delta<i>_m`` (:func:`_fit_shared_level`); otherwise constant ``k<i>_N_per_m`` and
    ``F<i>_N``."""
    if data.level_N is not None:
        return _fit_shared_level(data, n, residual)
    x, y = data.x_m, data.force_N
    best = _ms_search(x, y, n, None)
    deflections = np.exp(best.x)
    order = np.argsort(deflections)
    deflections = deflections[order]

    c, _ = _linear(_ms_columns(x, deflections), y, _ms_lower(n))
    k = c[2:]
    theta = np.concatenate([c[:2], k, k * deflections])
    names = ["F0_N", "k0_N_per_m", *(f"k{i + 1}_N_per_m" for i in range(n)), *(f"F{i + 1}_N" for i in range(n))]
    at_bound = np.concatenate([[False, False], k <= 0, k <= 0])
    positive = np.concatenate([[False, False], np.ones(2 * n, dtype=bool)])

    def predict(th):
        stiff = np.maximum(th[2:2 + n], 1e-300)
        run = MaxwellSlip(stiff, np.maximum(th[2 + n:], 0.0)).run(x)
        return th[0] + th[1] * x - run.force_N

    operator = MaxwellSlip(np.maximum(k, 1e-300), k * deflections)
    return _finish("maxwell_slip", f"maxwell_slip N={n}", data, names, theta, predict, at_bound, positive, operator,
                   lambda u: theta[0] + theta[1] * u - operator.run(u).force_N, residual_model=residual)


def _ms_search(x: np.ndarray, y: np.ndarray, n: int, level: np.ndarray | None):
    """The best of three local searches of the log slip deflections (log-spaced starts over the input's span)."""
    span = float(np.ptp(x))

    def residual(log_d):
        return _linear(_ms_columns(x, np.exp(log_d), level), y, _ms_lower(n))[1]

    best = None
    for low, high in ((0.01, 0.3), (0.003, 0.1), (0.03, 0.5)):
        start = np.log(span * np.geomspace(low, high, n))
        res = optimize.least_squares(residual, start, bounds=(np.log(1e-6 * span), np.log(2 * span)), x_scale=1.0,
                                     diff_step=1e-4)
        if best is None or res.cost < best.cost:
            best = res
    return best


def _fit_shared_level(data: LoopData, n: int, residual: str) -> ModelFit:
    """The rig's elements (:mod:`pamsim.components.maxwell_slip_friction`): element i's spring has the stiffness
    ``share_i level / delta_i`` and slips at ``share_i level``, so its pull is ``share_i level d_i / delta_i``
    with ``d_i`` the deflection of an element of slip displacement ``delta_i``: linear in the shares."""
    x, y, level = data.x_m, data.force_N, data.level_N
    deltas = np.sort(np.exp(_ms_search(x, y, n, level).x))
    c, _ = _linear(_ms_columns(x, deltas, level), y, _ms_lower(n))
    theta = np.concatenate([c, deltas])
    names = ["F0_N", "k0_N_per_m", *(f"share{i + 1}" for i in range(n)), *(f"delta{i + 1}_m" for i in range(n))]
    shares = c[2:]
    at_bound = np.concatenate([[False, False], shares <= 0, shares <= 0])
    positive = np.concatenate([[False, False], np.ones(2 * n, dtype=bool)])

    def predict(th):
        return _ms_columns(x, np.maximum(th[2 + n:], 1e-300), level) @ th[:2 + n]

    def predictor(u, level_N=None):
        if level_N is None:
            raise checks.InputError("this fit's elements share the friction law's level: give level_N, the level "
                                    "at each sample of the input")
        return _ms_columns(u, deltas, np.asarray(level_N, dtype=float)) @ c

    operator = MaxwellSlip(np.maximum(shares, 1e-300) / deltas, shares)  # at a level of 1 N
    return _finish("maxwell_slip", f"maxwell_slip N={n}", data, names, theta, predict, at_bound, positive, operator,
                   predictor, {"level": "shared: element i slips at share_i times the friction law's level"}, residual)


# ------------------------------------------------------------------ Prandtl-Ishlinskii
def _pi_excursion(x: np.ndarray, scale: float) -> float:
    """The envelope's largest excursion from its first sample: plays of threshold at least this never move
    from their relaxed start (the envelope is monotone)."""
    g = PrandtlIshlinskii([0.0], [1.0], 0.0, scale).envelope(x)
    return float(np.max(np.abs(g - g[0])))


def _pi_thresholds(x: np.ndarray, scale: float, plays: int) -> np.ndarray:
    return np.arange(plays) * _pi_excursion(x, scale) / plays


def _pi_columns(x: np.ndarray, thresholds: np.ndarray, scale: float) -> np.ndarray:
    """Columns of ``F0, w_0..w_m-1``: ``1`` and the plays of ``g(x)``, relaxed at the first sample.  A play
    that never moves has a column of 0: its constant would be the offset's, which alone carries it."""
    pi = PrandtlIshlinskii(thresholds, np.ones(thresholds.size), 0.0, scale)
    start = np.full(thresholds.size, float(pi.envelope(x[0])))
    states = pi.run(x, start).states
    states[:, np.ptp(states, axis=0) == 0.0] = 0.0
    return np.column_stack([np.ones_like(x), states])


def fit_pi(data: LoopData, plays: int = DEFAULT_PLAYS, thresholds_m=None, residual: str = "correlated") -> ModelFit:
    """Fit a generalized Prandtl-Ishlinskii operator (offset, weights, envelope scale) to ``data``."""
    x, y = data.x_m, data.force_N
    span = float(np.ptp(x))
    free = np.full(1 + (plays if thresholds_m is None else len(thresholds_m)), -np.inf)

    def grid(scale):
        return _pi_thresholds(x, scale, plays) if thresholds_m is None else np.asarray(thresholds_m, dtype=float)

    def cost(log_s):
        scale = span * math.exp(log_s)
        return float(np.sum(_linear(_pi_columns(x, grid(scale), scale), y, free)[1] ** 2))

    bounds = tuple(math.log(b) for b in ENVELOPE_SCALE_BOUNDS)
    res = optimize.minimize_scalar(cost, bounds=bounds, method="bounded", options={"xatol": 1e-6})
    at_top = res.x > bounds[1] - 1e-3
    scale = span * math.exp(res.x)
    thresholds = grid(scale)
    c, _ = _linear(_pi_columns(x, thresholds, scale), y, free)
    theta = np.concatenate([c, [scale]])
    names = ["F0_N", *(f"w{j}_N_per_m" for j in range(thresholds.size)), "envelope_scale_m"]

    def predict(th):
        return _pi_columns(x, thresholds, th[-1]) @ th[:-1]

    at_bound = np.zeros(theta.size, dtype=bool)
    at_bound[-1] = at_top
    operator = PrandtlIshlinskii(thresholds, c[1:], c[0], scale)
    positive = np.zeros(theta.size, dtype=bool)
    positive[-1] = True
    unreached = np.concatenate([[False], thresholds >= _pi_excursion(x, scale), [False]])
    return _finish("pi", f"pi m={thresholds.size}", data, names, theta, predict, at_bound, positive, operator,
                   lambda u: operator.run(u, np.full(thresholds.size, float(operator.envelope(u[0])))).output,
                   {"thresholds_m": thresholds}, residual, unreached)


# ------------------------------------------------------------------ Bouc-Wen
def _bw_shape(p: np.ndarray, exponent: float | None) -> tuple[float, float, float]:
    """``(beta, gamma, n)`` from the search variables: ``log(beta + gamma)``, ``beta / (beta + gamma)`` and,
    unless the exponent is given, ``log n``."""
    total = math.exp(p[0])
    n = exponent if exponent is not None else math.exp(p[2])
    return p[1] * total, (1.0 - p[1]) * total, n


def _bw_columns(x: np.ndarray, beta: float, gamma: float, n: float) -> np.ndarray:
    """Columns of ``F0, k_e, alpha``: ``1, x, -z``."""
    z = BoucWen(1.0, beta, gamma, n).run(x).z_m
    return np.column_stack([np.ones_like(x), x, -z])


def _bw_search(x: np.ndarray, y: np.ndarray, exponent: float | None):
    """The best of three local searches of the Bouc-Wen shape (starts with ``z_u`` 2, 10 and 40 % of the span),
    and which search variables ended on a bound."""
    span = float(np.ptp(x))
    free = np.full(3, -np.inf)
    fitted_n = exponent is None
    n_lo, n_hi = (math.log(b) for b in BOUC_WEN_EXPONENT_BOUNDS)
    lower = [math.log(1e-3 / span), -20.0] + [n_lo] * fitted_n
    upper = [math.log(1e4 / span), 20.0] + [n_hi] * fitted_n

    def residual(p):
        return _linear(_bw_columns(x, *_bw_shape(p, exponent)), y, free)[1]

    starts = [[math.log((z_u * span) ** -(exponent or 1.0)), 0.5] + [0.0] * fitted_n for z_u in (0.02, 0.1, 0.4)]
    best = min((optimize.least_squares(residual, p0, bounds=(lower, upper), diff_step=1e-5) for p0 in starts),
               key=lambda res: res.cost)
    return best.x, np.isclose(best.x, lower, atol=1e-6) | np.isclose(best.x, upper, atol=1e-6)


def fit_bouc_wen(data: LoopData, exponent: float | None = None, residual: str = "correlated") -> ModelFit:
    """Fit Bouc-Wen (``F0, k_e, alpha, beta, gamma`` and, unless ``exponent`` is given, ``n``) to ``data``."""
    x, y = data.x_m, data.force_N
    fitted_n = exponent is None
    p, on_edge = _bw_search(x, y, exponent)
    beta, gamma, n = _bw_shape(p, exponent)
    c, _ = _linear(_bw_columns(x, beta, gamma, n), y, np.full(3, -np.inf))
    theta = np.concatenate([c, [beta, gamma], [n] * fitted_n])
    names = ["F0_N", "k_e_N_per_m", "alpha_N_per_m", "beta_per_m_n", "gamma_per_m_n"] + ["n"] * fitted_n

    def predict(th):
        return _bw_columns(x, th[3], th[4], th[5] if fitted_n else n) @ th[:3]

    at_bound = np.array([False] * 3 + [on_edge[0] or on_edge[1]] * 2 + list(on_edge[2:]))
    positive = np.array([False] * 5 + [True] * fitted_n)
    operator = BoucWen(-c[2], beta, gamma, n, c[1], c[0])  # its law is F0 + k_e x + alpha z
    return _finish("bouc_wen", "bouc_wen" + ("" if fitted_n else f" n={n:g}"), data, names, theta, predict,
                   at_bound, positive, operator, lambda u: operator.run(u).force_N, {} if fitted_n else {"n": n},
                   residual)
