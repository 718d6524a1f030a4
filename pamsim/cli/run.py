"""``pamsim run SCENARIO -o DIR``: simulate one scenario, write CSV, PNG and JSON."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..atomic import atomic_outputs, ensure_output_dir
from ..backends import BACKENDS, get_backend
from ..scenario import load_scenario


def register(sub) -> None:
    p = sub.add_parser("run", help="simulate a scenario file",
                       description="Simulate a scenario and write NAME.csv, NAME.png and NAME.json into DIR.")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("-o", "--output", default="out", help="output directory (default: out)")
    p.add_argument("--backend", default="python", choices=sorted(BACKENDS),
                   help="python (solve_ivp, default) or an FMU importer")
    p.add_argument("--no-plot", action="store_true", help="skip the PNG")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario)
    ensure_output_dir(args.output)  # before the run, not after it
    result = get_backend(args.backend)(scenario)
    names = [f"{scenario.name}.csv", f"{scenario.name}.json"] + ([] if args.no_plot else [f"{scenario.name}.png"])
    with atomic_outputs(args.output, names) as tmp:
        result.to_csv(tmp[names[0]])
        summary = result.summary()
        summary["backend"] = args.backend
        tmp[names[1]].write_text(json.dumps(summary, indent=2) + "\n")
        if not args.no_plot:
            result.plot(tmp[names[2]])
    for warning in result.fit_range_violations:
        print(f"pamsim: warning: left the static model's valid (fitted) range: {warning}", file=sys.stderr)
    s = summary
    print(f"{scenario.name}: final contraction {s['final_contraction_m'] * 1e3:.2f} mm "
          f"(peak {s['peak_contraction_m'] * 1e3:.2f} mm), final pressure {s['final_pressure_gauge_Pa'] / 1e5:.3f} bar, "
          f"{'at rest' if s['at_rest_at_end'] else 'still moving'} ({s['final_mode']}), {s['events']} events, "
          f"{s['rhs_evaluations']} RHS evaluations, {s['wall_time_s'] * 1e3:.0f} ms")
    print(f"wrote {', '.join(str(Path(args.output) / n) for n in names)}")
    return 0
