"""Hysteresis compensation in the closed position loop: identify the muscle's hysteresis from noisy loops of
the plant, then track sinusoids with and without the identified model in the feedforward (docs/hysteresis.md,
"Compensation").

A scenario with a ``[compensation]`` table runs this study (``pamsim run``):

1. **Identification.** The scenario's muscle and load (its ``[hysteresis]`` elements included) are driven by
   a quasi-static pressure cycle of turns of falling amplitude, as a pressure-controlled test would drive
   them. Gaussian noise of the stated levels (seeded) is added to the sampled contraction and pressure, as
   a sensor would. The loop's force is what the muscle's static force misses of the weight,
   ``W - F_static(x, p)``, from the noisy samples and the nominal static model: the hysteretic force, in the
   sign of ``pamsim fit hysteresis`` (the elements resist the contraction). :func:`fit_hysteresis` fits it;
   the model the table names (Maxwell-slip with N by BIC or given, Prandtl-Ishlinskii or Bouc-Wen) is the
   compensator. The true elements are never read.
2. **Tracking.** For each frequency the controller of ``[controller]`` (designed at its
   ``design_contraction_mm``) tracks ``center + amplitude sin(2 pi f t)``, once with the inverse-dynamics
   feedforward alone (:mod:`pamsim.control.tracking`) and once with the compensator's force along the
   reference added to what the feedforward pressure must carry. Both start at rest at the centre, the
   elements relaxed. The RMS tracking error counts from one period after the start.

Compensation here is the plant's inverse built from its parts: the hysteresis acts in the force balance as an
operator of the contraction, so the compensator runs the identified operator forward along the reference and
the static model's inverse turns the force into pressure. A Prandtl-Ishlinskii operator fitted from pressure to
contraction and inverted (Kuhnen's inverse) would stand in the same place; pamsim fits the force side, where
the elements act.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..backends import simulate
from ..constants import PA_PER_BAR
from ..control.closed_loop import design_closed_loop
from ..control.tracking import FEEDFORWARDS, SineReference, TrackingSignals, tracking_rms_m, tracking_signals
from ..errors import InputError
from ..result import Result
from ..scenario import Scenario
from ..table_checks import TableChecker
from . import MODELS
from .fit import HysteresisFit, ModelFit, fit_hysteresis
from .hanging_load import hysteresis_pull_N
from .loop_data import LoopData

SETTLE_S = 1.0
"""Time [s] the identification run holds its first pressure before the cycle: the load lifts and comes to rest."""
_KEYS = {"model", "elements", "feedforward", "frequencies_Hz", "center_mm", "amplitude_mm", "periods", "start_s",
         "min_reduction_percent", "identification"}
_IDENT_KEYS = {"pressures_bar", "rate_bar_per_s", "sample_rate_Hz", "noise_contraction_mm", "noise_pressure_bar",
               "seed"}
_REFUSED_CONTROLLER_KEYS = ("target_contraction_mm", "step_time_s")


@dataclass(frozen=True)
class IdentificationConfig:
    """``[compensation.identification]``: the pressure cycle and the sensors' noise, SI units."""

    pressures_Pa: tuple[float, ...]
    rate_Pa_s: float
    sample_rate_Hz: float
    noise_contraction_m: float
    noise_pressure_Pa: float
    seed: int

    def knots(self) -> tuple[list[float], list[float]]:
        """Times [s] and gauge pressures [Pa] of the cycle: held at the first pressure for :data:`SETTLE_S`,
        then straight lines at the rate between the turns."""
        times, values = [0.0, SETTLE_S], [self.pressures_Pa[0]] * 2
        for a, b in zip(self.pressures_Pa, self.pressures_Pa[1:]):
            times.append(times[-1] + abs(b - a) / self.rate_Pa_s)
            values.append(b)
        return times, values


