"""Atomic file output: write to a temporary file beside the target, then rename.

A run that fails part-way leaves neither a partial file nor a stale temporary.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path; on success it is renamed to ``path``, on error removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_outputs(directory: str | os.PathLike, names: list[str]):
    """Yield ``{name: temporary path}`` for a set of files that appear together or not at all.

    The files are written into a hidden staging folder inside ``directory``
    and moved into place only when the block succeeds.
    """
    import shutil

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=".pamsim-", dir=directory))
    try:
        yield {name: stage / name for name in names}
        for name in names:
            os.replace(stage / name, directory / name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
