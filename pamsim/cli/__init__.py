"""The ``pamsim`` command line: a thin layer over the Python API.

Each subcommand lives in its own module with a ``register(subparsers)``
function; user mistakes exit with code 2 and a one-line message, solver
failures with code 3.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import signal
import sys
import threading
import warnings

from ..errors import InputError, RunFailure, SolverFailure

COMMANDS = (
    "pamsim.cli.run",
    "pamsim.cli.static",
    "pamsim.cli.joint_map",
    "pamsim.cli.sweep",
    "pamsim.cli.fmu",
    "pamsim.cli.linearize",
    "pamsim.cli.params",
    "pamsim.cli.models",
    "pamsim.cli.muscles",
    "pamsim.cli.force",
    "pamsim.cli.atlas",
    "pamsim.cli.fit",
)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose mistakes are one line, as every other user mistake of ``pamsim`` is: the
    command, the argument and why, and where the help is (exit code 2); not the usage block first."""

    def error(self, message: str):
        if message.endswith("expected one argument"):  # left out, or it begins with '-' and reads as an option
            option = message.removeprefix("argument ").partition(":")[0].split("/")[-1]
            message += f" (a value that begins with '-' is written {option}=VALUE)"
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _command_parser(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.ArgumentParser:
    """The (sub)command's own parser that ``argv`` reaches (``pamsim fit hysteresis``'s for its arguments):
    the one whose help lists the options a mistake is about."""
    for token in argv:
        commands = next((a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction)), None)
        if commands is None:
            break
        parser = commands.get(token, parser)
    return parser


def build_parser() -> argparse.ArgumentParser:
    """The ``pamsim`` parser: ``--version`` and one subcommand per module of :data:`COMMANDS`, each added by
    its ``register`` (its subparsers are of the same one-line-error class).
    """
    parser = _Parser(prog="pamsim", description="McKibben muscle simulator")
    parser.add_argument("--version", action="version", version="pamsim " + __import__("pamsim").__version__)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``pamsim`` command with ``argv`` (default: the process's arguments) and return its exit code.

    0 on success (1 for a closed-loop run that misses its specification); a user mistake
    (:class:`~pamsim.errors.InputError`, or a file that cannot be read or written) prints one ``pamsim: error:``
    line and returns 2, a :class:`~pamsim.errors.SolverFailure` or :class:`~pamsim.errors.RunFailure` returns 3,
    an interrupt 130, SIGTERM (handled as an interrupt) 143.
    """
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # told by the command they were given to, whose --help lists its options
        _command_parser(parser, argv).error(f"unrecognized arguments: {' '.join(unknown)}")
    try:
        with _sigterm_as_interrupt(), warnings.catch_warnings():
            # scipy warns of an LSODA failure before pamsim reports it (its reason in the solver failure)
            warnings.filterwarnings("ignore", message="lsoda: ", category=UserWarning)
            return int(args.func(args) or 0)
    except InputError as exc:
        print(f"pamsim: error: {exc}", file=sys.stderr)
        return 2
    except (SolverFailure, RunFailure) as exc:
        what = "solver failure" if isinstance(exc, SolverFailure) else "error"
        print(f"pamsim: {what}: {exc}", file=sys.stderr)
        return 3
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):  # output piped into `head` and the like: not an error of ours
            sys.stderr = open(os.devnull, "w")
            return 0
        # A file or folder named on the command line that cannot be read or written.
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"pamsim: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (Terminated)
        print(f"pamsim: {getattr(exc, 'what', 'interrupted')}", file=sys.stderr)
        return getattr(exc, "exit_code", 130)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the command is, so that it unwinds as an interrupt (Ctrl-C) does: workers
    stopped, temporary files and folders that nothing was written to removed."""

    what = "terminated"
    exit_code = 128 + signal.SIGTERM


def _raise_terminated(signum, frame):
    raise Terminated


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """SIGTERM raises :class:`Terminated` inside the block (in the main thread only: Python runs signal
    handlers there); the handler before is put back after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def int_at_least(minimum: int):
    """argparse type: an integer of at least ``minimum``; the message quotes the value, and argparse names
    the option."""
    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if n < minimum:
            raise argparse.ArgumentTypeError(f"{text!r}: must be at least {minimum}")
        return n
    return parse


def finite_float(text: str) -> float:
    """argparse type: a finite number."""
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value
