"""``report.md`` of a sweep: error statistics, cases not at rest, frequencies, failures.

Takes a :class:`pamsim.sweep.SweepResult` without importing it (the result imports this module).
"""

from __future__ import annotations

import math

import numpy as np


def error_stats_mm(errors_m: np.ndarray) -> tuple[float, float, int]:
    """RMS and maximum absolute error [mm] and the number of values."""
    e = np.asarray(errors_m, dtype=float) * 1e3
    if e.size == 0:
        return math.nan, math.nan, 0
    return float(np.sqrt(np.mean(e ** 2))), float(np.max(np.abs(e))), int(e.size)


def _mm(v: float) -> str:
    return "n/a" if not math.isfinite(v) else f"{v * 1e3:.2f}"


def _num(v: float, fmt: str = ".2f") -> str:
    return "n/a" if not (isinstance(v, (int, float)) and math.isfinite(v)) else format(v, fmt)


def write_report(result: "SweepResult", figure_format: str = "png") -> str:
    """The markdown text of ``report.md``, its figures linked as ``figure_format`` files.

    Parameters
    ----------
    result : SweepResult
        The sweep's tables.
    figure_format : {"png", "pdf", "svg"}
        The suffix of the figure files the report links.

    Returns
    -------
    str
        The report, one section after the other; a section with nothing to say (no frequency study,
        no failed run) is left out.
    """
    rows = result.rows
    measured = [r for r in rows if math.isfinite(r["measured_contraction_m"])]
    within = [r for r in measured if r["within_capability"]]
    sections = (_introduction(result, len(within), len(measured)), _error_table(result, within, measured),
                _worst_cases(result, within), _rest(result), _frequency(result), _responses(result),
                _failures(result), _figures(figure_format))
    return "\n".join(line for section in sections for line in section)


def _prefixes(models) -> dict[str, str]:
    """The prefix of each friction model's columns in the summary rows (none for the first model)."""
    return {f: ("" if n == 0 else f"{f}_") for n, f in enumerate(models)}


def _introduction(result: "SweepResult", n_within: int, n_measured: int) -> list[str]:
    spec = result.spec
    out = [f"# Sweep report: {spec.name}", ""]
    if spec.description:
        out += [spec.description, ""]
    thr_mm = spec.capability_min_equilibrium_m * 1e3
    return out + [f"Sweep file `{spec.origin}`, base scenario `{spec.base.origin}`; {len(result.rows)} cases, "
                  f"friction models: {', '.join(spec.friction_models)}; {result.failed_runs} failed runs; "
                  f"wall time {result.wall_time_s:.2f} s.", "",
                  f"*Within force capability* means the static equilibrium contraction is at least {thr_mm:g} mm "
                  f"({n_within} of the {n_measured} measured cases). Errors are model minus measurement.", ""]


def _error_table(result: "SweepResult", within: list[dict], measured: list[dict]) -> list[str]:
    """RMS and largest error of the static equilibrium and of each friction model's final contraction."""
    prefixes = _prefixes(result.spec.friction_models)
    stats = [("static equilibrium (no friction), within capability", "equilibrium_error_m", within),
             ("static equilibrium (no friction), all measured cases", "equilibrium_error_m", measured)]
    stats += [(f"simulated final contraction, {f} friction, within capability", prefixes[f] + "error_m", within)
              for f in result.spec.friction_models]
    out = ["## Steady-state contraction against measurement", "",
           "| quantity | cases | RMS error [mm] | max abs error [mm] |", "|---|---|---|---|"]
    for label, col, rows in stats:
        vals = np.array([r[col] for r in rows], dtype=float)
        rms, mx, n = error_stats_mm(vals[np.isfinite(vals)])
        out.append(f"| {label} | {n} | {_num(rms)} | {_num(mx)} |")
    return out + [""]


def _worst_cases(result: "SweepResult", within: list[dict]) -> list[str]:
    """The five largest static-equilibrium errors within capability, with each model's final contraction."""
    worst = sorted(within, key=lambda r: -abs(r["equilibrium_error_m"]))[:5]
    if not worst:
        return []
    models = result.spec.friction_models
    prefixes = _prefixes(models)
    out = ["Largest static-equilibrium errors within capability:", "",
           "| weight [N] | pressure [bar] | measured [mm] | equilibrium [mm] | error [mm] | "
           + " | ".join(f"{f} final [mm]" for f in models) + " |",
           "|---|---|---|---|---|" + "---|" * len(models)]
    for r in worst:
        out.append(f"| {r['weight_N']:g} | {r['pressure_bar']:.3f} | {_mm(r['measured_contraction_m'])} | "
                   f"{_mm(r['equilibrium_contraction_m'])} | {_mm(r['equilibrium_error_m'])} | "
                   + " | ".join(_mm(r[prefixes[f] + 'final_contraction_m']) for f in models) + " |")
    return out + [""]


