"""ctypes bindings of the native library (``fmu/src/pam_native.h``).

ctypes, not cffi: it is in the standard library, needs no build step of its
own, and each batch is one call, so its per-call overhead does not matter.
numpy arrays are passed by pointer; nothing is copied back and forth per case.
The layout of :class:`PamBatch` and the array widths are checked against the
library's own (``pam_native_layout``) when it is loaded.
"""

from __future__ import annotations

import ctypes
from functools import lru_cache
from typing import Sequence

import numpy as np

from ..fmu.variables import INPUTS, VARIABLES  # INPUTS: held over each segment, the order of segment_u
from .build import library_path
SAMPLE_COLUMNS = ("x_m", "v_m_s", "p_abs_Pa", "air_mass_kg", "W_muscle_J", "E_friction_J", "E_damping_J",
                  "W_external_J", "E_impacts_J")
"""The columns of each sample (PAM_NATIVE_NOUT)."""
EVENT_KINDS = ("velocity_zero", "stop_low", "stop_high", "release_up", "release_down")
"""``PamEventKind``: the names :mod:`pamsim.simulator` gives its events."""
QUANTITIES = ("static_force_N", "coulomb_level_N", "damping_force_N", "valve_flow_kg_s", "pressure_rate_Pa_s",
              "rhs_x", "rhs_v", "rhs_p", "rhs_m", "indicator_1", "indicator_2", "net_force_N", "level_at_rest_N",
              "rest_mode", "volume_m3", "upper_stop_m", "pressure_gauge_Pa")
"""``PamQuantity``: what ``pam_native_evaluate`` returns per point (PAM_NATIVE_NQ)."""
STATUS = ("ok", "bad input", "solver failed", "event buffer full")
MESSAGE_BYTES = 256

REALS = tuple(v.name for v in VARIABLES if v.kind == "real")
INTS = tuple(v.name for v in VARIABLES if v.kind == "integer")
REAL_INDEX = {name: i for i, name in enumerate(REALS)}
INT_INDEX = {name: i for i, name in enumerate(INTS)}
REAL_DEFAULTS = np.array([float(v.start) if v.start is not None else 0.0 for v in VARIABLES if v.kind == "real"])
INT_DEFAULTS = np.array([int(v.start) if v.start is not None else 0 for v in VARIABLES if v.kind == "integer"],
                        dtype=np.int32)
N_STATES = 4

_D = ctypes.POINTER(ctypes.c_double)
_I32 = ctypes.POINTER(ctypes.c_int32)
_I64 = ctypes.POINTER(ctypes.c_int64)


class PamBatch(ctypes.Structure):
    """Mirror of ``PamBatch`` in ``pam_native.h``."""

    _fields_ = [("n_cases", ctypes.c_int64), ("reals", _D), ("ints", _I32), ("duration_s", _D),
                ("n_samples", _I64), ("sample_offset", _I64), ("n_segments", _I64), ("segment_offset", _I64),
                ("segment_t_s", _D), ("segment_u", _D), ("segment_du", _D), ("event_capacity", _I64),
                ("event_offset", _I64),
                ("table_index", _I64), ("table_grid", _D), ("table_offset", _I64), ("table_nodes", _D),
                ("samples", _D), ("modes", _I32), ("events", _D), ("n_events", _I64), ("stats", _I64),
                ("status", _I32), ("peaks", _D), ("messages", ctypes.c_char_p)]


@lru_cache(maxsize=1)
def load() -> ctypes.CDLL:
    """The library built from the current sources (compiled on first use), its layout checked."""
    lib = ctypes.CDLL(str(library_path()))
    lib.pam_native_layout.restype = ctypes.c_int64
    lib.pam_native_layout.argtypes = [ctypes.c_int64]
    expected = (len(REALS), len(INTS), len(INPUTS), len(SAMPLE_COLUMNS), 6, len(QUANTITIES), MESSAGE_BYTES,
                ctypes.sizeof(PamBatch), N_STATES)
    actual = tuple(lib.pam_native_layout(k) for k in range(len(expected)))
    if actual != expected:  # a programming error, not bad input: the two sides were edited apart
        raise RuntimeError(f"native library layout {actual} differs from pamsim.native.library's {expected}")
    lib.pam_native_run_batch.restype = ctypes.c_int64
    lib.pam_native_run_batch.argtypes = [ctypes.POINTER(PamBatch)]
    lib.pam_native_evaluate.restype = None
    lib.pam_native_evaluate.argtypes = [ctypes.c_int64, _D, _I32, _D, _I32, _D]
    return lib


def _ptr(array: np.ndarray, kind):
    return array.ctypes.data_as(kind)