@dataclass(frozen=True)
class CompensationConfig:
    """The ``[compensation]`` table, SI units (see the module's docstring)."""

    model: str
    elements: int | None
    feedforward: str
    frequencies_Hz: tuple[float, ...]
    center_m: float
    amplitude_m: float
    periods: float
    start_s: float
    min_reduction_percent: float
    identification: IdentificationConfig

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> "CompensationConfig":
        """Read and check ``[compensation]``.

        Raises
        ------
        InputError
            Naming the file and the key: a missing or unknown key, a value out of its range, a
            ``[controller]`` key the tracking replaces, or a scenario without ``[hysteresis]``.
        """
        v = TableChecker(scenario.origin)
        table = scenario.spec.get("compensation")
        v.check_keys("[compensation]", "compensation.", table, _KEYS)
        if "hysteresis" not in scenario.spec:
            v.fail("hysteresis", None, "missing: compensation needs a plant with hysteresis ([hysteresis] table)")
        for key in _REFUSED_CONTROLLER_KEYS:
            if key in scenario.spec.get("controller", {}):
                v.fail(f"controller.{key}", scenario.spec["controller"][key],
                       "a tracking study takes its reference from [compensation] (center_mm, amplitude_mm)")
        model = table.get("model", "maxwell_slip")
        if not isinstance(model, str) or model not in MODELS:
            v.fail("compensation.model", model, "unknown hysteresis model", choices=list(MODELS))
        feedforward = table.get("feedforward", FEEDFORWARDS[0])
        if not isinstance(feedforward, str) or feedforward not in FEEDFORWARDS:
            v.fail("compensation.feedforward", feedforward, "unknown feedforward", choices=list(FEEDFORWARDS))
        return cls(model, _elements(v, table), feedforward, _frequencies(v, table), *_reference(v, table),
                   _positive(v, table, "periods", 3.0), _positive(v, table, "start_s", 0.5),
                   _positive(v, table, "min_reduction_percent", 50.0), _identification(v, table))


def _positive(v: TableChecker, table: dict, key: str, default: float | None = None, prefix: str = "compensation.",
              factor: float = 1.0) -> float:
    """``table[key]`` (its default if it has one and is missing) as a positive number times ``factor``."""
    raw = v.required(table, key, prefix=prefix) if default is None else table.get(key, default)
    return v.positive(prefix + key, v.number(prefix + key, raw)) * factor


def _elements(v: TableChecker, table: dict) -> int | None:
    raw = table.get("elements")
    if raw is None:
        return None
    if isinstance(raw, bool) or not isinstance(raw, int) or not 1 <= raw <= 100:
        v.fail("compensation.elements", raw, "must be an integer from 1 to 100 (leave it out: chosen by BIC)")
    return raw


def _frequencies(v: TableChecker, table: dict) -> tuple[float, ...]:
    values = v.number_list("compensation.frequencies_Hz", v.required(table, "frequencies_Hz", prefix="compensation."))
    for i, f in enumerate(values):
        v.positive(f"compensation.frequencies_Hz[{i}]", f)
    return tuple(values)


def _reference(v: TableChecker, table: dict) -> tuple[float, float]:
    center = _positive(v, table, "center_mm", factor=1e-3)
    amplitude = _positive(v, table, "amplitude_mm", factor=1e-3)
    if amplitude >= center:
        v.fail("compensation.amplitude_mm", amplitude * 1e3, f"must be below center_mm = {center * 1e3:g}: the "
               "reference would leave the muscle's contraction range")
    return center, amplitude


def _identification(v: TableChecker, table: dict) -> IdentificationConfig:
    where = "compensation.identification."
    ident = v.required(table, "identification", dict, prefix="compensation.")
    v.check_keys("[compensation.identification]", where, ident, _IDENT_KEYS)
    pressures = v.number_list(where + "pressures_bar", v.required(ident, "pressures_bar", prefix=where))
    if len(pressures) < 4:
        v.fail(where + "pressures_bar", pressures, "needs at least 4 turns: a loop needs two reversals")
    if any(p < 0 for p in pressures) or any(a == b for a, b in zip(pressures, pressures[1:])):
        v.fail(where + "pressures_bar", pressures, "must be gauge pressures >= 0, each different from the last")
    noise = {key: v.number(where + key, ident.get(key, 0.0)) for key in ("noise_contraction_mm", "noise_pressure_bar")}
    for key, value in noise.items():
        if value < 0:
            v.fail(where + key, value, "must be >= 0")
    seed = ident.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        v.fail(where + "seed", seed, "must be an integer >= 0")
    return IdentificationConfig(tuple(p * PA_PER_BAR for p in pressures),
                                _positive(v, ident, "rate_bar_per_s", prefix=where, factor=PA_PER_BAR),
                                _positive(v, ident, "sample_rate_Hz", 50.0, prefix=where),
                                noise["noise_contraction_mm"] * 1e-3, noise["noise_pressure_bar"] * PA_PER_BAR, seed)


