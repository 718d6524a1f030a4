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
import os
import tempfile
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

ENGINE_SOURCES = ("pam_engine_batch.c", "pam_engine_session.c", "pam_engine.c", "pam_engine.h", "pam_dopri.h", "pam_gauss.h")
LAYOUT = ("nx", "nq", "nu", "np", "ny", "nz", "nmodes", "ns", "event_columns", "message_bytes", "batch_bytes")
"""What ``pam_engine_layout(k)`` returns, by k."""
STATUS = ("ok", "bad input", "solver failed", "event buffer full")
MESSAGE_BYTES = 256

_D = ctypes.POINTER(ctypes.c_double)
_P = ctypes.c_void_p
_I32 = ctypes.POINTER(ctypes.c_int32)
_I64 = ctypes.POINTER(ctypes.c_int64)


class EngineBatch(ctypes.Structure):
    """Mirror of ``PamEngineBatch`` in ``pam_engine_batch.c``."""

    _fields_ = [("n_cases", ctypes.c_int64), ("params", _D), ("rtol", _D), ("max_step_s", _D), ("max_steps", _I64),
                ("duration_s", _D), ("n_samples", _I64), ("sample_offset", _I64), ("n_segments", _I64),
                ("segment_offset", _I64), ("segment_t_s", _D), ("segment_u", _D), ("segment_du", _D),
                ("event_capacity", _I64),
                ("event_offset", _I64), ("samples", _D), ("modes", _I32), ("events", _D), ("n_events", _I64),
                ("stats", _I64), ("status", _I32), ("extremes", _D), ("messages", ctypes.c_char_p)]


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
                      "reset": (ctypes.c_int32, [_P, _P, _P, ctypes.c_double, ctypes.c_double, ctypes.c_int64]),
                      "advance": (ctypes.c_int32, [_P, _P, ctypes.c_double]),
                      "read": (ctypes.c_int32, [_P, _P, _P, _P]),
                      "step": (ctypes.c_int32, [_P, _P, ctypes.c_double, _P, _P]),
                      "extremes": (None, [_P, _P]), "message": (ctypes.c_char_p, [_P])}
        for name, (restype, argtypes) in signatures.items():
            fn = getattr(lib, f"pam_engine_session_{name}")
            fn.restype, fn.argtypes = restype, argtypes
        self._lib = lib

    def session(self) -> "EngineSession":
        """A new :class:`EngineSession` of this library (one run, advanced step by step)."""
        return EngineSession(self)

    def run(self, cases: Sequence[EngineCase]) -> dict:
        """Run ``cases`` in one call.  Returns per case, concatenated: ``samples`` (a block of every state
        x its samples), ``modes``, ``events`` (rows of t, mode before, mode after, fired mask, outputs
        before, outputs after), ``n_events``, ``stats`` (RHS evaluations, steps, segments + events),
        ``status``, ``extremes`` (each output's largest then smallest value over every step end and
        event), ``messages``, and the offsets of each case's samples and events."""
        c = lambda a, t: np.ascontiguousarray(a, dtype=t)  # noqa: E731
        n, L = len(cases), self.layout
        offsets = lambda counts: np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)  # noqa: E731
        n_samples = c([k.n_samples for k in cases], np.int64)
        capacity = c([k.event_capacity for k in cases], np.int64)
        n_segments = c([len(k.segment_t_s) for k in cases], np.int64)
        arrays = {
            "params": c(np.array([k.params for k in cases]).reshape(n, L["np"]), np.float64),
            "rtol": c([k.rtol for k in cases], np.float64), "max_step_s": c([k.max_step_s for k in cases], np.float64),
            "max_steps": c([k.max_steps for k in cases], np.int64),
            "duration_s": c([k.duration_s for k in cases], np.float64),
            "segment_t_s": c(np.concatenate([k.segment_t_s for k in cases]), np.float64),
            "segment_u": c(np.concatenate([np.asarray(k.segment_u, float).reshape(-1, L["nu"]) for k in cases]),
                           np.float64)}
        exact = any(k.segment_du is not None for k in cases)
        if exact:  # a case with held inputs among them: no change over its segments
            arrays["segment_du"] = c(np.concatenate([
                np.zeros((len(k.segment_t_s), L["nu"], 3)) if k.segment_du is None
                else np.asarray(k.segment_du, float).reshape(-1, L["nu"], 3) for k in cases]), np.float64)
        out = {"sample_offset": offsets(n_samples), "event_offset": offsets(capacity),
               "samples": np.empty(int(n_samples.sum()) * L["ns"]),
               "modes": np.empty(int(n_samples.sum()), dtype=np.int32),
               "events": np.empty((max(int(capacity.sum()), 1), L["event_columns"])),
               "n_events": np.zeros(n, dtype=np.int64), "stats": np.zeros((n, 3), dtype=np.int64),
               "status": np.zeros(n, dtype=np.int32), "extremes": np.full((n, 2 * L["ny"]), np.nan)}
        messages = ctypes.create_string_buffer(MESSAGE_BYTES * n)
        segment_offset = offsets(n_segments)
        p = lambda a, kind: a.ctypes.data_as(kind)  # noqa: E731
        batch = EngineBatch(n, p(arrays["params"], _D), p(arrays["rtol"], _D), p(arrays["max_step_s"], _D),
                            p(arrays["max_steps"], _I64), p(arrays["duration_s"], _D), p(n_samples, _I64),
                            p(out["sample_offset"], _I64), p(n_segments, _I64), p(segment_offset, _I64),
                            p(arrays["segment_t_s"], _D), p(arrays["segment_u"], _D),
                            p(arrays["segment_du"], _D) if exact else None, p(capacity, _I64),
                            p(out["event_offset"], _I64), p(out["samples"], _D), p(out["modes"], _I32),
                            p(out["events"], _D), p(out["n_events"], _I64), p(out["stats"], _I64),
                            p(out["status"], _I32), p(out["extremes"], _D), ctypes.cast(messages, ctypes.c_char_p))
        self._lib.pam_engine_run_batch(ctypes.byref(batch))
        raw = messages.raw
        out["messages"] = [raw[MESSAGE_BYTES * i:MESSAGE_BYTES * (i + 1)].split(b"\0", 1)[0].decode(errors="replace")
                           for i in range(n)]
        return out


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
              max_steps: int) -> None:
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
                                                    float(max_step_s), int(max_steps))
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
    key = assembly.structure_key()
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
