"""The generic engine (``fmu/src/pam_engine.c``) compiled with an assembly's generated C, and run.

One library per assembly structure (:meth:`pamsim.modeling.Assembly.structure_key`): parameter
values are arguments, so every run of a sweep over parameters shares it.  A library is generated
(:class:`pamsim.modeling.cmodel.CModel`) and compiled on first use and kept in the native cache
folder (:func:`pamsim.native.build.cache_root`) under a hash of the structure, of pamsim's sources,
of the engine's C sources and of the compiler and its flags; within a process it is loaded once.

A library runs whole cases in one call (:meth:`EngineLibrary.run`), or one case step by step
(:class:`EngineSession`, ``fmu/src/pam_engine_session.c``): a controller or an environment sets the
inputs, advances to a time and reads the states and outputs.
"""

from __future__ import annotations

import ctypes
import hashlib
import itertools
import math
import os
import sys
import tempfile
import threading
import weakref
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import InputError, SolverFailure
from ..fmu.build import shared_library_suffix
from ..fmu.generate import c_source_dir
from ..modeling import code_cache
from .build import FLAGS, cache_root, compile_library, compiler

ENGINE_SOURCES = ("pam_engine_batch.c", "pam_engine_session.c", "pam_engine.c", "pam_engine.h", "pam_dopri.h",
                  "pam_rosenbrock.h", "pam_gauss.h")
LAYOUT = ("nx", "nq", "nu", "np", "ny", "nz", "nmodes", "ns", "event_columns", "message_bytes", "batch_bytes")
"""What ``pam_engine_layout(k)`` returns, by k."""
STATUS = ("ok", "bad input", "solver failed", "event buffer full")
MESSAGE_BYTES = 256

_P = ctypes.c_void_p


class EngineBatch(ctypes.Structure):
    """Mirror of ``PamEngineBatch`` in ``pam_engine_batch.c``.

    Every array is a plain address (``c_void_p``), the same size as the C pointers: an integer costs
    far less than a typed pointer from ``ndarray.ctypes.data_as``, and even a run of one case passes 21.
    """

    _fields_ = [("n_cases", ctypes.c_int64), ("params", _P), ("rtol", _P), ("max_step_s", _P), ("max_steps", _P),
                ("stiff_switch", _P),
                ("duration_s", _P), ("n_samples", _P), ("sample_offset", _P), ("n_segments", _P),
                ("segment_offset", _P), ("segment_t_s", _P), ("segment_u", _P), ("segment_du", _P),
                ("event_capacity", _P),
                ("event_offset", _P), ("samples", _P), ("modes", _P), ("events", _P), ("n_events", _P),
                ("stats", _P), ("status", _P), ("extremes", _P), ("messages", _P)]


BATCH_OUTPUTS = ("samples", "modes", "events", "n_events", "stats", "status", "extremes")
"""The fields of :class:`EngineBatch` the library fills."""
BATCH_FIELDS = tuple(name for name, _ in EngineBatch._fields_[1:-1])
"""The arrays of :class:`EngineBatch`, in its order (``segment_du`` None if every input is held)."""


@dataclass(frozen=True)
class EngineCase:
    """One run of an assembly: its parameter vector, solver settings, sample grid and input segments
    (``segment_u``: one row per segment, the flat model's inputs in its order at the segment's start;
    ``segment_du``: per segment and input the slope b, lag amplitude c and lag time constant tau (0: no
    lag) of ``u + b (t - t0) + c (exp(-(t - t0) / tau) - 1)`` from the segment's start t0, or None for
    inputs held over each segment)."""

    params: np.ndarray
    rtol: float
    max_step_s: float
    max_steps: int
    duration_s: float
    n_samples: int
    segment_t_s: np.ndarray
    segment_u: np.ndarray
    event_capacity: int
    segment_du: np.ndarray | None = None
    stiff_switch: bool = True


