"""``pamsim models``: the static force models of the library."""

from __future__ import annotations

import argparse
import json



def register(sub) -> None:
    """Add ``pamsim models`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("models", help="list the static force models",
                       description="Every static force model with its kind, source and required muscle parameters.")
    p.add_argument("--json", action="store_true",
                   help="print a JSON list of objects with keys name, kind, source, parameters")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim models``: print every static force model of the registry with its kind, source and required
    parameters (as JSON with ``--json``); exit code 0.
    """
    from ..static_models import REGISTRY

    rows = [{"name": s.name, "kind": s.kind, "source": s.source, "parameters": list(s.parameters),
             "optional": dict(s.optional), "variants": list(s.variants)} for s in REGISTRY.values()]
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    for r in rows:
        print(f"{r['name']:34s} {r['kind']:12s} needs {', '.join(r['parameters']) or '-'}")
        print(f"{'':34s} {r['source']}")
    return 0