@dataclass(frozen=True)
class Identification:
    """The identification run, its noisy loop and the fits."""

    result: Result
    loop: LoopData
    fit: HysteresisFit

    @property
    def compensator(self) -> ModelFit:
        """The fit used as the compensator (the model ``[compensation]`` names)."""
        return self.fit.chosen

    def extra_force_N(self, x_m: np.ndarray) -> np.ndarray:
        """The hysteretic force the muscle must overcome along the contraction path ``x_m`` [N] (more pull
        positive), zero at its first sample where the elements are relaxed."""
        pull = self.compensator.predict_N(x_m)
        return -(pull - pull[0])


def identification_scenario(scenario: Scenario, ident: IdentificationConfig) -> Scenario:
    """The scenario's muscle, load and hysteresis under the prescribed pressure cycle of ``ident``."""
    spec = {k: copy.deepcopy(v) for k, v in scenario.spec.items()
            if k not in ("controller", "compensation", "pressure", "simulation", "name", "description")}
    times, values = ident.knots()
    spec["pressure"] = {"source": "prescribed",
                        "prescribed": {"kind": "linear", "times_s": times, "values_gauge_Pa": values}}
    spec["simulation"] = {"duration_s": times[-1], "sample_rate_Hz": ident.sample_rate_Hz}
    return Scenario.from_dict(spec, f"{scenario.name}_identification", scenario.base_dir, scenario.origin)


def identify(scenario: Scenario, config: CompensationConfig, backend: str = "python") -> Identification:
    """Run the identification cycle on ``backend``, add the sensors' noise and fit the loop."""
    ident = config.identification
    plant = identification_scenario(scenario, ident)
    result = simulate(plant, backend)
    rng = np.random.default_rng(ident.seed)
    keep = result.t_s >= SETTLE_S
    x = result.x_m[keep] + rng.normal(0.0, ident.noise_contraction_m, int(keep.sum()))
    p = result.p_gauge_Pa[keep] + rng.normal(0.0, ident.noise_pressure_Pa, int(keep.sum()))
    model = plant.build_model()
    force = hysteresis_pull_N(model.static_force, model.load.weight_N, x, p)
    loop = LoopData(result.t_s[keep], p, x, force, f"{scenario.origin} (identification, seed {ident.seed})")
    return Identification(result, loop, fit_hysteresis(loop, config.model, config.elements))


@dataclass
class TrackingRun:
    """One frequency: the runs without and with compensation, their signals and RMS errors."""

    frequency_Hz: float
    from_s: float
    results: dict[str, Result]
    signals: dict[str, TrackingSignals]
    rms_m: dict[str, float] = field(default_factory=dict)

    @property
    def reduction_percent(self) -> float:
        """How much lower the RMS error is with compensation [% of the error without]."""
        return 100.0 * (1.0 - self.rms_m["compensated"] / self.rms_m["feedforward"])


RUN_KINDS = ("feedforward", "compensated")
"""The two runs at each frequency: inverse-dynamics feedforward alone, and with the compensator's force."""


def track(scenario: Scenario, config: CompensationConfig, identification: Identification | None, frequency_Hz: float,
          backend: str = "python") -> TrackingRun:
    """Track the sine of ``frequency_Hz`` without and (if ``identification`` is given) with compensation."""
    duration = config.start_s + config.periods / frequency_Hz
    sc = scenario.with_changes({"simulation": {"duration_s": duration, "initial_contraction_m": config.center_m}})
    overrides = {"target_contraction_mm": config.center_m * 1e3, "step_time_s": config.start_s}
    loop = design_closed_loop(sc, overrides)
    reference = SineReference(config.center_m, config.amplitude_m, frequency_Hz, config.start_s)
    supply = sc.final_pressure_gauge_Pa
    run = TrackingRun(frequency_Hz, config.start_s + 1.0 / frequency_Hz, {}, {})
    extras = {"feedforward": None, "compensated": identification.extra_force_N if identification else None}
    for kind in RUN_KINDS if identification else RUN_KINDS[:1]:
        signals = tracking_signals(loop.model, reference, duration, supply, extras[kind], config.feedforward)
        result = simulate(sc, backend, None, model=signals.apply(loop.model))
        run.results[kind], run.signals[kind] = result, signals
        run.rms_m[kind] = tracking_rms_m(result.t_s, result.x_m, signals, run.from_s)
    return run


