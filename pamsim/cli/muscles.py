"""``pamsim muscles``: the muscles shipped with pamsim."""

from __future__ import annotations

import argparse
import json


def register(sub) -> None:
    """Add ``pamsim muscles`` and its options to ``sub``, the subparsers of :func:`pamsim.cli.build_parser`."""
    p = sub.add_parser("muscles", help="list the shipped muscles",
                       description="Every shipped muscle with its citation, default static model and the "
                                   "models whose parameters it gives.")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``pamsim muscles``: print the shipped muscles, their default model and the models that apply (for a
    muscle none applies to: why, and the file's gaps); as JSON with ``--json``; exit code 0.
    """
    from ..muscles import load_muscle, shipped_names

    rows = []
    for name in shipped_names():
        m = load_muscle(name)
        rows.append({"name": m.name, "description": m.description, "citation": m.citation,
                     "default_static_force": m.default_static_force, "applicable_models": m.applicable_models(),
                     "no_model_reason": m.no_model_reason(), "gaps": list(m.gaps), "parameters": list(m.parameters)})
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    for r in rows:
        why = r["no_model_reason"]
        applies = why or f"{len(r['applicable_models'])} models apply"
        print(f"{r['name']:28s} default model {r['default_static_force']}; {applies}")
        print(f"{'':28s} {r['description']}")
        if why:  # the file's own account of what its sources leave out
            for gap in r["gaps"]:
                print(f"{'':28s} gap: {gap}")
    return 0
