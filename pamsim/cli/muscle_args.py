"""Options shared by the commands that query a muscle's static model:
``--muscle``, ``--model``, ``--variant`` and ``--set NAME=VALUE``."""

from __future__ import annotations

import argparse

from ..errors import InputError


def add_arguments(parser: argparse.ArgumentParser, model: bool = True) -> None:
    """Add ``--muscle`` and ``--set NAME=VALUE`` to ``parser``, and with ``model`` also ``--model`` (alias
    ``--static-force``) and ``--variant``.
    """
    parser.add_argument("--muscle", default="shadow_6x300_acra2012",
                        help="shipped muscle name (`pamsim muscles`) or a muscle TOML file (default: the Shadow muscle)")
    if model:
        parser.add_argument("--model", "--static-force", dest="model", default=None,
                            help="static force model (`pamsim models`; default: the muscle's own)")
        parser.add_argument("--variant", default=None, help="the model's variant (default: its first)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE",
                        help="override a muscle parameter, in the unit of its name (repeatable)")


def add_upper_stop_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--upper-stop CHOICE`` (where the upper stop stands; default: the muscle file's choice)."""
    from ..parameter_schema import UPPER_STOPS

    parser.add_argument("--upper-stop", choices=tuple(UPPER_STOPS), default=None,
                        help="where the upper stop stands: " + "; ".join(f"{k}: {v}" for k, v in UPPER_STOPS.items())
                        + " (default: the muscle file's choice)")


def end_stops(args: argparse.Namespace, muscle, params, model):
    """The stops of ``model`` on ``muscle`` with ``--upper-stop`` or the muscle's choice
    (:func:`pamsim.muscle_setup.end_stops`)."""
    from ..muscle_setup import end_stops as stops_of

    return stops_of(muscle, params, model, args.upper_stop, key="--upper-stop")


def _key(kind: str, name: str) -> str:
    return {"parameter": f"--set {name}", "model": "--model", "variant": "--variant"}[kind]


def overrides(pairs: list[str]) -> dict[str, float]:
    """``["NAME=VALUE", ...]`` -> ``{NAME: VALUE}``; a malformed pair raises InputError naming it."""
    out = {}
    for pair in pairs:
        name, sep, text = pair.partition("=")
        if not sep or not name.strip():
            raise InputError(f"--set {pair!r}: expected NAME=VALUE (for example --set E_bladder_Pa=1.2e6)")
        try:
            out[name.strip()] = float(text)
        except ValueError:
            raise InputError(f"--set {name.strip()} = {text!r}: not a number") from None
    return out


def resolve(args: argparse.Namespace):
    """``(muscle, parameters, built model)`` from the parsed options."""
    from ..muscle_setup import prepare

    return prepare(args.muscle, getattr(args, "model", None), overrides(args.overrides),
                   getattr(args, "variant", None), key=_key)


def resolve_parameters(args: argparse.Namespace):
    """``(muscle, parameters)`` from the parsed options (no static model)."""
    from ..muscle_setup import muscle_parameters

    return muscle_parameters(args.muscle, overrides(args.overrides), key=_key)
