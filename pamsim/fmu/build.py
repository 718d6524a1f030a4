"""Compile the FMU with the system C compiler and pack it.

``build(output_path, fmi_version)`` writes the generated sources, the model
description and a shared library in the platform folder the standard names
(``binaries/linux64`` for FMI 2.0, ``binaries/x86_64-linux`` for FMI 3.0 on
Linux), so ``fmpy compile`` can rebuild the same archive elsewhere.
"""

from __future__ import annotations

import datetime
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path
from typing import Callable

from ..errors import InputError
from .generate import (MODEL_IDENTIFIER, WRAPPERS, generation_date, spec_model_description,
                       write_spec_documentation, write_spec_sources)
from .spec import FmuSpec

FMI_VERSIONS = (2, 3)


def platform_folder(fmi_version: int) -> str:
    """The binaries/ sub-folder of this machine for ``fmi_version``."""
    machine = platform.machine().lower()
    arch = {"amd64": "x86_64", "x86_64": "x86_64", "arm64": "aarch64", "aarch64": "aarch64"}.get(machine, machine)
    system = {"linux": "linux", "darwin": "darwin", "win32": "windows", "cygwin": "windows"}[sys.platform]
    if fmi_version == 2:
        bits = "64" if sys.maxsize > 2**32 else "32"
        return {"linux": f"linux{bits}", "darwin": f"darwin{bits}", "windows": f"win{bits}"}[system]
    return f"{arch}-{system}"


def shared_library_suffix() -> str:
    """The platform's shared library suffix: ``.so``, ``.dylib`` or ``.dll``."""
    return {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")


def _zip_time() -> tuple[int, int, int, int, int, int]:
    """The archive's file dates: the model description's generation date (from the sources, not the
    clock), or the zip format's earliest date where there is none."""
    stamp = generation_date()
    if stamp is None:
        return (1980, 1, 1, 0, 0, 0)
    d = datetime.datetime.strptime(stamp, "%Y-%m-%dT%H:%M:%SZ")
    return (max(d.year, 1980), d.month, d.day, d.hour, d.minute, d.second)


def default_output(fmi_version: int) -> Path:
    """Where ``pamsim fmu build`` writes the FMU when no path is given."""
    return Path(f"{MODEL_IDENTIFIER}_fmi{fmi_version}.fmu")



def c_compiler(purpose: str) -> str:
    """The C compiler ``purpose`` (a phrase: "the native backend") uses: ``$CC``, else ``cc`` or ``gcc`` on the path.

    Raises
    ------
    InputError
        Naming ``CC`` if it names no program, else saying that none was found.
    """
    cc = os.environ.get("CC")
    if cc:
        if not shutil.which(cc):
            raise InputError(f"CC = {cc!r}: no such program; CC names the C compiler {purpose} uses "
                             "(install one there, or unset CC to use cc or gcc from the path)")
        return cc
    found = shutil.which("cc") or shutil.which("gcc")
    if not found:
        raise InputError(f"{purpose} needs a C compiler (install gcc, or set CC)")
    return found

def build_spec(out: Path, spec: FmuSpec) -> Path:
    """Generate, compile and zip the FMU ``spec`` describes into ``out`` (a ``.fmu`` path); return ``out``.

    Raises :class:`~pamsim.errors.InputError` for a missing C compiler or a failed compilation.
    """
    out = Path(out)
    fmi_version = spec.fmi_version
    if out.suffix != ".fmu":
        raise InputError(f"{out}: the FMU file name must end in .fmu")
    compiler = c_compiler("pamsim fmu build")
    with tempfile.TemporaryDirectory(prefix="pamsim-fmu-") as tmp:
        root = Path(tmp)
        src = root / "sources"
        write_spec_sources(src, spec)
        (root / "modelDescription.xml").write_text(spec_model_description(spec))
        bin_dir = root / "binaries" / platform_folder(fmi_version)
        bin_dir.mkdir(parents=True)
        lib = bin_dir / (spec.identifier + shared_library_suffix())
        write_spec_documentation(root / "documentation", spec)
        # Only the FMI functions are exported; relative source paths keep the temporary folder's name
        # out of the binary, so that the same sources give the same archive.
        cmd = [compiler, "-shared", "-fPIC", "-O2", "-std=c99", "-Wall", "-fvisibility=hidden", "-I", ".",
               *spec.compiled(), WRAPPERS[fmi_version], "-o", str(lib), "-lm"]
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=src)
        if proc.returncode != 0:
            raise InputError(f"compiling the FMU failed ({' '.join(cmd[:2])} ...): {proc.stderr.strip()}")
        out.parent.mkdir(parents=True, exist_ok=True)
        partial = out.with_name(f".{out.name}.{os.getpid()}.tmp")  # concurrent builds of one cache entry
        stamp = _zip_time()
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as zf:
            for path in sorted(root.rglob("*")):
                if path.is_file():
                    info = zipfile.ZipInfo(path.relative_to(root).as_posix(), date_time=stamp)
                    info.external_attr = 0o644 << 16
                    info.compress_type = zipfile.ZIP_DEFLATED
                    zf.writestr(info, path.read_bytes())
        os.replace(partial, out)
    return out



TEMP_FMUS_KEPT = 64
"""FMUs the backends keep in the temporary folder (``pamsim-fmu``): a sweep on an FMU backend builds one per
scenario value set, so older entries are removed (:func:`temp_fmu`)."""
TEMP_FMU_IDLE_S = 600.0
"""An entry unused for less than this [s] is never removed: another process may be about to run it."""


def temp_fmu_root() -> Path:
    """The folder the FMU backends keep their FMUs in."""
    return Path(tempfile.gettempdir()) / "pamsim-fmu"


def temp_fmu(token: str, file_name: str, make: Callable[[Path], object]) -> Path:
    """The FMU kept under ``token`` in :func:`temp_fmu_root`, made by ``make(path)`` on first use.

    Each use marks the entry as used; beyond :data:`TEMP_FMUS_KEPT` entries, the least recently used
    ones idle for :data:`TEMP_FMU_IDLE_S` are removed, so the folder does not grow with every value set.
    """
    folder = temp_fmu_root() / token.strip("{}")
    path = folder / file_name
    if not path.is_file():
        make(path)
        _prune(temp_fmu_root(), keep=folder)
    os.utime(folder)
    return path


def _prune(root: Path, keep: Path) -> None:
    entries = []
    for entry in root.iterdir():
        try:
            entries.append((entry.stat().st_mtime, entry))
        except FileNotFoundError:  # removed meanwhile by another process
            continue
    now = time.time()
    for mtime, entry in sorted(entries, reverse=True)[TEMP_FMUS_KEPT:]:
        if entry != keep and entry.is_dir() and now - mtime > TEMP_FMU_IDLE_S:
            shutil.rmtree(entry, ignore_errors=True)
