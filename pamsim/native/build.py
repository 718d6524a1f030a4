"""Build the native library from the C core, once per version of the sources.

The library is compiled with the system C compiler (``cc``, or ``CC``) on
first use and kept in a cache folder: ``$PAMSIM_NATIVE_CACHE`` if set, else
``pamsim-native/`` in the system temp folder.  Its sub-folder is named by a
hash of the C sources, the generated variable header, the compiler and its
flags, so a change to any of them builds a new library and an old one is
never loaded by mistake.  Concurrent first uses (the workers of a sweep)
each compile into a private file and move it into place atomically.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import tempfile
from pathlib import Path

from ..errors import InputError
from ..fmu.build import c_compiler, shared_library_suffix
from ..fmu.force_table import EMPTY_HEADER
from ..fmu.generate import CORE_HEADER, c_source_dir, hand_written_spec, spec_c_header

SOURCES = ("pam_native.c", "pam_native.h", "pam_core.c", "pam_core.h", "pam_dopri.h", "pam_gauss.h", "pam_shared.h",
           "pam_log.h", "pam_fmu_common.c", "pam_fmu_common.h")
"""The C files the library is built from (pam_native.c includes pam_core.c and pam_fmu_common.c: one
translation unit)."""
FLAGS = ("-shared", "-fPIC", "-O3", "-std=c99", "-Wall", "-fvisibility=hidden")
LIBRARY_NAME = "libpamsim_native"
CACHE_ENV = "PAMSIM_NATIVE_CACHE"


def compiler() -> str:
    """The C compiler: ``$CC``, else ``cc`` or ``gcc`` on the path."""
    return c_compiler("the native backend")


def cache_root() -> Path:
    """Where built libraries are kept (``$PAMSIM_NATIVE_CACHE`` or the temp folder's ``pamsim-native``)."""
    return Path(os.environ.get(CACHE_ENV) or Path(tempfile.gettempdir()) / "pamsim-native")


def library_token(cc: str) -> str:
    """Hash of everything that goes into the library: sources, generated header, compiler, flags."""
    h = hashlib.sha256()
    src = c_source_dir() / "src"
    for name in SOURCES:
        h.update(name.encode() + b"\0" + (src / name).read_bytes())
    h.update(_core_header().encode())
    h.update(EMPTY_HEADER.encode())
    h.update("\0".join((cc, *FLAGS)).encode())
    return h.hexdigest()[:24]


def library_path() -> Path:
    """The path of the library built from the current sources, compiling it if it is not cached.

    Raises
    ------
    InputError
        Without a C compiler, or if the compilation fails (with the compiler's message).
    """
    cc = compiler()
    folder = cache_root() / library_token(cc)
    path = folder / (LIBRARY_NAME + shared_library_suffix())
    if path.is_file():
        return path
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="build-", dir=folder) as tmp:
        work = Path(tmp)
        (work / "pam_variables.h").write_text(_core_header())
        # No force table: the library runs the polynomial; other static forces are refused before a run.
        (work / "pam_force_table.h").write_text(EMPTY_HEADER)
        (work / "pam_fmu_core.h").write_text(CORE_HEADER)
        os.replace(compile_library(cc, "pam_native.c", work, path.name, "the native library"), path)
    return path


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


def _core_header() -> str:
    """``pam_variables.h`` of the core written by hand, which the library's force-table path runs."""
    return spec_c_header(hand_written_spec(2))
