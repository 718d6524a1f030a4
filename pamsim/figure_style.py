"""How pamsim's figures tell their lines apart, and how every figure is written.

Lines that share an axes differ in line style (past four lines, in marker too) as well as in colour,
so that a figure printed in grey still tells them apart: :func:`series` gives the k-th line's style,
and the plot modules draw every set of lines with it.  Every figure file is written by :func:`save`,
as PNG, PDF or SVG at a resolution in dots per inch; the command line's ``--format`` and ``--dpi``
and the Python API's ``path`` and ``dpi`` arguments are checked here, with one message each.
"""

from __future__ import annotations

import os
from pathlib import Path

from .errors import InputError

FORMATS = ("png", "pdf", "svg")
"""The file formats a figure can be written in (``--format``, or the suffix of a path)."""

DEFAULT_DPI = 110
"""Resolution of a figure unless the caller gives one [dots per inch] (atlas_all.png: 100)."""

MAX_DPI = 1200
"""Highest resolution accepted: a 9 x 9 inch figure is then a 10,800-pixel square (about 470 MB in memory)."""

LINE_STYLES = ("-", "--", "-.", ":")
MARKERS = (None, "o", "s", "^", "v", "D", "x", "+", "*", "P")
"""Line styles, and the markers that mark lines past the first four; :func:`series` combines them."""

MARK_EVERY = 0.1
"""Markers on a line sit a tenth of the axes' diagonal apart (on lines of any number of points)."""

REFERENCE = {"color": "0.5", "linestyle": (0, (1, 1)), "linewidth": 0.8}
"""A thin, densely dotted grey line for a quantity on a second y axis (a pressure behind contractions)."""


def series(k: int, colour: str | None = None, points: bool = False) -> dict:
    """Matplotlib keywords of the ``k``-th line of several on one axes: colour, line style and marker.

    Lines 0-3 are solid, dashed, dash-dotted and dotted without markers; from line 4 on, the four
    styles repeat with a marker (circle, square, ...), so the first 40 lines all differ in style
    and marker, and ten consecutive lines in colour as well.  ``colour`` replaces the cycle's
    colour for a line whose colour means something (a force, a friction model).  ``points`` marks
    every data point of a line through a few points, each line with its own marker.
    """
    style = {"color": colour or f"C{k % 10}", "linestyle": LINE_STYLES[k % len(LINE_STYLES)]}
    if points:
        return {**style, "marker": MARKERS[1 + k % (len(MARKERS) - 1)]}
    marker = MARKERS[(k // len(LINE_STYLES)) % len(MARKERS)]
    if marker is not None:
        # Staggered starts, so that the markers of neighbouring lines do not pile up at the same places.
        style.update(marker=marker, markevery=(MARK_EVERY / 5 * (k % 5), MARK_EVERY), markersize=4,
                     markerfacecolor="none")
    return style


def check_format(text: str, label: str = "--format") -> str:
    """``text`` as one of :data:`FORMATS`; anything else raises :class:`InputError` naming ``label`` and it."""
    fmt = str(text).lower()
    if fmt not in FORMATS:
        raise InputError(f"{label} {text}: not a figure format (choose {', '.join(FORMATS[:-1])} or {FORMATS[-1]})")
    return fmt


def check_dpi(value, label: str = "--dpi") -> int:
    """``value`` (a number or the text of one) as a whole number of dots per inch from 1 to :data:`MAX_DPI`."""
    text = str(value).strip()
    try:
        dpi = None if isinstance(value, bool) else int(text)  # 300 or "300"; not 300.5, "3e2" or True
    except ValueError:
        dpi = None
    if dpi is None or not 1 <= dpi <= MAX_DPI:
        raise InputError(f"{label} {text}: must be a whole number of dots per inch from 1 to {MAX_DPI}")
    return dpi


def format_of(path: str | os.PathLike) -> str:
    """The figure format a file name asks for by its suffix (``fig4.pdf`` -> ``"pdf"``)."""
    suffix = Path(path).suffix
    if not suffix:
        raise InputError(f"{path}: no suffix to tell the figure format by (end the name in "
                         f"{', '.join('.' + f for f in FORMATS[:-1])} or .{FORMATS[-1]})")
    return check_format(suffix[1:], label=f"{path}: suffix")


def save(fig, target, fmt: str | None = None, dpi: int | None = None, default_dpi: int = DEFAULT_DPI) -> None:
    """Write ``fig`` to ``target`` (a path, or a binary file object with ``fmt``) in ``fmt`` (default: the
    path's suffix) at ``dpi`` dots per inch (default ``default_dpi``).

    The caller makes the write atomic (:mod:`pamsim.atomic`).  PDF and SVG files carry no creation date.
    """
    fmt = check_format(fmt, label="format") if fmt is not None else format_of(target)
    dpi = default_dpi if dpi is None else check_dpi(dpi, label="dpi")
    metadata = {"CreationDate": None} if fmt == "pdf" else {"Date": None} if fmt == "svg" else None
    fig.savefig(target, format=fmt, dpi=dpi, metadata=metadata)
