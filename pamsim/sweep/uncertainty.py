"""Uncertainty studies: the ``[uncertainty]`` table of a sweep file, its samples and their summary.

Parameters of the base scenario are drawn from normal, uniform or lognormal
distributions, each truncated to its bounds, by plain random sampling or a
Latin hypercube (:mod:`scipy.stats.qmc`), from a fixed seed.  Every sample is
run under every friction model of the sweep; the summary gives quantiles of the
final and peak contraction and of the contraction's settling time.  The format
is described in ``docs/scaling.md`` and ``scenarios/acra2012_fig4_uncertainty.toml``.

Bounds are handled by *truncation*: a uniform number ``u`` in [0, 1) is mapped to
``F(lower) + u (F(upper) - F(lower))`` and through the inverse CDF ``F^-1``.  This
has the same distribution as drawing and rejecting values outside the bounds, keeps
the sample count fixed, and keeps a Latin hypercube stratified (rejection would not).
"""

from __future__ import annotations

import csv
import inspect
import math
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping

import numpy as np

from ..scenario import Scenario
from ..table_checks import TableChecker

DISTRIBUTIONS = {
    "normal": ("mean", "std"),
    "uniform": (),
    "lognormal": ("median", "sigma"),
}
"""Distribution names and their shape keys (besides ``lower`` and ``upper``, which every one needs).
``lognormal``: ``ln(value)`` is normal with mean ``ln(median)`` and standard deviation ``sigma``."""

SAMPLING = ("latin_hypercube", "random")

QUANTITIES = {
    "final_contraction_m": "final contraction [mm]",
    "peak_contraction_m": "peak contraction [mm]",
    "contraction_settled_time_s": "settling time [s]",
}
"""Summarised outputs of each run and their axis labels (contractions shown in mm)."""

DEFAULT_QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)
MIN_BOUND_MASS = 1e-9
"""Bounds holding less probability than this exclude the distribution: an error, not a silent clamp."""

_TABLE_KEYS = {"samples", "seed", "sampling", "quantiles", "parameters"}
_PARAM_KEYS = {"distribution", "relative", "lower", "upper", "mean", "std", "median", "sigma"}


@dataclass(frozen=True)
class ParameterDistribution:
    """One sampled parameter: a distribution truncated to ``[lower, upper]``.

    With ``relative`` the distribution is of a factor applied to the base
    scenario's value ``nominal`` (so ``lower = 0.9, upper = 1.1`` is +-10 %).
    """

    name: str
    distribution: str
    lower: float
    upper: float
    shape: tuple[float, ...]
    relative: bool
    nominal: float

    def frozen(self):
        """The untruncated scipy distribution (of the factor when ``relative``)."""
        from scipy import stats  # imported when a study samples: it costs every sweep half a second

        if self.distribution == "normal":
            return stats.norm(loc=self.shape[0], scale=self.shape[1])
        if self.distribution == "lognormal":
            return stats.lognorm(s=self.shape[1], scale=self.shape[0])
        return stats.uniform(loc=self.lower, scale=self.upper - self.lower)

    def bound_mass(self) -> float:
        """Probability of the untruncated distribution inside the bounds."""
        d = self.frozen()
        return float(d.cdf(self.upper) - d.cdf(self.lower))

    def transform(self, u: np.ndarray) -> np.ndarray:
        """Values of the parameter (in its own unit) for uniform numbers ``u`` in [0, 1)."""
        d = self.frozen()
        lo, hi = d.cdf(self.lower), d.cdf(self.upper)
        x = np.clip(d.ppf(lo + np.asarray(u, dtype=float) * (hi - lo)), self.lower, self.upper)
        return x * self.nominal if self.relative else x

    def describe(self) -> str:
        """One line for reports, e.g. ``uniform factor on [0.9, 1.1] x 1e-09``."""
        shape = ", ".join(f"{k} = {v:g}" for k, v in zip(DISTRIBUTIONS[self.distribution], self.shape))
        what = f"{self.distribution}({shape})" if shape else self.distribution
        bounds = f"on [{self.lower:g}, {self.upper:g}]"
        return f"{what} factor {bounds} x {self.nominal:g}" if self.relative else f"{what} {bounds}"


@dataclass(frozen=True)
class Samples:
    """Drawn parameter values: ``values[k, j]`` is parameter ``names[j]`` of sample ``k``."""

    names: tuple[str, ...]
    values: np.ndarray


