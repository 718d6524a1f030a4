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
    """The markdown text of ``report.md``, its figures linked as ``figure_format`` files."""
    spec = result.spec
    models = spec.friction_models
    thr_mm = spec.capability_min_equilibrium_m * 1e3
    prefixes = {f: ("" if n == 0 else f"{f}_") for n, f in enumerate(models)}
    within = [r for r in result.rows if r["within_capability"] and math.isfinite(r["measured_contraction_m"])]
    measured = [r for r in result.rows if math.isfinite(r["measured_contraction_m"])]
    out = [f"# Sweep report: {spec.name}", ""]
    if spec.description:
        out += [spec.description, ""]
    out += [f"Sweep file `{spec.origin}`, base scenario `{spec.base.origin}`; {len(result.rows)} cases, "
            f"friction models: {', '.join(models)}; {len(result.failures)} failed runs; "
            f"wall time {result.wall_time_s:.2f} s.", "",
            f"*Within force capability* means the static equilibrium contraction is at least {thr_mm:g} mm "
            f"({len(within)} of the {len(measured)} measured cases). Errors are model minus measurement.", ""]
    out += ["## Steady-state contraction against measurement", "",
            "| quantity | cases | RMS error [mm] | max abs error [mm] |", "|---|---|---|---|"]
    stats = [("static equilibrium (no friction), within capability", "equilibrium_error_m", within),
             ("static equilibrium (no friction), all measured cases", "equilibrium_error_m", measured)]
    for f in models:
        stats.append((f"simulated final contraction, {f} friction, within capability", prefixes[f] + "error_m", within))
    for label, col, rows in stats:
        vals = np.array([r[col] for r in rows], dtype=float)
        rms, mx, n = error_stats_mm(vals[np.isfinite(vals)])
        out.append(f"| {label} | {n} | {_num(rms)} | {_num(mx)} |")
    out.append("")
    worst = sorted(within, key=lambda r: -abs(r["equilibrium_error_m"]))[:5]
    if worst:
        out += ["Largest static-equilibrium errors within capability:", "",
                "| weight [N] | pressure [bar] | measured [mm] | equilibrium [mm] | error [mm] | "
                + " | ".join(f"{f} final [mm]" for f in models) + " |",
                "|---|---|---|---|---|" + "---|" * len(models)]
        for r in worst:
            out.append(f"| {r['weight_N']:g} | {r['pressure_bar']:.3f} | {_mm(r['measured_contraction_m'])} | "
                       f"{_mm(r['equilibrium_contraction_m'])} | {_mm(r['equilibrium_error_m'])} | "
                       + " | ".join(_mm(r[prefixes[f] + 'final_contraction_m']) for f in models) + " |")
        out.append("")
    out += ["## Rest at the end of the run", ""]
    for f in models:
        moving = [r for r in result.rows if r[prefixes[f] + "at_rest"] is False]
        out.append(f"- {f}: {len(result.rows) - len(moving)} of {len(result.rows)} cases at rest at the end"
                   + (":" if moving else "."))
        if moving:
            ptp = [r[prefixes[f] + "last_second_peak_to_peak_m"] for r in moving]
            out.append("  not at rest: " + ", ".join(
                f"{r['weight_N']:g} N / {r['pressure_bar']:.3f} bar ({r[prefixes[f] + 'final_mode']})" for r in moving))
            out.append(f"  motion over the last second of the run, peak to peak: {min(ptp) * 1e3:.3f} to "
                       f"{max(ptp) * 1e3:.3f} mm")
    out.append("")
    if result.frequency_rows:
        study = spec.frequency
        source = (study.pressure_table or spec.base.spec["pressure"])
        out += [f"## Oscillation frequency against load at {study.pressure_bar:g} bar", "",
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
        out.append("")
    if result.responses:
        out += ["## Time responses", "", "| scenario | " + " | ".join(
            f"{f} final / peak [mm] | {f} at rest" for f in models) + " |", "|---|" + "---|---|" * len(models)]
        for name, runs in result.responses.items():
            out.append(f"| {name} | " + " | ".join(
                f"{_mm(runs[f].get('final_contraction_m', math.nan))} / {_mm(runs[f].get('peak_contraction_m', math.nan))}"
                f" | {runs[f].get('at_rest', 'failed')}" for f in models) + " |")
        out.append("")
    if result.failures:
        out += ["## Failed runs", ""] + [f"- {m}" for m in result.failures] + [""]
    ext = figure_format
    out += ["## Figures", "", f"![error heatmap](error_heatmap.{ext})", "",
            f"![steady state against pressure](steady_state_vs_pressure.{ext})", "",
            f"![time responses](time_responses.{ext})", "", f"![frequency against load](frequency_vs_load.{ext})", ""]
    return "\n".join(out)


def _inline(table) -> str:
    """A TOML-like one-line rendering of a small table, for the report."""
    parts = []
    for k, v in table.items():
        parts.append(f"{k} = {{{_inline(v)}}}" if isinstance(v, dict) else f"{k} = {v!r}")
    return ", ".join(parts)