class EngineLibrary:
    """A compiled engine for one assembly structure: its names, layout and batch runner."""

    def __init__(self, path: Path, names: dict):
        self.path = path
        self.names = names
        lib = ctypes.CDLL(str(path))
        lib.pam_engine_layout.restype = ctypes.c_int64
        lib.pam_engine_layout.argtypes = [ctypes.c_int64]
        self.layout = {key: int(lib.pam_engine_layout(k)) for k, key in enumerate(LAYOUT)}
        expected = {"ns": len(names["states"]), "nu": len(names["inputs"]), "np": len(names["parameters"]),
                    "ny": len(names["outputs"]), "message_bytes": MESSAGE_BYTES,
                    "batch_bytes": ctypes.sizeof(EngineBatch)}
        wrong = {k: (self.layout[k], v) for k, v in expected.items() if self.layout[k] != v}
        if wrong:  # a programming error: the two sides were edited apart
            raise RuntimeError(f"engine library {path.name}: layout differs from pamsim.native.engine's: {wrong}")
        lib.pam_engine_run_batch.restype = ctypes.c_int64
        lib.pam_engine_run_batch.argtypes = [ctypes.POINTER(EngineBatch)]
        # Sessions: pointers as plain addresses (c_void_p), the cheapest conversion per call.
        signatures = {"new": (_P, []), "free": (None, [_P]),
                      "reset": (ctypes.c_int32, [_P, _P, _P, ctypes.c_double, ctypes.c_double, ctypes.c_int64,
                                                 ctypes.c_int32]),
                      "advance": (ctypes.c_int32, [_P, _P, ctypes.c_double]),
                      "read": (ctypes.c_int32, [_P, _P, _P, _P]),
                      "step": (ctypes.c_int32, [_P, _P, ctypes.c_double, _P, _P]),
                      "extremes": (None, [_P, _P]), "message": (ctypes.c_char_p, [_P])}
        for name, (restype, argtypes) in signatures.items():
            fn = getattr(lib, f"pam_engine_session_{name}")
            fn.restype, fn.argtypes = restype, argtypes
        self._lib = lib
        self._spare = threading.local()  # per thread: a run's buffer, kept for the next (see _buffer)

    def _buffer(self, nbytes: int) -> np.ndarray:
        """An uninitialised byte buffer of at least ``nbytes`` for a run's arrays: the last run's if nothing
        refers to it any more (its arrays and every view of them refer to the buffer itself, numpy
        collapsing a view's base onto the array that owns the memory), else a new one.  Reused, its pages
        are mapped already: a fresh buffer of a batch's size costs the kernel a page fault and a page
        cleared per 4 KiB (or 2 MiB) on first touch, a tenth of a 66-case batch's time."""
        spare = getattr(self._spare, "buffer", None)
        # references: the thread-local slot, `spare`, getrefcount's argument
        if spare is not None and spare.nbytes >= nbytes and sys.getrefcount(spare) <= 3:
            return spare
        del spare
        buffer = np.empty(max(nbytes, 8), dtype=np.uint8)
        self._spare.buffer = buffer if nbytes <= SPARE_BYTES else None
        return buffer

    def session(self) -> "EngineSession":
        """A new :class:`EngineSession` of this library (one run, advanced step by step)."""
        return EngineSession(self)

    def run(self, cases: Sequence[EngineCase]) -> dict:
        """Run ``cases`` in one call.  Returns per case, concatenated: ``samples`` (a block of every state
        x its samples), ``modes``, ``events`` (rows of t, mode before, mode after, fired mask, outputs
        before, outputs after), ``n_events``, ``stats`` (RHS evaluations, steps, segments + events, Jacobians),
        ``status``, ``extremes`` (each output's largest then smallest value over every step end and
        event), ``messages``, the offsets of each case's samples and events, and the uninitialised
        :data:`SAMPLE_ROOM`."""
        arrays, address = batch_arrays(cases, self.layout, self._buffer)
        messages = ctypes.create_string_buffer(MESSAGE_BYTES * len(cases))
        batch = EngineBatch(len(cases), *(address.get(k) for k in BATCH_FIELDS), ctypes.addressof(messages))
        self._lib.pam_engine_run_batch(ctypes.byref(batch))
        out = {k: arrays[k] for k in ("sample_offset", "event_offset", *BATCH_OUTPUTS, *SAMPLE_ROOM)}
        out["messages"] = _messages(messages.raw, len(cases))
        return out


SPARE_BYTES = 256 * 2**20
"""Largest run buffer an engine library keeps for the next run, per thread."""
_F64, _I64, _I32 = np.dtype(np.float64), np.dtype(np.int64), np.dtype(np.int32)
SAMPLE_ROOM = {"modes_int64": _I64, "column_f64": _F64}
"""Room the library leaves alone, one value per sample like ``modes``, for what its caller makes of each case's
samples (the modes as numpy's default integers, a column computed from the states): written there, in the run's
buffer, which is reused while it is free, they are not new arrays whose first touch costs the kernel a page
fault per 4 KiB, as a batch's results would be (they are kept, so the heap grows)."""
_SETTINGS = ("rtol", "max_step_s", "duration_s")
"""The per-case float settings, rows of one block."""
_COUNTS = ("max_steps", "stiff_switch", "n_samples", "sample_offset", "n_segments", "segment_offset", "event_capacity",
           "event_offset")