def _rest(result: "SweepResult") -> list[str]:
    """How many cases each friction model left at rest, and how far the others still move."""
    out = ["## Rest at the end of the run", ""]
    models = result.spec.friction_models
    prefixes = _prefixes(models)
    for f in models:
        out += _rest_of_model(result.rows, f, prefixes[f])
    return out + [""]


def _rest_of_model(rows: list[dict], friction: str, prefix: str) -> list[str]:
    moving = [r for r in rows if r[prefix + "at_rest"] is False]
    line = f"- {friction}: {len(rows) - len(moving)} of {len(rows)} cases at rest at the end"
    if not moving:
        return [line + "."]
    ptp = [r[prefix + "last_second_peak_to_peak_m"] for r in moving]
    return [line + ":",
            "  not at rest: " + ", ".join(
                f"{r['weight_N']:g} N / {r['pressure_bar']:.3f} bar ({r[prefix + 'final_mode']})" for r in moving),
            f"  motion over the last second of the run, peak to peak: {min(ptp) * 1e3:.3f} to "
            f"{max(ptp) * 1e3:.3f} mm"]


def _frequency(result: "SweepResult") -> list[str]:
    """The frequency study's table, if the sweep has one."""
    if not result.frequency_rows:
        return []
    spec = result.spec
    models = spec.friction_models
    study = spec.frequency
    source = (study.pressure_table or spec.base.spec["pressure"])
    out = [f"## Oscillation frequency against load at {study.pressure_bar:g} bar", "",
           f"Pressure source for this study: `{_inline(source)}`. Frequency and damping ratio are estimated "
           "from the turning points of the contraction after the pressure has settled "
           "(`pamsim.oscillation`) over whole periods; n = number of half-cycles seen, n/a = fewer than two "
           "half-cycles; up/down = how much longer the swing up lasts than the swing down, in % of the mean "
           "half-period.", "",
           "| weight [N] | " + " | ".join(f"{f} f [Hz] | {f} zeta | {f} n | {f} up/down [%]" for f in models)
           + " |", "|---|" + "---|---|---|---|" * len(models)]
    for r in result.frequency_rows:
        out.append(f"| {r['weight_N']:g} | " + " | ".join(
            f"{_num(r[f + '_frequency_Hz'], '.3f')} | {_num(r[f + '_damping_ratio'], '.3f')} | "
            f"{r[f + '_n_half_cycles']} | {_num(100 * r[f + '_half_period_asymmetry'], '+.1f')}"
            for f in models) + " |")
    return out + [""]


def _responses(result: "SweepResult") -> list[str]:
    """Final and peak contraction of each time-response scenario, if the sweep has any."""
    if not result.responses:
        return []
    models = result.spec.friction_models
    out = ["## Time responses", "", "| scenario | " + " | ".join(
        f"{f} final / peak [mm] | {f} at rest" for f in models) + " |", "|---|" + "---|---|" * len(models)]
    for name, runs in result.responses.items():
        out.append(f"| {name} | " + " | ".join(
            f"{_mm(runs[f].get('final_contraction_m', math.nan))} / {_mm(runs[f].get('peak_contraction_m', math.nan))}"
            f" | {runs[f].get('at_rest', 'failed')}" for f in models) + " |")
    return out + [""]


def _failures(result: "SweepResult") -> list[str]:
    if not result.failures:
        return []
    more = result.failed_runs - len(result.failures)
    tail = [f"- and {more} more failed samples (every failed run is a row of uncertainty_samples.csv)"] if more else []
    return ["## Failed runs", ""] + [f"- {m}" for m in result.failures] + tail + [""]


def _figures(ext: str) -> list[str]:
    return ["## Figures", "", f"![error heatmap](error_heatmap.{ext})", "",
            f"![steady state against pressure](steady_state_vs_pressure.{ext})", "",
            f"![time responses](time_responses.{ext})", "", f"![frequency against load](frequency_vs_load.{ext})", ""]


def _inline(table) -> str:
    """A TOML-like one-line rendering of a small table, for the report."""
    parts = []
    for k, v in table.items():
        parts.append(f"{k} = {{{_inline(v)}}}" if isinstance(v, dict) else f"{k} = {v!r}")
    return ", ".join(parts)
