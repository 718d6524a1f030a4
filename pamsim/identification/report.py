"""Writing a fit's folder: ``fit.json``, the fitted ``muscle.toml``, ``report.md`` and figures, all or
nothing (pamsim.atomic)."""

from __future__ import annotations

import contextlib
import csv
import datetime
import json
import math
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

from ..atomic import atomic_outputs
from ..figure_style import check_format
from ..parameter_schema import UPPER_BASES
from .compare import comparison_rows, write_comparison_csv
from .muscle_file import muscle_toml, scenario_upper_stop
from .plots import plot_comparison, plot_correlation, plot_dynamic_fit, plot_static_fit, plot_static_residuals

if TYPE_CHECKING:
    from .dynamic_fit import DynamicFit
    from .static_fit import StaticFit


@contextlib.contextmanager
def _outputs(directory, names: list[str]):
    """:func:`pamsim.atomic.atomic_outputs`, and a folder it had to create is removed again on failure."""
    directory = Path(directory)
    existed = directory.exists()
    try:
        with atomic_outputs(directory, names) as out:
            yield out
    except BaseException:
        if not existed:
            with contextlib.suppress(OSError):
                directory.rmdir()  # only if empty: never remove what someone else put there
        raise


def _f(v: float, fmt: str = ".4g") -> str:
    return "n/a" if v is None or not math.isfinite(v) else format(v, fmt)


def provenance(origin: str, sha256: str, objective: str, rms_text: str) -> dict:
    """The provenance lines of a fitted muscle file."""
    return {"fitted by": "pamsim fit", "data file": Path(origin).name, "data sha256": sha256,
            "date (UTC)": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
            "objective": objective, "fit quality": rms_text}


def parameter_table(names: Sequence[str], start: dict, fitted: dict, unc, intervals: dict | None = None) -> list[str]:
    """Markdown rows: coefficient, start value, fitted value, standard error ("not identified" where
    the data carry no information on the coefficient) and, with ``intervals`` (a static fit's
    ``intervals_json()``), the 95 % Wald and profile-likelihood intervals."""
    errors = dict(zip(unc.names, map(float, unc.standard_errors)))
    blind = set(unc.not_identified())
    head, rule = "| coefficient | start | fitted | standard error |", "|---|---|---|---|"
    if intervals is not None:
        head, rule = head + " 95 % Wald | 95 % profile |", rule + "---|---|"
    out = [head, rule]
    for n in names:
        row = f"| {n} | {_f(start[n])} | {_f(fitted[n])} | {'not identified' if n in blind else _f(errors[n])} |"
        if intervals is not None:
            row += f" {_interval(intervals[n]['wald'])} | {_interval(intervals[n]['profile'])} |"
        out.append(row)
    return out


def _interval(ends) -> str:
    """``[lo, hi]`` for a report; an end the data do not set is an infinity, no interval is n/a."""
    if ends is None or all(e is None for e in ends):
        return "n/a"
    lo, hi = ("-inf" if ends[0] is None else _f(ends[0])), ("inf" if ends[1] is None else _f(ends[1]))
    return f"[{lo}, {hi}]"


def correlation_lines(fit_unc) -> list[str]:
    """Markdown lines on what the data do not show: coefficients not identified, and pairs correlated
    beyond ``|r| = 0.95``.
    """
    pairs = fit_unc.inseparable_pairs()
    blind = fit_unc.not_identified()
    out = []
    if blind:
        out += [f"**Not identified:** {', '.join(blind)}: the data carry no information on "
                f"{'it' if len(blind) == 1 else 'them'} (the fitted value is the optimiser's, not the data's).", ""]
    if not pairs and not blind:
        return ["No two coefficients are correlated beyond |r| = 0.95: the data separate them.", ""]
    if pairs:
        out += ["**Coefficients the data cannot separate** (|r| > 0.95); trust their combination, not each alone:",
                ""] + [f"- {a} and {b}: r = {r:+.3f}" for a, b, r in pairs] + [""]
    return out