"""The per-case integers, rows of one block."""


def batch_arrays(cases: Sequence[EngineCase], layout: dict, allocate=None) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """The arrays of an :class:`EngineBatch` of ``cases`` (for a library of ``layout``), the inputs
    filled and the outputs as the library expects them (counts and statistics zero, extremes NaN),
    and their addresses.  They share one buffer, the per-case settings and integers one block each:
    its address plus offsets costs far less than an address per array (``ndarray.ctypes``), and a block
    is filled in one assignment, for the 20 arrays of even a single case.  ``allocate(nbytes)`` gives
    the buffer (default: a new one)."""
    n, nu = len(cases), layout["nu"]
    counts = {"n_samples": [k.n_samples for k in cases], "n_segments": [len(k.segment_t_s) for k in cases],
              "event_capacity": [k.event_capacity for k in cases]}
    samples, segments, events = (sum(v) for v in counts.values())
    exact = any(k.segment_du is not None for k in cases)
    blocks = {"settings": (_F64, (len(_SETTINGS), n)), "counts": (_I64, (len(_COUNTS), n)),
              "params": (_F64, (n, layout["np"])), "segment_t_s": (_F64, (segments,)),
              "segment_u": (_F64, (segments, nu)), **({"segment_du": (_F64, (segments, nu, 3))} if exact else {}),
              "samples": (_F64, (samples * layout["ns"],)), "modes": (_I32, (samples,)),
              "events": (_F64, (max(events, 1), layout["event_columns"])), "tallies": (_I64, (5 * n,)),
              "status": (_I32, (n,)), "extremes": (_F64, (n, 2 * layout["ny"])),
              **{name: (dtype, (samples,)) for name, dtype in SAMPLE_ROOM.items()}}
    arrays, address = _arena(blocks, allocate)
    _fill_inputs(arrays, cases, counts, nu)
    arrays["tallies"].fill(0)
    arrays["status"].fill(0)
    arrays["extremes"].fill(np.nan)
    # the rows of the blocks, by field: n_events then the n x 4 stats share the tallies
    for block, rows, size in (("settings", _SETTINGS, 8 * n), ("counts", _COUNTS, 8 * n),
                              ("tallies", ("n_events", "stats"), 8 * n)):
        address.update({name: address[block] + k * size for k, name in enumerate(rows)})
    arrays.update(sample_offset=arrays["counts"][_COUNTS.index("sample_offset")],
                  event_offset=arrays["counts"][_COUNTS.index("event_offset")],
                  n_events=arrays["tallies"][:n], stats=arrays["tallies"][n:].reshape(n, 4))
    return arrays, address


def _fill_inputs(arrays: dict[str, np.ndarray], cases: Sequence[EngineCase], counts: dict[str, list], nu: int) -> None:
    """The cases' settings, counts and offsets, and their segments one after another."""
    arrays["params"][:] = [k.params for k in cases]
    arrays["settings"][:] = [[getattr(k, name) for k in cases] for name in _SETTINGS]
    offsets = {name: [0, *itertools.accumulate(values[:-1])] for name, values in counts.items()}
    arrays["counts"][:] = [[k.max_steps for k in cases], [int(k.stiff_switch) for k in cases], counts["n_samples"],
                           offsets["n_samples"], counts["n_segments"], offsets["n_segments"], counts["event_capacity"],
                           offsets["event_capacity"]]
    start = 0
    for k in cases:
        end = start + len(k.segment_t_s)
        arrays["segment_t_s"][start:end] = k.segment_t_s
        arrays["segment_u"][start:end] = np.reshape(k.segment_u, (-1, nu))
        if "segment_du" in arrays:  # a case with held inputs among exact ones: no change over its segments
            arrays["segment_du"][start:end] = 0.0 if k.segment_du is None else np.reshape(k.segment_du, (-1, nu, 3))
        start = end


