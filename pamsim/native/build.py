"""Compiling the native engine's libraries (:mod:`pamsim.native.engine`): the compiler, its flags and
the cache folder.

A library is compiled with the system C compiler (``cc``, or ``CC``) on first use and kept in a
cache folder: ``$PAMSIM_NATIVE_CACHE`` if set, else ``pamsim-native/`` in the system temp folder,
under a hash of everything it is built from, so a change to any of it builds a new library and an
old one is never loaded by mistake.  Concurrent first uses (the workers of a sweep) each compile
into a private file and move it into place atomically.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
from pathlib import Path

from ..errors import InputError
from ..fmu.build import c_compiler
from ..fmu.generate import c_source_dir

FLAGS = ("-shared", "-fPIC", "-O3", "-std=c99", "-Wall", "-fvisibility=hidden")
CACHE_ENV = "PAMSIM_NATIVE_CACHE"


def compiler() -> str:
    """The C compiler: ``$CC``, else ``cc`` or ``gcc`` on the path."""
    return c_compiler("the native backend")


def cache_root() -> Path:
    """Where built libraries are kept (``$PAMSIM_NATIVE_CACHE`` or the temp folder's ``pamsim-native``)."""
    return Path(os.environ.get(CACHE_ENV) or Path(tempfile.gettempdir()) / "pamsim-native")


def compile_library(cc: str, main: str, work: Path, name: str, what: str) -> Path:
    """Compile ``main`` (a unity build, in the C source folder) with the generated headers in ``work``
    into ``work / name``; raises :class:`InputError` with the compiler's message if it fails."""
    src = c_source_dir() / "src"
    partial = work / name
    cmd = [cc, *FLAGS, "-I", str(work), "-I", str(src), str(src / main), "-o", str(partial), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise InputError(f"compiling {what} failed ({cc} ...): {proc.stderr.strip()}")
    return partial