def upper_stop_line(stop: dict) -> str:
    """The report's line on the fitted muscle's upper stop (:meth:`StaticFit.upper_stop_json`)."""
    line = f"- upper stop: {stop['x_m'] * 1e3:.4g} mm, {UPPER_BASES[stop['basis']]} (choice {stop['at']!r})"
    on = stop["tests_on_stop"]
    if on:
        line += (f"; **{len(on)} test(s) predicted on it** (tests {', '.join(str(i) for i in on)}, counted from 0 "
                 "in the data's order): the fitted model still pulls harder than the load there")
    return line


def static_report_md(fit: "StaticFit", compare: Sequence[dict] | None, figure_format: str = "png") -> str:
    """The static fit's report in Markdown: errors, coefficients, correlations, the compared models and
    figures.
    """
    p = fit.problem
    start = {n: p.base[n] for n in p.free}
    out = [f"# Static fit: {p.model} on {Path(p.data.origin).name}", "",
           f"- muscle: {fit.muscle}; objective: **{p.objective}**; loss: {fit.loss}; extra starts: {fit.n_starts}",
           f"- tests: {fit.n_points}, censored (not lifted, <= {p.censor_threshold_m * 1e3:g} mm): {fit.n_censored}",
           f"- RMS equilibrium contraction error over all tests: **{_f(fit.rms_contraction_mm, '.3f')} mm**; "
           f"cross-validated ({fit.cv_kind}): **{_f(fit.cv_rms_contraction_mm, '.3f')} mm**",
           f"- RMS force error over the lifted tests: {_f(fit.rms_force_N, '.3f')} N",
           f"- AIC {_f(fit.aic, '.2f')}, BIC {_f(fit.bic, '.2f')}; optimiser: {fit.message} ({fit.nfev} evaluations)",
           upper_stop_line(fit.upper_stop_json()), "", "## Coefficients", ""]
    out += parameter_table(p.free, start, fit.parameters, fit.uncertainty, fit.intervals_json()) + [""]
    out += ["Standard errors come from the Jacobian at the optimum (linearised, residual variance from the fit); "
            "the Wald interval is the fitted value plus or minus the Student-t quantile times the standard error. "
            "The profile interval holds the values at which the sum of squares, the other coefficients refitted, "
            "stays within that quantile squared times the residual variance of its minimum: it follows the "
            "model's curvature where the Wald interval cannot (computed with the linear loss only).",
            ""] + correlation_lines(fit.uncertainty)
    ext = figure_format
    out += ["## Figures", "", f"![measured and fitted](fit.{ext})", "", f"![residuals](residuals.{ext})", "",
            f"![correlation](correlation.{ext})", ""]
    if compare:
        out += ["## Model comparison", "", "Ranked by AIC; the Akaike weight is the relative likelihood of each "
                "model being the best of those compared, on these tests and this objective.", "",
                "| rank | model | free | RMS [mm] | CV RMS [mm] | AIC | ΔAIC | Akaike weight | BIC |",
                "|---|---|---|---|---|---|---|---|---|"]
        out += [f"| {r['rank']} | {r['model']} | {r['n_free']} | {_f(r['rms_contraction_mm'], '.3f')} | "
                f"{_f(r['cv_rms_contraction_mm'], '.3f')} | {_f(r['aic'], '.2f')} | {_f(r['delta_aic'], '.2f')} | "
                f"{_f(r['akaike_weight'], '.3g')} | {_f(r['bic'], '.2f')} |" for r in compare]
        out += ["", f"![comparison](compare.{ext})", ""]
    return "\n".join(out)