@dataclass
class CompensationStudy:
    """The identification and the tracking runs of a ``[compensation]`` scenario on one backend."""

    scenario: Scenario
    config: CompensationConfig
    backend: str
    identification: Identification
    runs: list[TrackingRun]

    def failures(self) -> list[str]:
        """The frequencies whose RMS error compensation lowers by less than ``min_reduction_percent``."""
        need = self.config.min_reduction_percent
        return [f"{r.frequency_Hz:g} Hz: RMS error {r.rms_m['feedforward'] * 1e3:.3f} -> "
                f"{r.rms_m['compensated'] * 1e3:.3f} mm, {r.reduction_percent:.1f} % lower < {need:g} %"
                for r in self.runs if not r.reduction_percent >= need]

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures: the identification (fit, noise, comparison of models) and each frequency's
        RMS errors and reduction, the specification and what misses it."""
        ident, cfg = self.identification, self.config.identification
        return {"scenario": self.scenario.name, "backend": self.backend, "feedforward": self.config.feedforward,
                "identification": {"samples": len(ident.loop), "noise_contraction_m": cfg.noise_contraction_m,
                                   "noise_pressure_Pa": cfg.noise_pressure_Pa, "seed": cfg.seed,
                                   "compensator": ident.compensator.to_json(),
                                   "comparison": ident.fit.comparison_rows()},
                "tracking": [{"frequency_Hz": r.frequency_Hz, "rms_from_s": r.from_s,
                              "rms_feedforward_m": r.rms_m["feedforward"], "rms_compensated_m": r.rms_m["compensated"],
                              "reduction_percent": r.reduction_percent,
                              "events": {k: int(res.stats["events"]) for k, res in r.results.items()},
                              "wall_time_s": {k: float(res.wall_time_s) for k, res in r.results.items()}}
                             for r in self.runs],
                "min_reduction_percent": self.config.min_reduction_percent, "meets_spec": not self.failures(),
                "failures": self.failures()}


TRACKING_COLUMNS = ("frequency_Hz", "compensated", "t_s", "reference_m", "x_m", "p_gauge_Pa", "feedforward_gauge_Pa",
                    "feedforward_command", "compensator_force_N")
"""Columns of :func:`write_tracking_csv`; ``compensated`` is 0 for the feedforward alone, 1 with the compensator."""


def write_tracking_csv(study: CompensationStudy, path) -> None:
    """Every tracking run's samples in one CSV of :data:`TRACKING_COLUMNS`."""
    blocks = []
    for run in study.runs:
        for kind, res in run.results.items():
            sig = run.signals[kind]
            at = [np.interp(res.t_s, sig.t_s, values) for values in
                  (sig.reference_m, sig.feedforward_gauge_Pa, sig.feedforward_command, sig.extra_force_N)]
            blocks.append(np.column_stack([np.full(res.t_s.size, run.frequency_Hz),
                                           np.full(res.t_s.size, float(kind == "compensated")), res.t_s, at[0],
                                           res.x_m, res.p_gauge_Pa, *at[1:]]))
    np.savetxt(path, np.vstack(blocks), delimiter=",", header=",".join(TRACKING_COLUMNS), comments="", fmt="%.10g")


def run_compensation(scenario: Scenario, backend: str = "python") -> CompensationStudy:
    """Identify the compensator and track each frequency of ``[compensation]`` with and without it.

    Parameters
    ----------
    scenario : Scenario
        With ``[hysteresis]``, ``[controller]`` and ``[compensation]`` tables and a valve source.
    backend : str
        A name of :data:`pamsim.backends.BACKENDS`; the identification and every tracking run use it.

    Raises
    ------
    InputError
        For a bad table, a reference the supply cannot hold, or a model that is not a valve's.
    """
    config = CompensationConfig.from_scenario(scenario)
    identification = identify(scenario, config, backend)
    runs = [track(scenario, config, identification, f, backend) for f in config.frequencies_Hz]
    if not all(math.isfinite(r.reduction_percent) for r in runs):
        raise InputError(f"{scenario.origin}: a tracking run without compensation has no error to reduce")
    return CompensationStudy(scenario, config, backend, identification, runs)
