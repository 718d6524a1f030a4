"""``pamsim joint-map SCENARIO -o DIR``: a two-muscle joint's equilibrium angle and stiffness over a grid of
its muscles' pressures; writes NAME_map.csv, NAME_map.json and the figure NAME_map.png."""

from __future__ import annotations

import argparse
import csv
import io
import json
from pathlib import Path

from ..atomic import atomic_outputs, output_folder
from ..constants import PA_PER_BAR
from ..errors import InputError
from . import figure_args, finite_float


def register(sub) -> None:
    """Add ``pamsim joint-map`` and its options to ``sub``."""
    p = sub.add_parser("joint-map", help="a joint's equilibrium angle and stiffness over two pressures",
                       description="Equilibrium angle and stiffness (-d tau / d theta, exact) of a joint scenario's "
                                   "two muscles at rest, over a grid of their gauge pressures; writes NAME_map.csv, "
                                   "NAME_map.json and the figure NAME_map.png.")
    p.add_argument("scenario", help="a joint scenario file ([joint] and two [[muscle]] tables)")
    p.add_argument("-o", "--output", default="out", help="output directory (default: out)")
    p.add_argument("--min-bar", type=finite_float, default=0.5, help="lowest gauge pressure [bar] (default 0.5)")
    p.add_argument("--max-bar", type=finite_float, default=4.0, help="highest gauge pressure [bar] (default 4)")
    p.add_argument("--points", type=int, default=15, help="pressures per muscle (default 15, at most 101)")
    figure_args.add_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim joint-map``: compute the map and write its files; exit code 0."""
    import numpy as np

    from ..figure_style import save
    from ..joints import load_joint_scenario
    from ..joints.plots import equilibrium_map_figure
    from ..joints.static import JointStatics, equilibrium_map

    fig_format, dpi = figure_args.options(args)
    if not 2 <= args.points <= 101:
        raise InputError(f"--points = {args.points}: must lie in [2, 101]")
    if not 0.0 <= args.min_bar < args.max_bar:
        raise InputError(f"--min-bar = {args.min_bar:g}, --max-bar = {args.max_bar:g}: need 0 <= min < max")
    scenario = load_joint_scenario(Path(args.scenario))
    if len(scenario.muscles) != 2:
        raise InputError(f"{scenario.origin}: a map over two pressures needs two muscles, not {len(scenario.muscles)}")
    for table, sc in scenario.muscles:
        rating = sc.parameters["rated_pressure_gauge_Pa"]
        if args.max_bar * PA_PER_BAR > rating:
            raise InputError(f"--max-bar = {args.max_bar:g}: above muscle {table['name']!r}'s rating, "
                             f"{rating / PA_PER_BAR:g} bar")
    grid = np.linspace(args.min_bar, args.max_bar, args.points) * PA_PER_BAR
    with output_folder(args.output) as out:
        emap = equilibrium_map(JointStatics(scenario), grid, grid)
        stem = f"{scenario.name}_map"
        names = [f"{stem}.csv", f"{stem}.json", f"{stem}.{fig_format}"]
        rows = emap.rows()
        text = io.StringIO()
        writer = csv.DictWriter(text, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
        k = emap.k_Nm_per_rad
        summary = {"scenario": scenario.name, "muscles": list(emap.names), "pressures_bar": (grid / PA_PER_BAR).tolist(),
                   "stiffness_Nm_per_rad": {"min": float(k.min()), "max": float(k.max())},
                   "points_on_a_limit": int(np.count_nonzero(emap.on_limit != ""))}
        with atomic_outputs(out, names) as tmp:
            tmp[names[0]].write_text(text.getvalue())
            tmp[names[1]].write_text(json.dumps(summary, indent=2) + "\n")
            save(equilibrium_map_figure(emap), tmp[names[2]], fmt=fig_format, dpi=dpi)
    diag = [float(k[i, i]) for i in range(len(grid))]
    print(f"{scenario.name}: {len(grid)} x {len(grid)} pressures, {args.min_bar:g}-{args.max_bar:g} bar; stiffness "
          f"{k.min():.4g}-{k.max():.4g} N m/rad; equal pressures: {diag[0]:.4g} N m/rad at {args.min_bar:g} bar, "
          f"{diag[-1]:.4g} at {args.max_bar:g} bar; {summary['points_on_a_limit']} points on a joint limit")
    print(f"wrote {', '.join(str(out / n) for n in names)}")
    return 0