def write_static_fit(fit: "StaticFit", directory, compare: Sequence["StaticFit"] | None = None,
                     figure_format: str = "png", dpi: int | None = None) -> list[str]:
    """Write fit.json, muscle.toml (with a copy of the data beside it), report.md and figures (fit, residuals,
    correlation; PNG, PDF or SVG by ``figure_format``, at ``dpi`` dots per inch) into ``directory``; with
    ``compare``, also compare.csv and the compare figure.  Returns the file names."""
    p = fit.problem
    ext = check_format(figure_format, label="figure format")
    rows = comparison_rows(compare) if compare else None
    has_file = Path(p.data.origin).is_file()
    names = ["fit.json", "muscle.toml"] + (["data.csv"] if has_file else []) + \
        ["report.md", f"fit.{ext}", f"residuals.{ext}", f"correlation.{ext}"]
    if rows:
        names += ["compare.csv", f"compare.{ext}"]
    rms = (f"RMS contraction {fit.rms_contraction_mm:.3f} mm, cross-validated "
           f"{_f(fit.cv_rms_contraction_mm, '.3f')} mm ({fit.cv_kind})")
    prov = provenance(p.data.origin, p.data.sha256, p.objective, rms)
    body = fit.to_json()
    if rows:
        body["compare"] = rows
    with _outputs(directory, names) as out:
        out["fit.json"].write_text(json_text(body))
        out["muscle.toml"].write_text(muscle_toml(
            fit.fitted, name=f"{fit.fitted.name}_fitted",
            description=f"{fit.fitted.name} with {', '.join(p.free)} fitted by pamsim fit static "
                        f"({p.objective} objective, {rms}) on {Path(p.data.origin).name} "
                        f"(sha256 {p.data.sha256})",
            citation=fit.fitted.citation, static_force=p.model, provenance=prov, data_file="data.csv" if has_file else None,
            upper_stop=p.upper_stop))
        if has_file:
            shutil.copyfile(p.data.origin, out["data.csv"])
        out["report.md"].write_text(static_report_md(fit, rows, ext))
        plot_static_fit(fit, out[f"fit.{ext}"], dpi)
        plot_static_residuals(fit, out[f"residuals.{ext}"], dpi)
        plot_correlation(p.free, fit.uncertainty.correlation, out[f"correlation.{ext}"], dpi)
        if rows:
            write_comparison_csv(rows, out["compare.csv"])
            plot_comparison(rows, out[f"compare.{ext}"], dpi)
    return names


def json_text(body) -> str:
    """JSON with non-finite numbers written as null (strict JSON has no NaN)."""
    return json.dumps(_clean(body), indent=2, allow_nan=False) + "\n"


