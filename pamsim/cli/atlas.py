"""``pamsim atlas``: isobaric force-contraction curves of every applicable static model of a muscle."""

from __future__ import annotations

import argparse

from ..errors import InputError
from . import figure_args, muscle_args


def _list(text: str) -> list[str]:
    return [t.strip() for t in text.split(",") if t.strip()]


def register(sub) -> None:
    """Add ``pamsim atlas`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("atlas", help="force-contraction curves of every static model of a muscle",
                       description="Write atlas_curves.csv, atlas_table.csv/.md (blocked force and free "
                                   "contraction per model and pressure), one figure per pressure and "
                                   "atlas_all.png (or .pdf, .svg with --format) into DIR, with the muscle's "
                                   "measured points overlaid.")
    muscle_args.add_arguments(p, model=False)
    p.add_argument("--models", type=_list, default=None, metavar="M1,M2,...",
                   help="models to draw (default: every model whose parameters the muscle gives)")
    p.add_argument("--pressures-bar", type=_list, default=None, metavar="P1,P2,...",
                   help="gauge pressures [bar] (default: those of the measured points, else 25..100 %% of the rating)")
    p.add_argument("-o", "--output", required=True, help="output directory")
    figure_args.add_arguments(p, default_dpi="110; atlas_all: 100")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim atlas``: build the muscle's atlas, write its figures, curves and table into ``--output`` and print the
    table; exit code 0.
    """
    from ..atlas import build_atlas
    from ..atomic import ensure_output_dir

    fmt, dpi = figure_args.options(args)
    pressures = None
    if args.pressures_bar is not None:
        try:
            pressures = [float(p) for p in args.pressures_bar]
        except ValueError:
            raise InputError(f"--pressures-bar = {','.join(args.pressures_bar)!r}: not a list of numbers") from None
    atlas = build_atlas(args.muscle, args.models, pressures, muscle_args.overrides(args.overrides))
    ensure_output_dir(args.output)
    written = atlas.write(args.output, fmt, dpi)
    print(atlas.markdown_table())
    print(f"wrote {', '.join(str(p) for p in written)}")
    return 0