@dataclass(frozen=True)
class UncertaintySpec:
    """A validated ``[uncertainty]`` table."""

    parameters: tuple[ParameterDistribution, ...]
    samples: int
    seed: int
    sampling: str
    quantiles: tuple[float, ...] = DEFAULT_QUANTILES

    def uniforms(self) -> np.ndarray:
        """The ``(samples, parameters)`` array of uniform numbers in [0, 1) behind :meth:`draw`."""
        d = len(self.parameters)
        rng = np.random.default_rng(self.seed)
        if self.sampling == "random":
            return rng.random((self.samples, d))
        from scipy.stats import qmc

        # scipy >= 1.15 names the generator ``rng``; older versions call it ``seed``.
        kw = "rng" if "rng" in inspect.signature(qmc.LatinHypercube).parameters else "seed"
        return qmc.LatinHypercube(d=d, **{kw: rng}).random(self.samples)

    def draw(self) -> Samples:
        """The samples; the same seed gives the same values on every machine and executor."""
        u = self.uniforms()
        cols = [p.transform(u[:, j]) for j, p in enumerate(self.parameters)]
        return Samples(tuple(p.name for p in self.parameters), np.column_stack(cols))


# ---------------------------------------------------------------- reading the table
def _sampling_name(sampling: str) -> str:
    """The sampling's name in a sentence: ``latin hypercube``, ``random sample``."""
    return "Latin hypercube" if sampling == "latin_hypercube" else "random sample"


def parse_uncertainty(check: TableChecker, table: Any, base: Scenario) -> UncertaintySpec:
    """Validate an ``[uncertainty]`` table against the base scenario's parameter set.

    Every mistake raises ``check.error`` (:class:`pamsim.sweep.SweepError` in a sweep file) naming
    the file, the key and the value.
    """
    check.check_keys("[uncertainty]", "uncertainty.", table, _TABLE_KEYS)
    n = check.required(table, "samples", int, "uncertainty.")
    if isinstance(n, bool) or n < 1:
        check.fail("uncertainty.samples", n, "must be a positive integer")
    seed = check.required(table, "seed", int, "uncertainty.")
    if isinstance(seed, bool) or seed < 0:
        check.fail("uncertainty.seed", seed, "must be a non-negative integer")
    sampling = check.typed("uncertainty.sampling", table.get("sampling", "latin_hypercube"), str)
    if sampling not in SAMPLING:
        check.fail("uncertainty.sampling", sampling, "unknown sampling", SAMPLING)
    quantiles = table.get("quantiles", list(DEFAULT_QUANTILES))
    if not isinstance(quantiles, list) or not quantiles:
        check.fail("uncertainty.quantiles", quantiles, "must be a non-empty list of numbers in [0, 1]")
    for q in quantiles:
        if not 0.0 <= check.number("uncertainty.quantiles", q) <= 1.0:
            check.fail("uncertainty.quantiles", q, "must lie in [0, 1]")
    params = check.required(table, "parameters", dict, "uncertainty.")
    if not params:
        raise check.error(f"{check.origin}: uncertainty.parameters is empty: name at least one parameter to sample")
    dists = []
    for name, entry in params.items():
        if name not in base.parameters.entries:
            check.fail(f"uncertainty.parameters.{name}", entry, "unknown parameter", base.parameters.entries)
        dists.append(_distribution(check, f"uncertainty.parameters.{name}", name, entry, base))
    return UncertaintySpec(tuple(dists), n, seed, sampling, tuple(float(q) for q in quantiles))


def _distribution(check: TableChecker, where: str, name: str, entry: Any, base: Scenario) -> ParameterDistribution:
    """Parameter ``name``'s table ``entry`` (at ``where``) read into its distribution, checked in this order:
    its keys and kind, ``relative``, the bounds, the shape, that a factor can vary the base value, that the
    bounds hold some of the distribution and that they give values within the parameter's range."""
    kind = _kind(check, where, entry)
    relative = check.typed(f"{where}.relative", entry.get("relative", False), bool)
    lower, upper = _bounds(check, where, entry)
    shape = _shape(check, where, entry, kind)
    nominal = float(base.parameters[name])
    if relative and nominal == 0.0:
        check.fail(f"{where}.relative", True, "the base value is 0, so a factor cannot vary it")
    dist = ParameterDistribution(name, kind, lower, upper, shape, relative, nominal)
    _check_bound_mass(check, where, dist)
    _check_parameter_range(check, where, dist, base.parameters.entries[name])
    return dist


def _kind(check: TableChecker, where: str, entry: Any) -> str:
    """The entry's distribution, known, with no key that another distribution takes."""
    check.check_keys(f"[{where}]", where + ".", entry, _PARAM_KEYS)
    kind = check.required(entry, "distribution", str, where + ".")
    if kind not in DISTRIBUTIONS:
        check.fail(f"{where}.distribution", kind, "unknown distribution", DISTRIBUTIONS)
    allowed = {"distribution", "relative", "lower", "upper", *DISTRIBUTIONS[kind]}
    for key in entry:
        if key not in allowed:
            check.fail(f"{where}.{key}", entry[key], f"does not apply to a {kind} distribution "
                       f"(it takes {', '.join(sorted(allowed - {'distribution'}))})")
    return kind


