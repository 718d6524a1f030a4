"""One segment of a hybrid run: a scipy integrator stepped to a breakpoint or its first terminal event.

``scipy.integrate.solve_ivp`` around each segment cost more than the steps inside it: a valve switched by
PWM at 50 Hz for 5 s makes about 870 segments of about ten LSODA steps, and ``solve_ivp`` built a dense
output and an array of every event's value at every step, and a piecewise solution at the end, where a
segment reads a dense output only at a sample, an event or a check inside a long step.

:func:`integrate_segment` steps the same solver class (``scipy.integrate.LSODA``, ``RK45``...) with the
same options, finds events by ``solve_ivp``'s rule (a terminal event fires at the step end where its
value, seen at the step's two ends, went from >= 0 to <= 0; its time is ``brentq``'s root, to ``4 eps``,
of the value along the step's dense output; the earliest of those found in one step fires), and reads
samples from the step ``solve_ivp``'s piecewise solution would have used.  Its steps, events and samples
are those of ``solve_ivp``, number for number.

A step that is long, in which the load's velocity changes sign, or in which a sliding load's indicator may
dip to zero and back (:func:`_may_dip`), is also checked inside for an indicator that went below zero and
back between its ends (:func:`missed_crossing`), and the segment then ends there.  The run stops at that
step, where ``solve_ivp`` went on to its segment's end and was cut afterwards: only the count of right-hand-side evaluations differs.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

EPS = float(np.finfo(float).eps)

LONG_STEP_S = 0.01
"""A step longer than this [s] is checked inside for a crossing that its two ends do not show (the C
engine's default longest step while the load slides, the FMU's ``cs_max_step_s``).  So is a step of any
length in which the load turns back (:func:`missed_crossing`)."""
LONG_STEP_CHECKS = 16
"""Points of a checked step's dense output looked at for a crossing (as the C engine checks a held load's)."""

# solve_ivp's piecewise solution of these two methods takes a time on a step boundary from the step that
# starts there (scipy's OdeSolution ``alt_segment``), the others' from the step that ends there.
_FROM_NEXT_STEP = ("LSODA", "BDF")


@dataclass
class Segment:
    """What :func:`integrate_segment` integrated.

    ``t``, ``y``: the start, every step's end and the segment's end (its event's time, if any), and the
    states there (one column per time).  ``samples_t``, ``samples_y``: the samples asked for, up to the
    segment's end, from the dense output.  ``status``: 0 at the breakpoint, 1 at an event, -1 failed
    (``message`` says why).  ``event``: the index of the event function that fired, at ``t_event`` [s]
    with the states ``y_event``; ``nfev``: right-hand-side evaluations; ``njev``: Jacobians the method formed
    (scipy's count; LSODA's by finite differences, whose evaluations are among ``nfev``); ``h_next``:
    :data:`DOPRI5`'s proposal for the next step [s]; for scipy's methods the last step taken (to the
    segment's end or its event; None if it took none)."""

    t: np.ndarray
    y: np.ndarray
    samples_t: np.ndarray
    samples_y: np.ndarray
    status: int
    event: int | None
    t_event: float | None
    y_event: np.ndarray | None
    nfev: int
    message: str
    h_next: float | None = None
    njev: int = 0


DOPRI5 = "DOPRI5"
"""The method name of :class:`DormandPrince` (``solver.method``)."""


class DormandPrince:
    """Dormand and Prince's explicit Runge-Kutta pair of order 5(4), with the formulas, the error norm, the
    step-size control and the dense output of ``scipy.integrate.RK45``, stepped without scipy's generic
    solver around each step; the solver of ``solver.method = "DOPRI5"``.

    What it does that ``RK45`` does not: a segment may start from a given step size (``first_step``, the
    last segment's proposal: :attr:`h_next`) instead of estimating one from the start's derivatives.  A
    run of many short segments (a valve under PWM) then does not start every one of them small.

    E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary Differential Equations I: Nonstiff Problems*,
    Springer, 2nd ed., 1993, sec. II.4-5 (the pair, its step control and its dense output).
    """

    SAFETY, MIN_FACTOR, MAX_FACTOR, ERROR_EXPONENT = 0.9, 0.2, 10.0, -1.0 / 5.0  # as RK45's

    def __init__(self, fun, t0: float, y0, t_bound: float, *, rtol: float, atol, max_step: float = np.inf,
                 first_step: float | None = None):
        from scipy.integrate import RK45

        self.A, self.B, self.C, self.E, self.P = RK45.A, RK45.B, RK45.C, RK45.E, RK45.P
        self.fun, self.t, self.t_bound, self.t_old = fun, float(t0), float(t_bound), None
        self.y = np.array(y0, dtype=float)
        self.rtol, self.atol, self.max_step = rtol, np.asarray(atol, dtype=float), max_step
        self.f = np.asarray(fun(self.t, self.y), dtype=float)
        self.nfev = 1
        self.K = np.empty((len(self.B) + 1, self.y.size))
        self.y_old = self.y
        self.status = "running" if self.t < self.t_bound else "finished"
        self.h_abs = first_step if first_step else self._initial_step()
        self._constant = False  # the last step took no time (its dense output is the state)
        self.h_next = self.h_abs
        """The step the last step proposed for the next, unshortened by the end of the segment [s]."""

    def _norm(self, x) -> float:
        return float(np.linalg.norm(x) / x.size ** 0.5)  # scipy's RMS norm, rounded as it rounds

    def _initial_step(self) -> float:
        """Hairer, Norsett and Wanner's starting step (sec. II.4), as ``RK45`` takes it."""
        t0, y0, f0 = self.t, self.y, self.f
        span = self.t_bound - t0
        if span <= 0.0:
            return 0.0
        scale = self.atol + np.abs(y0) * self.rtol
        d0, d1 = self._norm(y0 / scale), self._norm(f0 / scale)
        h0 = min(1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1, span)
        f1 = np.asarray(self.fun(t0 + h0, y0 + h0 * f0), dtype=float)
        self.nfev += 1
        d2 = self._norm((f1 - f0) / scale) / h0
        h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 else (0.01 / max(d1, d2)) ** 0.2
        return min(100 * h0, h1, span)

    def step(self) -> str | None:
        """One accepted step (rejected trial steps inside); a message if the step became too small."""
        t, y, K, A, C = self.t, self.y, self.K, self.A, self.C
        if t == self.t_bound:  # a segment of no time: as scipy's solvers, no step
            self.t_old, self.y_old, self.status = t, y, "finished"
            self._constant = True
            return None
        self._constant = False
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        h_abs = min(max(self.h_abs, min_step), self.max_step)
        rejected = False
        while True:
            if h_abs < min_step:
                self.status = "failed"
                return "Required step size is less than spacing between numbers."
            t_new = min(t + h_abs, self.t_bound)
            shortened = t_new == self.t_bound and t + h_abs != t_new
            h = t_new - t
            K[0] = self.f
            for s in range(1, len(C)):
                K[s] = self.fun(t + C[s] * h, y + np.dot(K[:s].T, A[s, :s]) * h)
            y_new = y + h * np.dot(K[:-1].T, self.B)
            K[-1] = f_new = self.fun(t_new, y_new)
            self.nfev += len(C)
            scale = self.atol + np.maximum(np.abs(y), np.abs(y_new)) * self.rtol
            err = self._norm(np.dot(K.T, self.E) * h / scale)
            if err < 1.0:
                factor = self.MAX_FACTOR if err == 0.0 else min(self.MAX_FACTOR, self.SAFETY * err ** self.ERROR_EXPONENT)
                proposed = h * (min(1.0, factor) if rejected else factor)
                break
            h_abs = h * max(self.MIN_FACTOR, self.SAFETY * err ** self.ERROR_EXPONENT)
            rejected = True
        self.t_old, self.y_old, self.t, self.y = t, y, t_new, y_new
        self.f = np.asarray(f_new, dtype=float)
        self.h_abs = proposed
        if not shortened:
            self.h_next = proposed
        if t_new >= self.t_bound:
            self.status = "finished"
        return None

    def dense_output(self):
        """The step's quartic interpolant: a callable of a time or an array of times in it."""
        if self._constant:
            y_end = self.y
            return lambda t: y_end if np.ndim(t) == 0 else np.repeat(y_end[:, None], np.size(t), axis=1)
        q1, q2, q3, q4 = self.K.T.dot(self.P).T * (self.t - self.t_old)
        t_old, y_old, h = self.t_old, self.y_old, self.t - self.t_old

        def y_at(t):
            if t.__class__ is float:  # the root finders' and event checks' many scalar reads: no array made
                x = (t - t_old) / h
            else:
                x = (np.asarray(t, dtype=float) - t_old) / h
                if x.ndim:
                    x = x[None, :]
                    return y_old[:, None] + x * (q1[:, None] + x * (q2[:, None] + x * (q3[:, None] + x * q4[:, None])))
            return y_old + x * (q1 + x * (q2 + x * (q3 + x * q4)))
        return y_at


# The exponents 0..q of LSODA's orders (up to 12, Adams; 5, BDF) as floats: numpy raises a float to an
# integer array's powers through the same pow() after casting them, so only the cast is saved.
_POWERS = [np.arange(q + 1, dtype=float) for q in range(13)]


class _Nordsieck:
    """LSODA's dense output over its last step, read from the solver's Nordsieck array as scipy's (1.12 and
    later: pamsim's floor) ``LSODA._dense_output_impl`` reads it (ODEPACK's layout: the last step's order
    ``iwork[13]``, the next step ``rwork[11]``, the array from ``rwork[20]``, its last column rescaled where
    the order is to fall) and evaluated with the same operations as scipy's ``LsodaDenseOutput``: the same
    numbers.  Without scipy's generic objects around it, which cost more than the evaluation: a run under PWM
    reads one at every step (its midpoint, :func:`_may_dip`)."""

    __slots__ = ("t", "h", "yh", "p")

    def __init__(self, solver):
        integrator = solver._lsoda_solver._integrator
        iwork, rwork = integrator.iwork, integrator.rwork
        order, h = iwork[13], rwork[11]
        yh = rwork[20:20 + (order + 1) * solver.n].reshape((solver.n, order + 1), order="F").copy()
        if iwork[14] < order:  # the last column, unused at the next order, was not rescaled to its step
            yh[:, -1] *= (h / rwork[10]) ** order
        self.t, self.h, self.yh, self.p = solver.t, h, yh, _POWERS[order]

    def __call__(self, t):
        if t.__class__ is not float and np.ndim(t):
            return np.dot(self.yh, ((np.asarray(t, dtype=float) - self.t) / self.h) ** self.p[:, None])
        return np.dot(self.yh, ((t - self.t) / self.h) ** self.p)


def _dense_of(solver):
    """The solver's dense output over its last step (:class:`_Nordsieck` for LSODA's, where the installed
    scipy keeps LSODA's arrays where scipy 1.12 to 1.17 do)."""
    if solver.t != solver.t_old and hasattr(solver, "_lsoda_solver"):
        try:
            return _Nordsieck(solver)
        except (AttributeError, IndexError, TypeError):
            pass
    return solver.dense_output()


def _failure_message(solver, message: str | None) -> str:
    """Why ``solver`` failed: for LSODA, ODEPACK's own words for its state (scipy says only "Unexpected
    istate in LSODA." and puts the reason in a warning), else the solver's message."""
    integrator = getattr(getattr(solver, "_lsoda_solver", None), "_integrator", None)
    words = getattr(integrator, "messages", {}).get(getattr(integrator, "istate", None))
    return f"LSODA: {words}" if words else (message or "")


class LsodaRestarts:
    """``scipy.integrate.LSODA`` solvers kept from one segment to the next of a run and restarted at each
    segment's start, in place of a new solver per segment.

    A valve under PWM cuts a run into hundreds of segments of about ten steps each, and building an LSODA
    solver (scipy's argument checks, its ``ode`` wrapper looking its integrator up by name) cost a tenth of
    such a run.  A restart does what the constructor does to the integrator, through the same private
    attributes scipy's ``LSODA.__init__`` sets (``_lsoda_solver``, its integrator's ``rwork`` and
    ``call_args``): the initial value set afresh (new work arrays, ``istate = 1``, so nothing of the last
    segment is kept) and the segment's end written where LSODA's one-step mode reads it.  Its steps are
    those of a new solver, bit for bit (``tests/test_stepping.py``).  Where the installed scipy lacks those
    attributes, a new solver is built as before.  One solver per set of options (tolerances and longest
    step); the right-hand side, which changes with the mode, is looked up at each call."""

    def __init__(self):
        self._solvers: dict = {}
        self._fun: Callable | None = None

    def _call(self, t, y):
        return self._fun(t, y)

    def start(self, fun: Callable, t0: float, y0: np.ndarray, t_bound: float, *, rtol: float, atol,
              max_step: float):
        """An LSODA solver of ``fun`` from ``(t0, y0)`` to ``t_bound``, as ``scipy.integrate.LSODA`` builds it."""
        from scipy.integrate import LSODA

        self._fun = fun
        key = (rtol, np.asarray(atol, dtype=float).tobytes(), max_step, np.size(y0))
        solver = self._solvers.get(key)
        if solver is None:
            solver = LSODA(self._call, t0, y0, t_bound, rtol=rtol, atol=atol, max_step=max_step)
            self._solvers[key] = solver
            return solver
        try:
            ode, integrator = solver._lsoda_solver, solver._lsoda_solver._integrator
            ode.set_initial_value(y0, t0)
            integrator.rwork[0] = t_bound
            integrator.call_args[4] = integrator.rwork
        except (AttributeError, IndexError, TypeError):  # scipy's internals changed: build as before
            del self._solvers[key]
            return self.start(fun, t0, y0, t_bound, rtol=rtol, atol=atol, max_step=max_step)
        solver.y = np.asarray(y0, dtype=float)
        if not all(map(math.isfinite, solver.y.tolist())):  # scipy's own check, and its words
            raise ValueError("All components of the initial state `y0` must be finite.")
        solver.t_old, solver.t, solver.t_bound, solver.status = None, t0, t_bound, "running"
        solver.direction = np.sign(t_bound - t0) if t_bound != t0 else 1
        solver.nfev = solver.njev = solver.nlu = 0
        return solver


def missed_crossing(events: Sequence[Callable], directions: Sequence[float], g_old: Sequence[float], dense,
                    t_old: float, t: float, also: Sequence[float] = ()):
    """The first ``(time, index)`` inside the step ``(t_old, t]`` where one of ``events`` crossed zero in its
    ``direction`` (``solve_ivp``'s rule, :func:`_crossed`), looked for between :data:`LONG_STEP_CHECKS` points
    of the step's ``dense`` output and the times ``also`` inside it from the events' values ``g_old`` at
    ``t_old``, or None.

    ``solve_ivp`` finds an event where an indicator changes sign between two step ends.  A free swing at
    a tight tolerance can take a step long enough for the load to reach a stop and come back within it
    (RK45 at rtol 1e-10 took 0.17 s and carried the load 24 mm through its upper stop)."""
    from scipy.optimize import brentq

    # Floats, not numpy scalars: the dense output reads a float without making an array (same values)
    taus = np.linspace(t_old, t, LONG_STEP_CHECKS + 1).tolist()
    if len(also):
        taus = sorted(set(taus).union(a for a in also if t_old < a < t))
    g_lo = list(g_old)
    for lo, hi in zip(taus[:-2], taus[1:-1]):  # the step's end is what the event rule checked
        y_hi = dense(hi)
        g_hi = [fun(hi, y_hi) for fun in events]
        crossed = [k for k in range(len(events)) if _crossed(g_lo[k], g_hi[k], directions[k])]
        if crossed:
            roots = []
            for k in crossed:
                fun = events[k]
                before = fun(lo, dense(lo))  # the dense output's, which may round to the far side at t_old
                roots.append((brentq(lambda tau: fun(tau, dense(tau)), lo, hi, xtol=1e-15)
                              if before * g_hi[k] < 0.0 else hi, k))
            return min(roots)
        g_lo = g_hi
    return None


def _resolution(fun: Callable, t: float, y: np.ndarray, value: float, atol) -> float:
    """How far the event function ``fun`` (``value`` at ``(t, y)``) moves when the states move by their
    absolute tolerances ``atol`` (one, or one per state), one at a time (the sum of the moves): a value closer
    to zero than that is below what the integration resolves."""
    moved, atol = 0.0, np.broadcast_to(np.asarray(atol, dtype=float), y.shape)
    for n in range(y.size):
        yd = y.copy()
        yd[n] += atol[n]
        moved += abs(fun(t, yd) - value)
    return moved


def _may_dip(events: Sequence[Callable], directions: Sequence[float], g_old: Sequence[float],
             g_new: Sequence[float], dense, t_old: float, t: float, atol) -> list[float] | None:
    """Where to look inside a step, as a time, for an event function on the same side of zero at both ends
    (the side it crosses from) that may cross zero and come back inside it, or None: it is on the far side
    at the step's midpoint (look there), or the parabola through its values at the ends and the midpoint
    has its extreme inside the step, on the far side (look there); either by more than its resolution at
    the midpoint (:func:`_resolution`: a velocity hovering far below its tolerance of zero is no stick).
    The C engine's ``may_dip``.  Under PWM a load comes to rest for a few milliseconds between two pulses:
    a step of that length crossed the stick and came back from it, its velocity of one sign at both ends."""
    t_mid = 0.5 * (t_old + t)
    y_mid = dense(t_mid)
    for fun, a0, a1, d in zip(events, g_old, g_new, directions):
        # the near side: positive for a falling event, negative for a rising one, either for one of both ways
        sign = -1.0 if d > 0 or (d == 0 and a0 < 0.0) else 1.0
        z0, z1 = sign * a0, sign * a1
        if not (z0 > 0.0 and z1 > 0.0):
            continue
        value = fun(t_mid, y_mid)
        zm = sign * value
        a = 2.0 * (z0 + z1 - 2.0 * zm)  # the parabola a th^2 + b th + z0 through th = 0, 1/2, 1
        b = z1 - z0 - a
        th, low = 0.5, zm
        if a > 0.0 and b < 0.0 and -b < 2.0 * a and z0 - b * b / (4.0 * a) < low:
            th, low = -b / (2.0 * a), z0 - b * b / (4.0 * a)
        if low < 0.0 and -low > _resolution(fun, t_mid, y_mid, value, atol):
            return [t_old + th * (t - t_old)]
    return None


def _turned(v_old: float, v_new: float, v_tol: float) -> bool:
    """Whether the load's velocity went from one side of zero to the other over a step, beyond its absolute
    tolerance ``v_tol`` on both.  A step from rest is judged instead, in :func:`integrate_segment`, by its
    velocity at the first of the points :func:`missed_crossing` looks at: a turn before it is below the
    resolution of that look anyway.  A slide that ends at its velocity's zero (an event there leaves v at
    +-1e-17) has not turned.  A turn that leaves the load slower than its tolerance carries it
    ``v_tol^2 / (2 a)`` past where it turned, far below its position's tolerance."""
    return (v_old > v_tol and v_new < -v_tol) or (v_old < -v_tol and v_new > v_tol)


def _crossed(g_old, g_new, direction) -> bool:
    """Whether an event function's values at a step's two ends show its crossing (``solve_ivp``'s rule)."""
    up, down = g_old <= 0 and g_new >= 0, g_old >= 0 and g_new <= 0
    return (up and direction > 0) or (down and direction < 0) or ((up or down) and direction == 0)


def _earliest_event(events, directions, g_old, g_new, dense, t_old: float, t: float) -> tuple[float, int]:
    """``solve_ivp``'s terminal event of the step ``(t_old, t]``: ``(time, index)`` of the earliest root of
    the events that crossed in it, and of equal times the first event (as its stable sort orders them)."""
    from scipy.optimize import brentq

    roots = []
    for k, (a, b, d) in enumerate(zip(g_old, g_new, directions)):
        if _crossed(a, b, d):
            fun = events[k]
            roots.append((brentq(lambda tau: fun(tau, dense(tau)), t_old, t, xtol=4 * EPS, rtol=4 * EPS), k))
    return min(roots)


def integrate_segment(fun: Callable, t0: float, t_end: float, y0: np.ndarray, method: str,
                      events: Sequence[Callable], samples: np.ndarray, *, rtol: float, atol, max_step: float,
                      v_row: int | None = None, first_step: float | None = None,
                      long_step_s: float = LONG_STEP_S, restarts: LsodaRestarts | None = None) -> Segment:
    """Integrate ``fun`` from ``(t0, y0)`` to ``t_end`` or the first of the terminal ``events``.

    Parameters
    ----------
    fun : callable
        ``f(t, y)``.
    t0, t_end : float
        The segment [s].
    y0 : ndarray
        The states at ``t0``.
    method : str
        A ``scipy.integrate.solve_ivp`` method name ("LSODA", "RK45"...), or :data:`DOPRI5`.
    events : sequence of callable
        Event functions ``g(t, y)``, each with a ``direction`` attribute, all terminal.
    samples : ndarray
        Sorted times in ``[t0, t_end]`` to read the solution at (those after an event are not read).
    rtol, atol, max_step
        The solver's options.
    v_row : int, optional
        The row of the load's velocity: a step in which it changes sign (:func:`_turned`) is checked inside
        (:func:`missed_crossing`), as is any step longer than ``long_step_s`` (:data:`LONG_STEP_S`).
    first_step : float, optional
        The first step [s] of :data:`DOPRI5` and of ``"BDF"`` (None: estimated from the start); the other
        methods ignore it.
    restarts : LsodaRestarts, optional
        Where LSODA's solver is kept between the segments of a run (None: a new solver).

    Returns
    -------
    Segment
    """
    import scipy.integrate

    if method == DOPRI5:
        solver = DormandPrince(fun, t0, y0, t_end, rtol=rtol, atol=atol, max_step=max_step, first_step=first_step)
    elif method == "LSODA" and restarts is not None:
        solver = restarts.start(fun, float(t0), y0, float(t_end), rtol=rtol, atol=atol, max_step=max_step)
    else:
        first = {"first_step": min(first_step, t_end - t0)} if method == "BDF" and first_step else {}
        solver = getattr(scipy.integrate, method)(fun, float(t0), y0, float(t_end), rtol=rtol, atol=atol,
                                                  max_step=max_step, **first)
    from_next = method in _FROM_NEXT_STEP
    v_tol = None if v_row is None else float(atol[v_row] if np.ndim(atol) else atol)
    grid = samples.tolist()  # bisect on a list: a step's samples are few, and a numpy call costs more
    directions = [getattr(e, "direction", 0.0) for e in events]
    g = [e(solver.t, solver.y) for e in events]
    ts, ys = [solver.t], [solver.y]
    sample_ys, n_taken, status, event, message = [], 0, None, None, ""
    kept = None  # the last kept step's dense output, where a sample sits on its end (see below)
    while status is None:
        message = solver.step()
        if solver.status == "failed":
            status, message = -1, _failure_message(solver, message)
            break
        if not all(map(math.isfinite, solver.y.tolist())):
            # LSODA takes a step whose right-hand side was NaN and calls it a success: the run would go on,
            # or end, with NaN states.
            status, message = -1, (f"the state is not finite after the step from t = {solver.t_old:.9g} s to "
                                   f"{solver.t:.9g} s (the right-hand side returned NaN or overflowed)")
            break
        if solver.status == "finished":
            status = 0
        t_old, t, y = solver.t_old, solver.t, solver.y
        dense = None  # built only where something is read from it
        g_new = [e(t, y) for e in events]
        if events and any(map(_crossed, g, g_new, directions)):
            dense = _dense_of(solver)
            t, event = _earliest_event(events, directions, g, g_new, dense, t_old, t)
            y, status = dense(t), 1
        turned, dips = False, None
        v_old, v_new = (0.0, 0.0) if v_row is None else (float(ys[-1][v_row]), float(y[v_row]))
        if v_row is not None and abs(v_new) > v_tol:
            if v_old == 0.0:  # a slide from rest: turned if it ends moving against its motion early in the step
                dense = _dense_of(solver) if dense is None else dense
                turned = float(dense(t_old + (t - t_old) / LONG_STEP_CHECKS)[v_row]) * v_new < 0.0
            else:
                turned = _turned(v_old, v_new, v_tol)
        if events and status != 1 and not turned and v_old * v_new > 0.0:
            dense = _dense_of(solver) if dense is None else dense
            dips = _may_dip(events, directions, g, g_new, dense, t_old, t, atol)
        if events and (t - t_old > long_step_s or turned or dips):
            dense = _dense_of(solver) if dense is None else dense
            missed = missed_crossing(events, directions, g, dense, t_old, t, dips or ())
            if missed is not None:
                t, event = missed
                y, status = dense(t), 1
        g = g_new
        if t == ts[-1] and len(ts) > 1:
            continue  # no time passed: solve_ivp keeps neither the point nor its dense output
        # A sample on a step boundary is read from the step solve_ivp's piecewise solution reads it from:
        # for LSODA and BDF the one that starts there, unless that one is the last and has no time.
        n_step = (bisect_left if from_next and status is None else bisect_right)(grid, t)
        if n_step > n_taken:
            dense = _dense_of(solver) if dense is None else dense
            sample_ys.append(dense(samples[n_taken:n_step]))
            n_taken = n_step
        on_end = status is None and n_step < len(grid) and grid[n_step] == t
        kept = None if not on_end else _dense_of(solver) if dense is None else dense
        ts.append(t)
        ys.append(y)
    if status is not None and status >= 0 and kept is not None:
        n_end = bisect_right(grid, ts[-1])
        sample_ys.append(kept(samples[n_taken:n_end]))
        n_taken = n_end
    n = len(y0)
    last_step = ts[-1] - ts[-2] if len(ts) > 1 else None
    return Segment(t=np.array(ts, dtype=float), y=np.array(ys, dtype=float).T,
                   samples_t=samples[:n_taken],
                   samples_y=np.hstack(sample_ys) if sample_ys else np.empty((n, 0)),
                   status=status, event=event, t_event=float(t) if status == 1 else None,
                   y_event=np.array(y, dtype=float) if status == 1 else None,
                   nfev=solver.nfev, message=message or "", h_next=solver.h_next if method == DOPRI5 else last_step,
                   njev=getattr(solver, "njev", 0))


__all__ = ["DOPRI5", "DormandPrince", "LsodaRestarts", "Segment", "integrate_segment", "missed_crossing", "LONG_STEP_S",
           "LONG_STEP_CHECKS"]
