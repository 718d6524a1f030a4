"""The per-run table of an uncertainty study (``uncertainty_samples.csv``), written to disk as its runs finish.

The rows go to a hidden temporary file while the study runs, so that memory does not grow with the sample
count; :meth:`SampleTable.publish` gives the finished file its name.  The file is made in the output folder,
or, while that folder does not exist yet, in the folder it will be made in (a killed sweep then leaves no
output folder behind); either way on the same disk, so that publishing it is a rename, not a copy.

The rows are written in the order of the runs (friction model by friction model, sample by sample) whatever
order the executor finishes its chunks in: :class:`ChunkOrder` holds a chunk that finishes early, as its
formatted text, until the chunks before it are written.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import shutil
import tempfile
import weakref
from pathlib import Path
from typing import Any, Mapping, Sequence

from ..atomic import existing_folder
from .uncertainty import QUANTITIES

NAME = "uncertainty_samples.csv"

ROW_BYTES_PER_NUMBER = 16
"""Bytes a number takes in a row at most: 9 significant digits as ``-1.23456789e-10`` and its comma."""

ROW_BYTES_FIXED = 8
"""Bytes of a row besides its sample number, friction model and numbers: the rest flag, the empty failure
message and the line end."""


def row_bytes(samples: int, n_parameters: int, friction: str) -> int:
    """Most bytes a successful run's row can take (a failed run's message adds its length)."""
    return len(str(samples)) + len(friction) + 2 + ROW_BYTES_PER_NUMBER * (n_parameters + len(QUANTITIES)) \
        + ROW_BYTES_FIXED


class ChunkOrder:
    """Puts chunks of runs back in order: :meth:`add` takes a chunk (its first run's index, its run count and
    a payload) in any order and returns the payloads that can now follow the ones returned before.

    ``next`` is the index of the first run not yet returned: the chunks held back all start after it.
    """

    def __init__(self) -> None:
        self.next = 0
        self.held: dict[int, tuple[int, Any]] = {}

    def add(self, start: int, count: int, payload: Any) -> list:
        """Take the chunk of ``count`` runs from ``start`` on; return the payloads now in order."""
        self.held[start] = (count, payload)
        ready = []
        while self.next in self.held:
            count, payload = self.held.pop(self.next)
            ready.append(payload)
            self.next += count
        return ready


class SampleTable:
    """``uncertainty_samples.csv`` being written: a hidden temporary file beside ``folder`` (made in
    ``folder`` if it exists, else in its nearest existing parent), removed if the object is dropped before
    :meth:`publish` (or by :meth:`discard`).

    Parameters
    ----------
    folder : str or Path
        The output folder the table will be published in.
    names : sequence of str
        The sampled parameters' names, the table's columns after ``sample`` and ``friction_model``.
    """

    def __init__(self, folder: str | os.PathLike, names: Sequence[str]):
        fd, path = tempfile.mkstemp(prefix=f".pamsim-{NAME}.", suffix=".tmp", dir=existing_folder(folder))
        self.path = Path(path)
        self.file = os.fdopen(fd, "w", newline="")
        # The writer's dialect is csv's default, the one the table has always had (CRLF line ends).
        csv.writer(self.file).writerow(["sample", "friction_model", *names, *QUANTITIES, "at_rest", "failure"])
        self._finalizer = weakref.finalize(self, _remove, self.file, self.path)

    @staticmethod
    def rows_text(rows: Sequence[tuple[int, str, Sequence[float], Mapping]]) -> str:
        """The CSV text of ``rows``, each ``(sample number, friction model, parameter values, run output)``: the
        numbers to 9 significant digits, ``at_rest`` ``True``, ``False`` or ``nan`` (no result)."""
        buffer = io.StringIO()
        w = csv.writer(buffer)
        for k, friction, values, output in rows:
            at_rest = float(output.get("at_rest", math.nan))
            outputs = [float(output.get(q, math.nan)) for q in QUANTITIES]
            w.writerow([k, friction, *(f"{float(v):.9g}" for v in values), *(f"{v:.9g}" for v in outputs),
                        at_rest if math.isnan(at_rest) else bool(at_rest), output["error"]])
        return buffer.getvalue()

    def write(self, text: str) -> None:
        """Append rows (:meth:`rows_text`), handed to the system at once: the file shows the study's progress,
        and what Python buffers is one chunk's rows at most."""
        self.file.write(text)
        self.file.flush()

    def finish(self) -> None:
        """Close the file: every row is written."""
        self.file.close()

    def publish(self, path: str | os.PathLike) -> None:
        """Give the finished table the name ``path`` (a staged output): a second name of the same file where the
        disk allows it, else a copy; this object's file stays, to be published again or discarded."""
        try:
            os.link(self.path, path)
        except OSError:  # another disk, or one without hard links
            shutil.copyfile(self.path, path)

    def discard(self) -> None:
        """Remove the temporary file (after it was published, or when the study stops)."""
        self._finalizer()


def _remove(file, path: Path) -> None:
    file.close()
    with contextlib.suppress(FileNotFoundError):
        path.unlink()