def _bounds(check: TableChecker, where: str, entry: Any) -> tuple[float, float]:
    """``lower`` and ``upper``, the one below the other."""
    lower = check.required(entry, "lower", float, where + ".")
    upper = check.required(entry, "upper", float, where + ".")
    if not lower < upper:
        check.fail(f"{where}.upper", upper, f"must be above lower = {lower:g}")
    return lower, upper


def _shape(check: TableChecker, where: str, entry: Any, kind: str) -> tuple[float, ...]:
    """The shape keys of ``kind`` (:data:`DISTRIBUTIONS`): a positive spread, and a positive lognormal median."""
    shape = tuple(check.required(entry, k, float, where + ".") for k in DISTRIBUTIONS[kind])
    if kind in ("normal", "lognormal") and not shape[1] > 0:
        check.fail(f"{where}.{DISTRIBUTIONS[kind][1]}", shape[1], "must be positive")
    if kind == "lognormal" and not shape[0] > 0:
        check.fail(f"{where}.median", shape[0], "must be positive")
    return shape


def _check_bound_mass(check: TableChecker, where: str, dist: ParameterDistribution) -> None:
    """Refuse bounds that hold (next to) none of the distribution: a truncation to them would be all clamp."""
    mass = dist.bound_mass()
    if not mass >= MIN_BOUND_MASS:
        check.fail(f"{where}.lower", dist.lower, f"the bounds [{dist.lower:g}, {dist.upper:g}] exclude the "
                   f"{dist.distribution} distribution (probability inside {mass:.3g})")


def _check_parameter_range(check: TableChecker, where: str, dist: ParameterDistribution, rule) -> None:
    """Refuse a bound that gives a value outside the parameter's own range (``rule``, its schema entry)."""
    for key, bound in (("lower", dist.lower), ("upper", dist.upper)):
        value = bound * dist.nominal if dist.relative else bound
        why = rule.violation(value)
        if why is not None:
            check.fail(f"{where}.{key}", bound, f"gives {dist.name} = {value:g}, which {why}")


# ---------------------------------------------------------------- results
LOST = "lost: "
"""How the error of a run that the executor lost (its worker or cluster gone) begins: it has no result,
and the study is incomplete."""

MAX_KEPT_MESSAGES = 10
"""Failed runs' messages a study keeps in memory per friction model (those of the lowest sample numbers);
the samples table holds every one."""


@dataclass
class RunColumns:
    """What a study keeps in memory of one friction model's runs: the summarised quantities as columns of
    floats (``values[quantity][k]`` is run ``k``'s, NaN where the run failed), the number of failed and of
    lost runs, and the first :data:`MAX_KEPT_MESSAGES` failures' messages (``errors[k]``).

    The quantiles and the figures need every value, 8 bytes per run and quantity (24 bytes per run); the rest
    of each run goes to the samples table on disk (:mod:`.sample_table`).
    """

    values: dict[str, np.ndarray]
    errors: dict[int, str] = field(default_factory=dict)
    n_failed: int = 0
    n_lost: int = 0

    @classmethod
    def empty(cls, n: int) -> "RunColumns":
        """Room for ``n`` runs, every value NaN."""
        return cls({key: np.full(n, math.nan) for key in QUANTITIES})

    def put(self, k: int, output: Mapping) -> None:
        """Keep run ``k``'s output (a run's dict, with its ``error`` message, empty if it succeeded)."""
        error = output["error"]
        if error:
            self.n_failed += 1
            self.n_lost += error.startswith(LOST)
            self.errors[k] = error
            if len(self.errors) > MAX_KEPT_MESSAGES:  # the chunks finish in any order: keep the first samples'
                del self.errors[max(self.errors)]
        for key in QUANTITIES:
            self.values[key][k] = math.nan if error else output.get(key, math.nan)

    def output(self, k: int) -> dict:
        """Run ``k``'s summarised quantities (NaN where it failed)."""
        return {key: float(self.values[key][k]) for key in QUANTITIES}

    def lost(self) -> int:
        """Runs the executor lost (no result at all, as opposed to a run that failed)."""
        return self.n_lost