def _clean(v):
    if isinstance(v, dict):
        return {k: _clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_clean(x) for x in v]
    if hasattr(v, "tolist"):
        return _clean(v.tolist())
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def scenario_toml(spec: dict, header: Sequence[str]) -> str:
    """A scenario spec (as validated by :class:`pamsim.Scenario`) as TOML text; sub-tables inline."""
    lines = [f"# {h}" for h in header]
    lines += [f"{k} = {_toml_value(v)}" for k, v in spec.items() if not isinstance(v, dict)]
    for section, table in spec.items():
        if isinstance(table, dict):
            lines += ["", f"[{section}]"] + [f"{k} = {_toml_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _absolute_files(value, base_dir: Path):
    """Trace file names made absolute, so the written scenario works from the output folder."""
    if isinstance(value, dict):
        return {k: (str((base_dir / v).resolve()) if k == "file" and isinstance(v, str) else _absolute_files(v, base_dir))
                for k, v in value.items()}
    return value


def dynamic_report_md(fit: "DynamicFit", figure_format: str = "png") -> str:
    """The dynamic fit's report in Markdown: errors per trace, coefficients, correlations and figures."""
    p = fit.problem
    start = dict(zip(p.free, map(float, fit.start)))
    out = [f"# Dynamic fit (eq. 13) on {len(p.traces)} trace(s), scenario {p.scenario.name}", "",
           f"- pooled RMS contraction error in the window: **{fit.rms_pooled_mm:.4f} mm**",
           f"- {fit.n_simulations} simulations in {fit.wall_time_s:.2f} s, {fit.n_starts} extra start(s); "
           f"optimiser: {fit.message}", ""]
    out += [f"**Warning:** {w}." for w in fit.warnings] + ([""] if fit.warnings else [])
    out += ["| trace | load [N] | pressure | RMS [mm] | noise [mm] |", "|---|---|---|---|---|"]
    out += [f"| {tr.origin} | {w:g} | {'recorded' if tr.p_gauge_Pa is not None else 'scenario valve'} | {r:.4f} | "
            f"{n:.4f} |" for tr, w, r, n in zip(p.traces, p.loads_N, fit.rms_contraction_mm, fit.noise_mm)]
    out += ["", "## Coefficients", ""] + parameter_table(p.free, start, fit.parameters, fit.uncertainty) + [""]
    out += correlation_lines(fit.uncertainty)
    if fit.per_trace:
        out += ["## Each trace alone (the layout of the paper's Table 4)", "",
                "| trace | final pressure [bar] | load [N] | " + " | ".join(p.free) + " | RMS [mm] |",
                "|---|---|---|" + "---|" * len(p.free) + "---|"]
        out += [f"| {row['trace']} | {row['pressure_final_bar']:.3f} | {row['load_N']:g} | "
                + " | ".join(f"{row[n]:.4g}" for n in p.free) + f" | {row['rms_contraction_mm']:.4f} |"
                for row in fit.per_trace]
        out += [""]
    out += [f"![measured and fitted](fit.{figure_format})", "", f"![correlation](correlation.{figure_format})", ""]
    return "\n".join(out)


def write_dynamic_fit(fit: "DynamicFit", directory, figure_format: str = "png", dpi: int | None = None) -> list[str]:
    """Write fit.json, muscle.toml, scenario.toml (the scenario with the fitted coefficients), report.md and
    the figures fit (overlays and residuals) and correlation (PNG, PDF or SVG by ``figure_format``, at ``dpi``
    dots per inch); per_trace.csv with a per-trace fit."""
    p = fit.problem
    ext = check_format(figure_format, label="figure format")
    names = ["fit.json", "muscle.toml", "scenario.toml", "report.md", f"fit.{ext}", f"correlation.{ext}"]
    if fit.per_trace:
        names.append("per_trace.csv")
    rms = f"pooled RMS contraction {fit.rms_pooled_mm:.4f} mm over {len(p.traces)} trace(s)"
    prov = {"fitted by": "pamsim fit dynamic (eq. 13)",
            "traces": ", ".join(f"{Path(t.origin).name} (sha256 {t.sha256})" for t in p.traces),
            "date (UTC)": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
            "objective": "sum of squared contraction residuals in the window", "fit quality": rms}
    source = f"fitted: pamsim fit dynamic on {', '.join(Path(t.origin).name for t in p.traces)}"
    fitted = p.scenario.parameters.with_overrides(fit.parameters, source=source)
    spec = _absolute_files(dict(p.scenario.spec), p.scenario.base_dir)
    spec["parameters"] = {**spec.get("parameters", {}), **fit.parameters}
    spec["name"] = f"{p.scenario.name}_fitted"
    with _outputs(directory, names) as out:
        out["fit.json"].write_text(json_text(fit.to_json()))
        out["muscle.toml"].write_text(muscle_toml(
            fitted, name=f"{fitted.name}_dynamic_fit",
            description=f"{fitted.name} with {', '.join(p.free)} fitted by pamsim fit dynamic ({rms})",
            citation=fitted.citation, static_force=p.scenario.spec["model"]["static_force"], provenance=prov,
            upper_stop=scenario_upper_stop(p.scenario)))
        out["scenario.toml"].write_text(scenario_toml(spec, [f"{k}: {v}" for k, v in prov.items()]))
        out["report.md"].write_text(dynamic_report_md(fit, ext))
        plot_dynamic_fit(fit, out[f"fit.{ext}"], dpi)
        plot_correlation(p.free, fit.uncertainty.correlation, out[f"correlation.{ext}"], dpi)
        if fit.per_trace:
            cols = list(fit.per_trace[0])
            with open(out["per_trace.csv"], "w", newline="") as fh:
                w = csv.DictWriter(fh, fieldnames=cols)
                w.writeheader()
                w.writerows(fit.per_trace)
    return names
