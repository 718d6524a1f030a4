"""``pamsim control-example SCENARIO -o DIR``: design the scenario's position controller and run it
on the hybrid model; write NAME.csv, NAME.json and NAME.png into DIR."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..atomic import atomic_outputs, ensure_output_dir


def register(sub) -> None:
    p = sub.add_parser("control-example", help="closed-loop position control on the hybrid model",
                       description="Design the LQR + integral position controller of a scenario's [controller] "
                                   "table on its linearisation and run it on the hybrid stick/slip model "
                                   "(docs/control.md).  Exit code 1 if the run misses its [controller.spec].")
    p.add_argument("scenario", help="scenario TOML file with a [controller] table")
    p.add_argument("-o", "--output", default="out", help="output directory (default: out)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..control.closed_loop import run_closed_loop
    from ..control.plots import closed_loop_figure

    ensure_output_dir(args.output)
    loop = run_closed_loop(args.scenario)
    name = loop.result.name
    names = [f"{name}.csv", f"{name}.json", f"{name}.png"]
    summary = loop.summary()
    with atomic_outputs(args.output, names) as tmp:
        loop.result.to_csv(tmp[names[0]])
        tmp[names[1]].write_text(json.dumps(summary, indent=2) + "\n")
        closed_loop_figure(loop).savefig(tmp[names[2]], format="png", dpi=110)
    m = summary["metrics"]
    print(f"{name}: rise time {m['rise_time_s'] * 1e3:.1f} ms, overshoot {m['overshoot_percent']:.2f} %, "
          f"settling time {m['settling_time_s'] * 1e3:.1f} ms, steady-state error {m['steady_state_error_mm']:.3f} mm")
    print("gains K (x [1/m], v [s/m], p [1/Pa], z [1/(m s)]): " + ", ".join(f"{k:.4g}" for k in summary["gains_K"]))
    print("meets its specification" if summary["meets_spec"] else "misses its specification: "
          + "; ".join(summary["failures"]))
    print(f"wrote {', '.join(str(Path(args.output) / n) for n in names)}")
    return 0 if summary["meets_spec"] else 1