@dataclass
class UncertaintyResult:
    """The runs of an uncertainty study: ``runs[friction]`` holds what is kept in memory of every sample's run
    under ``friction``, ``table`` the per-run table on disk (a :class:`.sample_table.SampleTable`, finished)."""

    spec: UncertaintySpec
    samples: Samples
    runs: Mapping[str, RunColumns]
    table: Any = None

    @property
    def friction_models(self) -> list[str]:
        """The friction models, in the sweep's order."""
        return list(self.runs)

    def output(self, friction: str, k: int) -> dict:
        """Sample ``k``'s summarised quantities under ``friction`` (:meth:`RunColumns.output`)."""
        return self.runs[friction].output(k)

    def values(self, friction: str, quantity: str) -> np.ndarray:
        """``quantity`` of every successful run of ``friction`` (failed runs, NaN in the columns, left out)."""
        v = self.runs[friction].values[quantity]
        return v[np.isfinite(v)]

    def failed(self, friction: str) -> int:
        """Number of failed runs under ``friction`` (the lost ones included)."""
        return self.runs[friction].n_failed

    def lost(self) -> int:
        """Runs that the executor lost, under every friction model: the sample is incomplete if any."""
        return sum(r.lost() for r in self.runs.values())

    def quantile_rows(self) -> list[dict]:
        """One row per friction model and quantity: count, failed and lost runs, mean, standard deviation and
        quantiles (of the successful runs)."""
        rows = []
        for f in self.runs:
            for q in QUANTITIES:
                v = self.values(f, q)
                row = {"friction_model": f, "quantity": q, "runs": int(v.size), "failed": self.failed(f),
                       "lost": self.runs[f].lost(), "mean": float(v.mean()) if v.size else math.nan,
                       "std": float(v.std(ddof=1)) if v.size > 1 else math.nan}
                for p in self.spec.quantiles:
                    row[f"q{p:g}"] = float(np.quantile(v, p)) if v.size else math.nan
                rows.append(row)
        return rows

    def sample_rows(self) -> Iterator[dict]:
        """The rows of the samples table as read back from its file (strings), one at a time."""
        with open(self.table.path, newline="") as fh:
            yield from csv.DictReader(fh)

    def write_tables(self, samples_path, summary_path) -> None:
        """Publish the per-run table as ``samples_path`` and write the quantile table as CSV (the caller stages
        them atomically)."""
        self.table.publish(samples_path)
        rows = self.quantile_rows()
        with open(summary_path, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            for row in rows:
                w.writerow({k: (f"{v:.9g}" if isinstance(v, float) else v) for k, v in row.items()})

    def __getstate__(self) -> dict:
        # A worker that draws the figures gets the columns, not the table (an open file's object).
        return {**self.__dict__, "table": None}

    def close(self) -> None:
        """Remove the per-run table's temporary file (once it is published, or not wanted)."""
        if self.table is not None:
            self.table.discard()

    def report(self, sweep_name: str, figure_format: str = "png") -> str:
        """The markdown text of ``uncertainty.md``, its figures linked as ``figure_format`` files."""
        s = self.spec
        out = [f"# Uncertainty study: {sweep_name}", "",
               f"{s.samples} samples ({s.sampling.replace('_', ' ')}, seed {s.seed}) of {len(s.parameters)} "
               f"parameters, each run under {', '.join(self.runs)} friction; distributions truncated to "
               "their bounds.", "", "| parameter | distribution |", "|---|---|"]
        out += [f"| {p.name} | {p.describe()} |" for p in s.parameters]
        out += self._incomplete_note()
        out += ["", "Contractions in mm; the settling time is the first time (from the start of the run) after "
                "which the contraction stays within 5 % of its change of its final value.", "",
                "| friction | quantity | runs | failed | mean | std | "
                + " | ".join(f"q{p:g}" for p in s.quantiles) + " |", "|---|---|---|---|---|---|"
                + "---|" * len(s.quantiles)]
        for row in self.quantile_rows():
            scale = 1e3 if row["quantity"].endswith("_m") else 1.0
            nums = [row["mean"], row["std"], *(row[f"q{p:g}"] for p in s.quantiles)]
            out.append(f"| {row['friction_model']} | {QUANTITIES[row['quantity']]} | {row['runs']} | {row['failed']} | "
                       + " | ".join(f"{v * scale:.4g}" for v in nums) + " |")
        out += ["", f"![histograms](uncertainty_histograms.{figure_format})", "",
                f"![ECDF](uncertainty_ecdf.{figure_format})", ""]
        return "\n".join(out)

    def _incomplete_note(self) -> list[str]:
        """The report's warning that runs were lost, so the quantiles come from part of the sample (nothing if
        none was)."""
        lost = self.lost()
        if not lost:
            return []
        total = len(self.samples.values) * len(self.runs)
        return ["", f"**Incomplete sample: {lost} of {total} runs were lost** (their worker or cluster went away; "
                    "the `lost` column). The quantiles below come from the runs that finished, which are not the "
                    f"{_sampling_name(self.spec.sampling)} that was drawn: rerun the study for its quantiles."]
