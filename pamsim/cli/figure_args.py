"""``--format`` and ``--dpi``, the options of every command that writes figures.

argparse keeps them as text; :func:`options` checks them before the command does any work, so a bad
value is one ``pamsim: error:`` line naming the flag and the value (exit 2), and nothing is written.
"""

from __future__ import annotations

import argparse

from ..figure_style import DEFAULT_DPI, FORMATS, MAX_DPI, check_dpi, check_format


def add_arguments(parser: argparse.ArgumentParser, default_dpi: str = str(DEFAULT_DPI)) -> None:
    """Add ``--format`` and ``--dpi`` to ``parser`` (``default_dpi``: the default its help names); :func:`options`
    checks the values.
    """
    parser.add_argument("--format", dest="figure_format", default="png", metavar="{" + ",".join(FORMATS) + "}",
                        help="file format of the figures (default png; pdf and svg are vector graphics for papers)")
    parser.add_argument("--dpi", default=None, metavar="N",
                        help=f"resolution of the figures in dots per inch, 1 to {MAX_DPI} (default {default_dpi}; "
                             "in a PDF or SVG it applies only to embedded images)")


def options(args: argparse.Namespace) -> tuple[str, int | None]:
    """``(format, dpi)`` of the parsed options; ``dpi`` is None where the figures keep their own default."""
    return check_format(args.figure_format), None if args.dpi is None else check_dpi(args.dpi)
