"""``pamsim params``: a muscle's parameters as the dynamics use them, with units and provenance."""

from __future__ import annotations

import argparse
import json
import math

from . import muscle_args


def register(sub) -> None:
    """Add ``pamsim params`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("params", help="list a muscle's parameters with units and provenance",
                       description="A muscle's parameters with the dynamics' assumed defaults for what its "
                                   "file does not give, each with unit, range and source.")
    muscle_args.add_arguments(p, model=False)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--markdown", action="store_true", help="print a Markdown table (as in docs/model.md)")
    p.add_argument("--defaults", action="store_true",
                   help="the dynamics' assumed defaults instead (a Markdown table, as in docs/model.md)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim params``: print a muscle's parameters with units and provenance (as JSON or markdown), or with
    ``--defaults`` the dynamics' assumed defaults; exit code 0.
    """
    if args.defaults:
        print(defaults_table())
        return 0
    _, ps = muscle_args.resolve_parameters(args)
    rows = ps.table()
    if args.json:
        print(json.dumps({"name": ps.name, "citation": ps.citation,
                          "parameters": [dict(zip(("name", "value", "unit", "source", "description"), r))
                                         for r in rows]}, indent=2))
        return 0
    if args.markdown:
        print(markdown_table(ps))
        return 0
    print(f"{ps.name}: {ps.citation}")
    for name, value, unit, source, _ in rows:
        print(f"  {name:26s} {value:>12.6g} {unit:12s} {source}")
    return 0


def markdown_table(ps) -> str:
    """The parameter table of ``docs/model.md``; a test keeps the two identical."""
    lines = ["| name | value | unit | range | source | meaning |", "| --- | --- | --- | --- | --- | --- |"]
    for name, p in ps.entries.items():
        lines.append(f"| `{name}` | {p.value:.6g} | {p.unit} | {_range(p)} | {p.source} | {p.description} |")
    return "\n".join(lines)


def defaults_table() -> str:
    """The dynamics defaults of ``docs/model.md``; a test keeps the two identical."""
    from ..parameter_schema import unit_of
    from ..parameters import DYNAMICS_DEFAULTS

    lines = ["| name | value | unit | source |", "| --- | --- | --- | --- |"]
    for name, (value, source) in DYNAMICS_DEFAULTS.items():
        lines.append(f"| `{name}` | {value:.6g} | {unit_of(name)} | {source} |")
    return "\n".join(lines)


def _range(p) -> str:
    if not (math.isfinite(p.lower) or math.isfinite(p.upper)):
        return "any"
    lo = ("(" if p.lower_open or not math.isfinite(p.lower) else "[") + (f"{p.lower:g}" if math.isfinite(p.lower) else "-inf")
    hi = (f"{p.upper:g}" if math.isfinite(p.upper) else "inf") + (")" if p.upper_open or not math.isfinite(p.upper) else "]")
    return f"{lo}, {hi}"