def _arena(shapes: dict[str, tuple[np.dtype, tuple[int, ...]]], allocate=None) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """Uninitialised arrays of the given dtypes and shapes in one buffer (``allocate(nbytes)``, default a
    new one), each at a multiple of 8 bytes, and their addresses."""
    offsets, total = {}, 0
    for name, (dtype, shape) in shapes.items():
        offsets[name] = total
        total += -(-math.prod(shape) * dtype.itemsize // 8) * 8
    buffer = allocate(total) if allocate is not None else np.empty(max(total, 8), dtype=np.uint8)
    base = buffer.ctypes.data
    arrays = {name: np.frombuffer(buffer, dtype, math.prod(shape), offsets[name]).reshape(shape)
              for name, (dtype, shape) in shapes.items()}
    return arrays, {name: base + offset for name, offset in offsets.items()}


def _messages(raw: bytes, n: int) -> list[str]:
    """Each case's message, from the library's ``n`` fixed-size, NUL-terminated slots."""
    return [raw[MESSAGE_BYTES * i:MESSAGE_BYTES * (i + 1)].split(b"\0", 1)[0].decode(errors="replace")
            for i in range(n)]


class EngineSession:
    """One run of an engine library advanced by its caller, with the inputs held over each advance.

    A session is what one case of :meth:`EngineLibrary.run` does, cut where its caller chooses: after
    :meth:`reset`, each :meth:`advance` (or :meth:`step`) holds its inputs from the session's time to
    its end time, as a batch case holds one input segment.  Advanced from ``t_k`` to ``t_(k+1)`` with the
    inputs ``u_k``, a session takes the same integrator steps, events and modes as a batch case whose
    segments start at every ``t_k`` with those inputs, and ends at the same states to the last bit.
    The run starts at the first advance, from the state and mode its inputs decide (a batch case starts
    from its first segment's inputs); until then :attr:`states` and :attr:`outputs` are the start the
    reset's inputs decide.

    Parameters
    ----------
    library : EngineLibrary
        The compiled engine of the model's assembly.

    Notes
    -----
    The arrays :attr:`states` and :attr:`outputs` are the session's own buffers, overwritten by every
    :meth:`step` and :meth:`read`; copy what must outlive the next call.  A session is not thread-safe
    and cannot be pickled: a worker process makes its own.
    """

    def __init__(self, library: EngineLibrary):
        self.library = library
        self._lib = lib = library._lib
        handle = lib.pam_engine_session_new()
        if not handle:
            raise MemoryError("pam_engine_session_new: out of memory")
        self._handle = handle
        self._free = weakref.finalize(self, lib.pam_engine_session_free, handle)
        L = library.layout
        self.states = np.zeros(L["ns"])
        """Every state, in the flat model's order (``library.names["states"]``)."""
        self.outputs = np.zeros(L["ny"])
        """Every output, in the flat model's order (``library.names["outputs"]``), in the current mode."""
        self._u = np.zeros(L["nu"])
        self._info = np.zeros(5)
        self._x_at, self._y_at = self.states.ctypes.data, self.outputs.ctypes.data
        self._u_at, self._info_at = self._u.ctypes.data, self._info.ctypes.data
        self._step = lib.pam_engine_session_step

    def _check(self, status: int, what: str) -> None:
        if status == 0:
            return
        message = self._lib.pam_engine_session_message(self._handle).decode(errors="replace")
        if status == 1:
            raise InputError(f"{what}: {message}")
        raise SolverFailure(f"native backend: {message}")

    def reset(self, params: Sequence[float], inputs: Sequence[float], rtol: float, max_step_s: float,
              max_steps: int, stiff_switch: bool = True) -> None:
        """Start a new run at t = 0.

        Parameters
        ----------
        params : sequence of float
            The flat model's parameter vector (``library.names["parameters"]``).
        inputs : sequence of float
            The inputs (``library.names["inputs"]``) that decide the start shown until the first advance.
        rtol : float
            Relative tolerance; the absolute ones are ``rtol`` times each state's nominal value.
        max_step_s : float
            The longest step while the model moves [s].
        max_steps : int
            The most internal steps of one advance.
        stiff_switch : bool
            Whether a held model whose Dormand-Prince steps are bound by stability steps with Rodas4 (the
            native backend's ``LSODA``, the automatic choice) or not (``RK45``, ``DOPRI5``).

        Raises
        ------
        InputError
            A parameter or input that is not a finite number, or a non-positive setting (naming it).
        """
        p = np.ascontiguousarray(params, dtype=np.float64)
        u = np.ascontiguousarray(inputs, dtype=np.float64)
        L = self.library.layout
        if p.shape != (L["np"],) or u.shape != (L["nu"],):
            raise ValueError(f"expected {L['np']} parameters and {L['nu']} inputs, got {p.shape} and {u.shape}")
        status = self._lib.pam_engine_session_reset(self._handle, p.ctypes.data, u.ctypes.data, float(rtol),
                                                    float(max_step_s), int(max_steps), int(bool(stiff_switch)))
        self._check(status, "engine session reset")
        self.read()

    def advance(self, inputs: Sequence[float], t_end_s: float) -> None:
        """Hold ``inputs`` from the session's time to ``t_end_s`` [s] and integrate there.

        Raises
        ------
        InputError
            An input that is not a finite number, or ``t_end_s`` not after the session's time: nothing
            changes.
        SolverFailure
            The integrator failed; the session must be reset before it advances again.
        """
        self._u[:] = inputs
        self._check(self._lib.pam_engine_session_advance(self._handle, self._u_at, float(t_end_s)), "engine session")
        self.read()

    def step(self, inputs: np.ndarray, t_end_s: float) -> None:
        """:meth:`advance` and then :meth:`read` in one library call, the cheapest way to step.

        ``inputs`` must be a C-contiguous float64 array of the model's inputs; the result is in
        :attr:`states` and :attr:`outputs`.
        """
        status = self._step(self._handle, inputs.ctypes.data, t_end_s, self._x_at, self._y_at)
        if status:
            self._check(status, "engine session")

    def read(self) -> int:
        """Fill :attr:`states` and :attr:`outputs`; returns the mode's value."""
        return int(self._lib.pam_engine_session_read(self._handle, self._x_at, self._y_at, self._info_at))

    @property
    def time_s(self) -> float:
        """The session's time [s] (as of the last :meth:`read`, which every method but :meth:`step` does)."""
        return float(self._info[0])

    @property
    def mode(self) -> int:
        """The mode's value (``library.names["modes"]``), as of the last :meth:`read`."""
        return int(self._info[1])

    @property
    def stats(self) -> dict:
        """Right-hand-side evaluations, accepted steps and events since the reset, as of the last :meth:`read`."""
        return {"rhs_evaluations": int(self._info[2]), "steps": int(self._info[3]), "events": int(self._info[4])}

    def extremes(self) -> tuple[np.ndarray, np.ndarray]:
        """Each output's largest and smallest value since the start, over every step end and event."""
        out = np.empty(2 * self.library.layout["ny"])
        self._lib.pam_engine_session_extremes(self._handle, out.ctypes.data)
        return out[:len(out) // 2], out[len(out) // 2:]


_LOADED: dict = {}
LOADED_SIZE = 32
"""Engine libraries kept loaded per process (a sweep's runs share one)."""


def engine_sources_token(cc: str) -> str:
    """Hash of the engine's C sources, the compiler and its flags."""
    h = hashlib.sha256()
    src = c_source_dir() / "src"
    for name in ENGINE_SOURCES:
        h.update(name.encode() + b"\0" + (src / name).read_bytes())
    h.update("\0".join((cc, *FLAGS)).encode())
    return h.hexdigest()


def engine_library(assembly) -> EngineLibrary:
    """The engine compiled for ``assembly``'s structure (generated and compiled on first use).

    Raises
    ------
    InputError
        Without a C compiler, or if the compilation fails (with the compiler's message).
    NotImplementedError
        For an assembly the C engine cannot run (external functions, more than one hybrid component).
    """
    # The assembly's name is only a comment in the C: scenarios that differ in name alone (a sweep's
    # cases) share one engine.
    key = assembly.structure_key()[1:]
    if key in _LOADED:
        return _LOADED[key]
    cc = compiler()
    name = code_cache.entry_name(("engine", key))
    tag = hashlib.sha256(((name or "") + engine_sources_token(cc)).encode()).hexdigest()[:24]
    folder = cache_root() / "engine" / tag
    path = folder / ("libpamsim_engine" + shared_library_suffix())
    names_file = folder / "names.json"
    if name is None or not (path.is_file() and names_file.is_file()):
        path, names = _build(assembly, cc, folder if name is not None else None)
    else:
        import json
        names = json.loads(names_file.read_text())
    if len(_LOADED) >= LOADED_SIZE:
        _LOADED.pop(next(iter(_LOADED)))
    _LOADED[key] = EngineLibrary(path, names)
    return _LOADED[key]


def _build(assembly, cc: str, folder: Path | None) -> tuple[Path, dict]:
    import json

    from ..modeling.cmodel import CModel

    model = CModel(assembly)
    names = {kind: [v.name for v in getattr(model.full, kind)] for kind in ("states", "inputs", "outputs", "parameters")}
    names["modes"] = model.mode_values
    if folder is None:  # a structure another process cannot name: built for this process only
        folder = Path(tempfile.mkdtemp(prefix="pamsim-engine-"))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / ("libpamsim_engine" + shared_library_suffix())
    with tempfile.TemporaryDirectory(prefix="build-", dir=folder) as tmp:
        work = Path(tmp)
        for file, text in model.sources().items():
            (work / file).write_text(text)
        partial = compile_library(cc, "pam_engine_batch.c", work, path.name, f"the engine for {model.full.name}")
        (work / "names.json").write_text(json.dumps(names))
        os.replace(work / "names.json", folder / "names.json")
        os.replace(partial, path)
    return path, names
