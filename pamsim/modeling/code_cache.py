"""Generated code kept on disk, so that a new process runs a model without generating it again.

A process that finds its model's code here needs neither CasADi nor the time to generate (a few
tenths of a second for the one-muscle model).  The folder is ``$PAMSIM_CODE_CACHE`` if set, else
``pamsim-code`` in the system's temporary folder.  An entry's name hashes what the code depends on:
the model's structure (:meth:`pamsim.modeling.Assembly.structure_key`), the source of every pamsim
module (a change of the physics or of the printer makes new entries) and the CasADi version.  A key
that holds anything whose value another process cannot reproduce (an object known by identity, a
function's code) keeps its model out of the cache.  A file that cannot be read is generated again.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from functools import lru_cache
from pathlib import Path

CACHE_ENV = "PAMSIM_CODE_CACHE"
_PLAIN = (type(None), bool, int, float, str)


def cache_root() -> Path:
    """Where generated code is kept (``$PAMSIM_CODE_CACHE`` or the temp folder's ``pamsim-code``)."""
    return Path(os.environ.get(CACHE_ENV) or Path(tempfile.gettempdir()) / "pamsim-code")


def _plain(value) -> bool:
    if isinstance(value, tuple):
        return all(_plain(v) for v in value)
    return isinstance(value, _PLAIN)


@lru_cache(maxsize=1)
def source_fingerprint() -> str:
    """A hash of every pamsim module's source and of the CasADi version."""
    from importlib import metadata

    package = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        h.update(str(path.relative_to(package)).encode())
        h.update(path.read_bytes())
    try:
        h.update(metadata.version("casadi").encode())
    except metadata.PackageNotFoundError:
        h.update(b"no casadi")
    return h.hexdigest()


def entry_name(key) -> str | None:
    """The file name for ``key``, or None if the key is not the same in another process."""
    if not _plain(key):
        return None
    return hashlib.sha256(repr((key, source_fingerprint())).encode()).hexdigest()[:32] + ".json"


def load(key):
    """The entry stored under ``key``, or None."""
    name = entry_name(key)
    if name is None:
        return None
    try:
        return json.loads((cache_root() / name).read_text())
    except (OSError, ValueError):
        return None


def store(key, payload) -> None:
    """Keep ``payload`` (JSON) under ``key``; written whole or not at all, quietly skipped if the
    folder cannot be written."""
    name = entry_name(key)
    if name is None:
        return
    root = cache_root()
    try:
        root.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".part-", dir=root)
        with os.fdopen(fd, "w") as fh:
            json.dump(payload, fh)
        os.replace(tmp, root / name)
    except OSError:
        pass
