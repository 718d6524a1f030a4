"""Writing a hysteresis fit's folder: ``fit.json``, ``report.md``, ``compare.csv`` and the loop and residual
figures, all or nothing (:func:`pamsim.atomic.atomic_outputs`)."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import TYPE_CHECKING

from ..atomic import atomic_outputs
from ..figure_style import check_format
from ..identification.report import json_text
from .fit import CONFIDENCE
from .plots import plot_loop, plot_residuals

if TYPE_CHECKING:
    from .fit import HysteresisFit, ModelFit


def _g(v: float) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.6g}"


def parameter_lines(fit: "ModelFit") -> list[str]:
    """``name = value  [low, high]`` per parameter; ``not identified`` instead of an interval the data do not
    bound."""
    intervals = fit.intervals()
    width = max(map(len, fit.names))
    out = []
    for name, value in zip(fit.names, fit.values):
        ends = intervals[name]
        band = "not identified" if ends is None else f"[{_g(ends[0])}, {_g(ends[1])}]"
        out.append(f"{name:<{width}} = {_g(float(value)):>12}  {band}")
    return out


def comparison_lines(fit: "HysteresisFit") -> list[str]:
    """The comparison as aligned text, the least BIC marked."""
    rows = fit.comparison_rows()
    best = min(rows, key=lambda r: r["bic"])
    out = [f"{'model':<18} {'k':>3} {'RMS [N]':>10} {'AIC':>12} {'BIC':>12}"]
    for r in rows:
        mark = "  <- least BIC" if r is best else ""
        out.append(f"{r['label']:<18} {r['n_parameters']:>3} {r['rms_N']:>10.4g} {r['aic']:>12.2f} "
                   f"{r['bic']:>12.2f}{mark}")
    return out


def correlation_lines(fit: "HysteresisFit") -> list[str]:
    """A warning when the reported fit's residual is correlated (model error along the loop), and what that does
    to the intervals and the comparison; nothing when it is white."""
    r = fit.chosen.correlation
    if not r.significant:
        return []
    return [f"warning: the residual is correlated along the loop (lag-1 autocorrelation {r.lag1:.4g}; white noise "
            f"stays below {1.96 / math.sqrt(r.samples):.2g}): model error, or noise that is not white; its "
            f"autocorrelation lasts {r.integrated_time_samples:.4g} samples, so about {r.effective_samples:.4g} of the "
            f"{r.samples} are independent: the intervals are widened {r.widening:.3g} times and AIC and BIC count "
            f"{fit.effective_samples:.4g} samples (--residual white takes the residual as white noise)"]


def summary_lines(fit: "HysteresisFit") -> list[str]:
    """What ``pamsim fit hysteresis`` prints: the reported fit, its parameters and the comparison."""
    c = fit.chosen
    how = "" if c.model != "maxwell_slip" else (" (N given)" if fit.elements_given else " (N chosen by BIC)")
    return [f"{c.label}{how} on {fit.data.origin}: RMS {c.rms_N:.4g} N over {len(fit.data)} samples, "
            f"AIC {c.aic:.2f}, BIC {c.bic:.2f}", *correlation_lines(fit),
            f"parameters ({100 * CONFIDENCE:g} % intervals from the Jacobian):",
            *("  " + line for line in parameter_lines(c)), "comparison:", *("  " + line for line in comparison_lines(fit))]


def report_md(fit: "HysteresisFit", ext: str) -> str:
    """``report.md``: provenance, the summary and the figures."""
    d = fit.data
    window = "" if d.window_s is None else f" from {d.window_s[0]:g} s to {d.window_s[1]:g} s"
    force = dict(d.columns).get("force", "")
    derived = f" (at a hanging load: {force}, quasi-static)" if d.level_N is not None else ""
    lines = ["# Hysteresis fit", "", f"- data: `{Path(d.origin).name}` (sha256 `{d.sha256}`), {len(d)} samples{window}",
             f"- input: contraction (m); output: force (N){derived}; models start relaxed at the first sample", "",
             "```", *summary_lines(fit), "```", "", f"![loop](fit.{ext})", "", f"![residuals](residuals.{ext})", ""]
    return "\n".join(lines)


def write_hysteresis_fit(fit: "HysteresisFit", directory, figure_format: str = "png",
                         dpi: int | None = None) -> list[str]:
    """Write fit.json, report.md, compare.csv, fit.EXT (the loops) and residuals.EXT into ``directory``;
    return the names."""
    ext = check_format(figure_format, label="figure format")
    names = ["fit.json", "report.md", "compare.csv", f"fit.{ext}", f"residuals.{ext}"]
    with atomic_outputs(directory, names) as out:
        out["fit.json"].write_text(json_text(fit.to_json()))
        out["report.md"].write_text(report_md(fit, ext))
        with open(out["compare.csv"], "w", newline="") as fh:
            writer = csv.DictWriter(fh, ["label", "n_parameters", "rms_N", "aic", "bic"])
            writer.writeheader()
            writer.writerows(fit.comparison_rows())
        plot_loop(fit, out[f"fit.{ext}"], dpi)
        plot_residuals(fit, out[f"residuals.{ext}"], dpi)
    return names
