"""Atomic file output: write to temporary files beside the targets, then rename.

A run that fails part-way leaves neither a partial file nor a stale temporary.
A folder that cannot be written to is a user mistake (:class:`OutputError`),
found before any work is done when the caller checks it first with
:func:`ensure_output_dir`.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path

from .errors import InputError

_UMASK = os.umask(0)
os.umask(_UMASK)


class OutputError(InputError):
    """An output folder or file that cannot be written."""


def ensure_output_dir(directory: str | os.PathLike) -> Path:
    """Create ``directory`` if needed and check that files can be created in it."""
    directory = Path(directory)
    with _output_error(directory):
        directory.mkdir(parents=True, exist_ok=True)
        _probe(directory)
    return directory


def check_output_dir(directory: str | os.PathLike) -> Path:
    """Check that files can be written into ``directory`` without creating it: the folder itself if it
    exists, else its nearest existing parent (where it would be made) is probed."""
    directory = Path(directory)
    existing = existing_folder(directory)
    with _output_error(directory):
        if not existing.is_dir():
            raise NotADirectoryError(20, "Not a directory")
        _probe(existing)
    return directory


def existing_folder(directory: str | os.PathLike) -> Path:
    """``directory`` if it exists, else its nearest existing parent: where it would be made."""
    directory = Path(directory)
    return next(p for p in (directory, *directory.parents) if p.exists() or p.is_symlink())


def _probe(folder: Path) -> None:
    """Create and remove a file in ``folder`` (an OSError if it cannot be written)."""
    fd, probe = tempfile.mkstemp(prefix=".pamsim-probe-", dir=folder)
    os.close(fd)
    os.unlink(probe)


@contextlib.contextmanager
def _output_error(directory: Path):
    """An OSError inside the block becomes the :class:`OutputError` naming ``directory``."""
    try:
        yield
    except OSError as exc:
        raise OutputError(f"{directory}: cannot write output there: {exc.strerror or exc}") from None


@contextlib.contextmanager
def output_folder(directory: str | os.PathLike):
    """:func:`check_output_dir` for a block of work that may fail: yields the folder, not yet made.

    The folder is made by the first write into it (:func:`atomic_outputs`), so a process killed before it
    writes (SIGKILL, which no handler sees) leaves no empty folder behind.  If the block raises (an input
    error found late, a solver failure, a write error, an interrupt), the folders this call would have
    made are removed again when they are still empty, so a failed command leaves no trace.
    """
    directory = Path(directory)
    created = [p for p in (directory, *directory.parents) if not p.exists() and not p.is_symlink()]  # deepest first
    try:
        yield check_output_dir(directory)
    except BaseException:
        for folder in created:
            try:
                folder.rmdir()
            except OSError:  # not empty (something else wrote there), already gone, or never made
                if folder.exists():
                    break
        raise


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path; on success it is renamed to ``path``, on error removed."""
    path = Path(path)
    ensure_output_dir(path.parent)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes it private; the result is an ordinary file
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_outputs(directory: str | os.PathLike, names: list[str]):
    """Yield ``{name: temporary path}`` for a set of files that appear together or not at all.

    The files are written into a hidden staging folder inside ``directory``
    and moved into place only when the block succeeds; if a move fails, the
    files already moved are removed again.
    """
    directory = ensure_output_dir(directory)
    stage = Path(tempfile.mkdtemp(prefix=".pamsim-", dir=directory))
    try:
        yield {name: stage / name for name in names}
        moved = []
        try:
            for name in names:
                os.replace(stage / name, directory / name)
                moved.append(directory / name)
        except OSError as exc:
            for path in moved:
                with contextlib.suppress(OSError):
                    path.unlink()
            raise OutputError(f"{directory / name}: cannot write it: {exc.strerror or exc}") from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)