def run_batch(reals, ints, duration_s, n_samples, segment_counts, segment_t_s, segment_u, event_capacity,
              tables: Sequence = (), table_index=None, segment_du=None) -> dict:
    """Run cases in one library call.

    Parameters
    ----------
    reals, ints : ndarray
        ``(n_cases, len(REALS))`` float64 and ``(n_cases, len(INTS))`` int32: every variable's value.
    duration_s, n_samples : ndarray
        Per case: the run's length [s] and the samples of ``linspace(0, duration_s, n_samples)``.
    segment_counts : ndarray
        Per case: its number of input segments.
    segment_t_s, segment_u : ndarray
        All cases' segments, concatenated: start time [s] and the :data:`INPUTS` at it.
    event_capacity : ndarray
        Per case: how many events to keep.
    tables : sequence of pamsim.fmu.force_table.ForceTable
        The static force tables the cases use (``static_force_model = table``).
    table_index : ndarray, optional
        Per case: its table in ``tables``, or -1 (none; the default for every case).
    segment_du : ndarray, optional
        Per segment and input, the slope, lag amplitude and lag time constant of the input over the
        segment (:class:`pamsim.native.engine.EngineCase`); None: every input held over its segment.

    Returns
    -------
    dict
        ``samples`` (per case a block of :data:`SAMPLE_COLUMNS` x its samples, flattened), ``modes``, ``sample_offset``, ``events``,
        ``event_offset``, ``n_events``, ``stats`` (RHS evaluations, steps, segments), ``status``,
        ``peaks`` (per case: largest and smallest x [m], largest gauge pressure [Pa] at every step end and event),
        ``messages``.
    """
    lib = load()
    c = lambda a, t: np.ascontiguousarray(a, dtype=t)  # noqa: E731
    reals, ints = c(reals, np.float64), c(ints, np.int32)
    duration_s, n_samples = c(duration_s, np.float64), c(n_samples, np.int64)
    segment_counts, event_capacity = c(segment_counts, np.int64), c(event_capacity, np.int64)
    segment_t_s, segment_u = c(segment_t_s, np.float64), c(segment_u, np.float64)
    n = len(duration_s)
    offsets = lambda counts: np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)  # noqa: E731
    out = {"sample_offset": offsets(n_samples), "event_offset": offsets(event_capacity),
           "samples": np.empty(int(n_samples.sum()) * len(SAMPLE_COLUMNS)),
           "modes": np.empty(int(n_samples.sum()), dtype=np.int32),
           "events": np.empty((int(event_capacity.sum()), 6)), "n_events": np.zeros(n, dtype=np.int64),
           "stats": np.zeros((n, 3), dtype=np.int64), "status": np.zeros(n, dtype=np.int32),
           "peaks": np.full((n, 3), np.nan)}
    messages = ctypes.create_string_buffer(MESSAGE_BYTES * n)
    table_index = c(np.full(n, -1) if table_index is None else table_index, np.int64)
    grid = c([[*t.shape, t.x_min_m, (t.x_max_m - t.x_min_m) / (t.shape[0] - 1), t.p_min_Pa,
               (t.p_max_Pa - t.p_min_Pa) / (t.shape[1] - 1)] for t in tables] or np.zeros((1, 6)), np.float64)
    nodes = c(np.concatenate([t.values.reshape(-1, 4) for t in tables]) if tables else np.zeros((1, 4)), np.float64)
    table_offset = c(np.concatenate([[0], np.cumsum([t.shape[0] * t.shape[1] for t in tables])[:-1]])
                     if tables else np.zeros(1), np.int64)
    segment_offset = offsets(segment_counts)
    du = None if segment_du is None else c(segment_du, np.float64).reshape(-1, len(INPUTS), 3)
    batch = PamBatch(n, _ptr(reals, _D), _ptr(ints, _I32), _ptr(duration_s, _D), _ptr(n_samples, _I64),
                     _ptr(out["sample_offset"], _I64), _ptr(segment_counts, _I64), _ptr(segment_offset, _I64),
                     _ptr(segment_t_s, _D), _ptr(segment_u, _D), _ptr(du, _D) if du is not None else None,
                     _ptr(event_capacity, _I64),
                     _ptr(out["event_offset"], _I64), _ptr(table_index, _I64), _ptr(grid, _D),
                     _ptr(table_offset, _I64), _ptr(nodes, _D), _ptr(out["samples"], _D), _ptr(out["modes"], _I32),
                     _ptr(out["events"], _D), _ptr(out["n_events"], _I64), _ptr(out["stats"], _I64),
                     _ptr(out["status"], _I32), _ptr(out["peaks"], _D), ctypes.cast(messages, ctypes.c_char_p))
    lib.pam_native_run_batch(ctypes.byref(batch))
    raw = messages.raw
    out["messages"] = [raw[MESSAGE_BYTES * i:MESSAGE_BYTES * (i + 1)].split(b"\0", 1)[0].decode(errors="replace")
                       for i in range(n)]
    return out


def evaluate(reals, ints, states, modes) -> dict[str, np.ndarray]:
    """The C core's element functions at many points: :data:`QUANTITIES` by name, one value per point.

    ``reals``/``ints`` hold each point's variables (as :func:`run_batch`), ``states`` its
    ``(x_m, v_m_s, p_abs_Pa, air_mass_kg)`` and ``modes`` its :class:`~pamsim.model.Mode`.
    """
    lib = load()
    reals = np.ascontiguousarray(reals, dtype=np.float64)
    ints = np.ascontiguousarray(ints, dtype=np.int32)
    states = np.ascontiguousarray(states, dtype=np.float64)
    modes = np.ascontiguousarray(modes, dtype=np.int32)
    n = len(modes)
    out = np.empty((n, len(QUANTITIES)))
    lib.pam_native_evaluate(n, _ptr(reals, _D), _ptr(ints, _I32), _ptr(states, _D), _ptr(modes, _I32),
                            _ptr(out, _D))
    return {name: out[:, k] for k, name in enumerate(QUANTITIES)}
