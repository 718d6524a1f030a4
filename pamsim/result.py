"""Simulation results: arrays with units in their names, summaries, balances, CSV."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .atomic import atomic_path
from .constants import PA_PER_BAR
from .elements.pressure_source import PrescribedPressure, ValveChamberSource
from .elements.pwm_average import AveragedPwmSource
from .model import N_WORK, Mode
from .signals import Constant, PiecewiseConstant, Pwm, Step

if TYPE_CHECKING:
    from .model import MuscleModel

CSV_BYTES_PER_VALUE = 17
"""Upper bound of one CSV value: ``%.10g`` writes at most 16 characters (``-1.234567891e-05``), plus a comma."""

REST_SPEED_M_S = 1e-4
"""A load in a slip mode slower than this, with the net force inside the friction band, counts as at rest."""


class Signals(Mapping):
    """``Result.signals``: the work integrals at once, the force breakdown and source outputs when
    first read, since a sweep reads only a few figures of each run and the breakdown costs more than a
    native run.  The forces are the generated outputs of the run's assembly where the backend ran one
    (``outputs``, :class:`pamsim.assemblies.one_muscle.RigOutputs`), else those of
    :meth:`MuscleModel.breakdown`; the source's own columns (its command, supply, air mass) come from
    the source."""

    def __init__(self, work: dict[str, np.ndarray], model: "MuscleModel", t, Y, modes, outputs=None, impacts=None):
        self._work = work
        self._trace = (model, t, Y, modes)
        self._outputs = outputs
        self._all: dict[str, np.ndarray] | None = None
        # (t_s, event times, losses): E_impacts_J, the last work integral, is summed when first read, since
        # filling a column per run costs as much as a native run's other columns together.
        self._impacts = impacts

    def _everything(self) -> dict[str, np.ndarray]:
        if self._all is None:
            model, t, Y, modes = self._trace
            if self._outputs is None:
                sig = model.breakdown(t, Y, modes)
                sig.pop("p_gauge_Pa")
            else:
                generated = self._outputs.sampled()
                own = model.source.outputs(t, Y[2:2 + model.n_source], Y[0])
                forces = {k: v for k, v in generated.items() if k.startswith("F_")}
                sig = {**forces, **{k: generated.get(k, v) for k, v in own.items()}, **generated}
            self._all = {**sig, **self._integrals()}
        return self._all

    def _integrals(self) -> dict[str, np.ndarray]:
        """The work integrals, ``E_impacts_J`` last (summed here if it was left to the first read)."""
        if self._impacts is not None:
            self._work["E_impacts_J"] = running_losses(*self._impacts)
            self._impacts = None
        return self._work

    def __getitem__(self, key: str) -> np.ndarray:
        work = self._integrals() if key == "E_impacts_J" else self._work
        return work[key] if key in work else self._everything()[key]

    def __iter__(self):
        return iter(self._everything())

    def __len__(self) -> int:
        return len(self._everything())


@dataclass(frozen=True)
class TransitionEvent:
    """A mode change: when, why, from and to which mode, at which contraction."""

    t_s: float
    kind: str
    from_mode: str
    to_mode: str
    x_m: float


@dataclass
class Result:
    """Trace of one simulation, sampled at the output rate.

    Attributes are numpy arrays named with their unit: ``t_s``, ``x_m``,
    ``v_m_s``, ``p_gauge_Pa``, ``mode`` (:class:`~pamsim.model.Mode` values),
    and ``signals``, a dict holding the force components (``F_static_N``,
    ``F_friction_N``, ``F_damping_N``, ``F_gravity_N``, ``F_external_N``,
    ``F_stop_N``, ``F_coulomb_level_N``), the work integrals and, for a valve
    source, ``air_mass_kg``, ``valve_mass_flow_kg_s``, ``valve_command``,
    ``supply_gauge_Pa`` and ``gas_temperature_K``.
    """

    name: str
    t_s: np.ndarray
    x_m: np.ndarray
    v_m_s: np.ndarray
    p_gauge_Pa: np.ndarray
    mode: np.ndarray
    signals: Mapping[str, np.ndarray]
    transitions: list[TransitionEvent]
    stats: dict
    wall_time_s: float
    mass_kg: float
    g_m_s2: float
    impact_loss_J: float
    final_rest_forces_N: tuple[float, float]
    fit_range_violations: list[str] = field(default_factory=list)
    peaks: dict[str, float] = field(default_factory=dict)
    """Largest ``x_m`` and ``p_gauge_Pa`` and smallest ``x_min_m`` of the integrated solution (every step and
    event), where the backend knows them; the samples may miss a peak between them."""
    model: "MuscleModel | None" = field(default=None, repr=False)
    warnings: list[str] = field(default_factory=list)
    """One line each: the fit-range violations and the signs of a pointless run
    (:func:`pointless_run_warnings`); ``pamsim run`` prints them on stderr, the run itself is kept."""

    @classmethod
    def from_trace(cls, model: "MuscleModel", name, t, Y, modes, transitions, impact_losses, stats, wall_time_s,
                   peaks: dict[str, float] | None = None, impacts_J: np.ndarray | None = None, outputs=None,
                   p_gauge_Pa: np.ndarray | None = None):
        """A Result from a sampled trace ``Y`` (one row per model state, one column per time ``t`` [s]).

        ``impact_losses`` lists ``(t_s, loss_J)`` of every event; ``impacts_J`` is their running sum
        at the samples [J] where the backend has it, else it is summed here.  ``outputs``: the run's
        generated outputs (:class:`pamsim.assemblies.one_muscle.RigOutputs`), which give the force
        columns and the forces at rest at the end; without them the composed model computes both.
        ``p_gauge_Pa``: ``model.pressure_trace_Pa(t, Y)`` where the backend has it (in memory of its own).
        """
        n = len(model.state_names)  # rows past them: the states of components added to the rig, by name
        work = {key: Y[n - N_WORK + i] for i, key in enumerate(model.state_names[-N_WORK:])}
        work.update(zip(outputs.added_states if outputs is not None else (), Y[n:]))
        loss_J = np.array([b for _, b in impact_losses])
        if impacts_J is not None:
            work["E_impacts_J"] = impacts_J
        sig = Signals(work, model, t, Y, modes, outputs,
                      None if impacts_J is not None else (t, [a for a, _ in impact_losses], loss_J))
        p = model.pressure_trace_Pa(t, Y) if p_gauge_Pa is None else p_gauge_Pa
        fr = model.fit_range
        peaks = dict(peaks or {})
        x_lo = min(peaks.get("x_min_m", np.inf), Y[0].min())
        x_hi = max(peaks.get("x_m", -np.inf), Y[0].max())
        p_hi = max(peaks.get("p_gauge_Pa", -np.inf), p.max())
        violations = []
        if x_lo < fr.x_min_m:
            violations.append(f"contraction down to {x_lo * 1e3:.2f} mm, below the fitted {fr.x_min_m * 1e3:.2f} mm")
        if x_hi > fr.x_max_m:
            violations.append(f"contraction up to {x_hi * 1e3:.2f} mm, above the fitted {fr.x_max_m * 1e3:.1f} mm")
        if p_hi > fr.p_max_gauge_Pa:
            violations.append(f"pressure up to {p_hi / 1e5:.3f} bar, above the fitted {fr.p_max_gauge_Pa / 1e5:.2f} bar")
        final = model.rest_forces(float(t[-1]), Y[:, -1]) if outputs is None else outputs.rest_forces()
        res = cls(name, t, Y[0], Y[1], p, modes, sig, transitions, stats, wall_time_s,
                  model.load.mass_kg, model.load.g_m_s2, float(loss_J.sum()), final, violations, peaks=peaks, model=model)
        res.warnings = ([f"left the static model's valid (fitted) range: {v}" for v in violations]
                        + pointless_run_warnings(model, t, res.at_rest_at_end, float(Y[1][-1])))
        return res

    # ------------------------------------------------------------------ queries
    @property
    def final_mode(self) -> Mode:
        """The friction/contact mode at the end of the run."""
        return Mode(int(self.mode[-1]))

    @property
    def at_rest_at_end(self) -> bool:
        """Held (stick or on a stop), or slower than ``REST_SPEED_M_S`` inside the friction band."""
        if not self.final_mode.is_slip:
            return True
        net, level = self.final_rest_forces_N
        return abs(self.v_m_s[-1]) < REST_SPEED_M_S and abs(net) <= level + 1e-3

    @property
    def on_stop(self) -> str | None:
        """``"upper"`` or ``"lower"`` when the run ends held on that end stop, else None."""
        return {Mode.STOP_HIGH: "upper", Mode.STOP_LOW: "lower"}.get(self.final_mode)

    @property
    def peak_contraction_m(self) -> float:
        """Largest contraction of the run: of the integrated solution where known, else of the samples."""
        return float(max(self.peaks.get("x_m", -np.inf), self.x_m.max()))

    @property
    def out_of_fit_range(self) -> bool:
        """Whether the run left the static model's valid domain (``fit_range_violations``)."""
        return bool(self.fit_range_violations)

    def energy_balance(self) -> dict[str, float]:
        """Work of the muscle and external force against the energy the load gained and lost [J].

        ``residual_J`` = work in - (kinetic + potential gain + friction + damping + impacts);
        ``relative`` divides it by the largest term.  A component added to the rig brings its own
        terms, by their namespaced names: ``W_`` work it did on the load, ``E_`` energy it took.
        """
        s = self.signals
        d_ke = 0.5 * self.mass_kg * (self.v_m_s[-1] ** 2 - self.v_m_s[0] ** 2)
        d_pe = self.mass_kg * self.g_m_s2 * (self.x_m[-1] - self.x_m[0])
        terms = {"W_muscle_J": float(s["W_muscle_J"][-1]), "W_external_J": float(s["W_external_J"][-1]),
                 "dKE_J": float(d_ke), "dPE_J": float(d_pe), "E_friction_J": float(s["E_friction_J"][-1]),
                 "E_damping_J": float(s["E_damping_J"][-1]), "E_impacts_J": float(s["E_impacts_J"][-1])}
        # A component added to the rig reports the work it does on the load (W_...) or takes from it (E_...).
        added = {k: float(v[-1]) for k, v in s.items() if "." in k and k.split(".", 1)[1][:2] in ("W_", "E_")}
        terms.update(added)
        residual = (terms["W_muscle_J"] + terms["W_external_J"] - terms["dKE_J"] - terms["dPE_J"]
                    - terms["E_friction_J"] - terms["E_damping_J"] - terms["E_impacts_J"]
                    + sum(v if k.split(".", 1)[1].startswith("W_") else -v for k, v in added.items()))
        scale = max(abs(v) for v in terms.values()) or 1.0
        return {**terms, "residual_J": float(residual), "relative": float(abs(residual) / scale)}

    def damping_energy_note(self) -> str:
        """Why ``E_damping_J`` is negative (the damping added energy), or "" when it took energy as damping does."""
        E = float(self.signals["E_damping_J"][-1])
        if E >= 0.0:
            return ""
        damping = getattr(self.model, "damping", None)
        D1, D2 = getattr(damping, "D1_N_s_per_m", None), getattr(damping, "D2_N_s2_per_m2", None)
        why = "the damping law pushes the motion at some speeds"
        if D1 is not None and D1 < 0.0:
            why = f"the paper's D1 = {D1:g} N s/m < 0 pushes the motion"
            if D2 is not None and D2 > 0.0:
                why += f" below {-D1 / D2:.3g} m/s"
        return f"the damping added {-E:.3g} J (E_damping_J < 0): {why}"

    def summary(self) -> dict:
        """The figures ``pamsim run`` writes to its JSON file."""
        s = {
            "scenario": self.name,
            "final_contraction_m": float(self.x_m[-1]),
            "peak_contraction_m": self.peak_contraction_m,
            "final_velocity_m_s": float(self.v_m_s[-1]),
            "final_pressure_gauge_Pa": float(self.p_gauge_Pa[-1]),
            "peak_pressure_gauge_Pa": float(max(self.peaks.get("p_gauge_Pa", -np.inf), self.p_gauge_Pa.max())),
            "final_mode": self.final_mode.label,
            "at_rest_at_end": bool(self.at_rest_at_end),
            "on_stop": self.on_stop,
            "final_net_force_N": float(self.final_rest_forces_N[0]),
            "final_coulomb_level_N": float(self.final_rest_forces_N[1]),
            "events": int(self.stats["events"]),
            # an FMU's own solver does not report its evaluations: not counted (null), rather than 0
            "rhs_evaluations": (None if str(self.stats.get("method", "")).startswith("fmu")
                                else int(self.stats["rhs_evaluations"])),
            "segments": int(self.stats["segments"]),
            # what the backend counts: an FMU's runs count no Jacobians
            **{k: self.stats[k] for k in ("jacobians", "method", "rtol") if k in self.stats},
            "wall_time_s": float(self.wall_time_s),
            "out_of_fit_range": self.out_of_fit_range,
            "fit_range_violations": list(self.fit_range_violations),
            "warnings": list(self.warnings),
            "energy_balance": self.energy_balance(),
        }
        note = self.damping_energy_note()
        if note:
            s["energy_balance_note"] = note
        return s

    # ------------------------------------------------------------------ output
    @classmethod
    def csv_bytes_estimate(cls, model: "MuscleModel", n_samples: int) -> int:
        """Upper bound [bytes] of the CSV of a run of ``model`` with ``n_samples`` samples.

        The columns are those of a one-sample result of the same model, each
        value at most :data:`CSV_BYTES_PER_VALUE` bytes.
        """
        y0 = model.initial_state()
        one = cls.from_trace(model, "", np.zeros(1), y0[:, None], np.zeros(1, dtype=int), [], [],
                             {"events": 0, "rhs_evaluations": 0, "segments": 0}, 0.0)
        return int(n_samples) * len(one.columns()) * CSV_BYTES_PER_VALUE

    def columns(self) -> dict[str, np.ndarray]:
        """Every column of the CSV by name: time, contraction, velocity, pressure, mode and the signals."""
        cols = {"t_s": self.t_s, "x_m": self.x_m, "v_m_s": self.v_m_s, "p_gauge_Pa": self.p_gauge_Pa,
                "mode": self.mode}
        cols.update(self.signals)
        return cols

    def to_csv(self, path) -> None:
        """Write the trace; the first columns are ``t_s,x_m,v_m_s,p_gauge_Pa``. Atomic."""
        write_columns(path, self.columns())

    def valve_panel(self) -> "tuple[str, list[tuple[str, str]]] | None":
        """The run figure's valve panel, for a run whose valve follows a PWM command (its opening, each
        valve's of a pair, or the averaged valve's duty) or is a spool valve (its command and position): its
        y label and its ``(signal, legend label)`` lines; None for any other run (a plain step or steps)."""
        signals = self.signals
        if "spool_position" in signals:
            return ("spool / stroke [-]\n(+1 supply, -1 exhaust)",
                    [("valve_command", "command"), ("spool_position", "position")])
        source = getattr(self.model, "source", None)
        if source is None or "valve_command" not in signals:
            return None
        if isinstance(source, AveragedPwmSource):
            return "PWM duty [-]", [("valve_command", "duty (averaged valve)")]
        inlet, exhaust = getattr(source, "command", None), getattr(source, "exhaust_command", None)
        averaged_inlet = getattr(source, "averaged_inlet", None)  # a pair's inlet run by its mean opening
        if not any(isinstance(c, Pwm) for c in (inlet, exhaust, averaged_inlet)):
            return None
        if "exhaust_command" in signals:
            what = (_pwm_text(averaged_inlet, ", mean over a period") if isinstance(averaged_inlet, Pwm)
                    else _pwm_text(inlet))
            return ("valve opening [-]\n(0 shut, 1 open)",
                    [("valve_command", f"inlet{what}"), ("exhaust_command", f"exhaust{_pwm_text(exhaust)}")])
        return "valve opening [-]\n(+1 supply, -1 exhaust)", [("valve_command", f"valve{_pwm_text(inlet)}")]

    def plot(self, path=None, dpi: int | None = None, **kwargs):
        """Plot contraction, pressure and forces; write them to ``path`` if given, as PNG, PDF or SVG by its
        suffix, at ``dpi`` dots per inch (default 110).  See :func:`pamsim.plotting.plot_result`."""
        from .plotting import plot_result

        return plot_result(self, path, dpi=dpi, **kwargs)


def _pwm_text(command, note: str = "") -> str:
    """A PWM command's frequency and duty in brackets after a space, with whether it is inverted (a
    complementary exhaust's: at its high level, shut, for the duty) and ``note``; empty for any other command."""
    if not isinstance(command, Pwm):
        return ""
    inverted = ", inverted" if command.high < command.low else ""
    return f" (PWM {command.frequency_Hz:g} Hz, duty {command.duty:g}{inverted}{note})"


def write_columns(path, cols: dict) -> None:
    """Write ``cols`` (name: values at the samples) as a CSV, one column each, 10 significant digits. Atomic."""
    data = np.column_stack([np.asarray(v, dtype=float) for v in cols.values()])
    with atomic_path(path) as tmp:
        np.savetxt(tmp, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")


def running_losses(t_s: np.ndarray, loss_t_s, loss_J: np.ndarray) -> np.ndarray:
    """At each time of ``t_s`` (ascending), the sum of the losses ``loss_J`` of the events at ``loss_t_s``
    (ascending) at or before it: ``cumsum(loss_J)[k - 1]`` from the first time at or after event k's
    (0 before the first event).  Each sum fills the samples from its event's first to the next one's,
    so that a run of thousands of samples and a few events costs a few searches, not one per sample."""
    out = np.empty(len(t_s))
    bounds = [0, *np.searchsorted(t_s, loss_t_s, side="left").tolist(), len(t_s)]
    for k, value in enumerate([0.0, *np.cumsum(loss_J).tolist()]):
        out[bounds[k]:bounds[k + 1]] = value
    return out


def _opens_in_run(command, t_s: np.ndarray) -> bool:
    """Whether ``command`` rises above 0 (opens the valve to the supply) before the run's end: at a sample,
    or for a PWM anywhere in its trace (a pulse may open it between two samples)."""
    if isinstance(command, Pwm):
        opens_s = _first_opening_s(command)
        return opens_s is not None and opens_s < float(t_s[-1])
    # ndarray methods, not np.any: the same reduction without numpy's dispatch, run after run
    return bool((np.asarray(at_samples(command, t_s)) > 0.0).any())


def _closed_valve_warning(command, t_end: float, key: str = "pressure.command") -> str:
    """Why a valve whose command never rises above 0 (closed, or a 3/2 valve's exhaust side) kept the muscle
    from its supply: a step or a first opening after the run's end, a PWM whose high level does not open it,
    or PWM pulses too short for the valve's delays and opening time (the command is the opening the valve
    reaches, :class:`~pamsim.signals.Pwm`)."""
    if isinstance(command, Pwm) and command.duty > 0.0 and command.start_s < t_end:
        if command.high <= 0.0:
            return (f"the valve never opens toward the supply: its PWM command's high level, "
                    f"{key}.high = {command.high:g}, is at or below 0 (1 opens it to the supply)")
        opens_s = _first_opening_s(command)
        if opens_s is None:
            return _short_pulses_warning(command, key)
        return (f"the valve first opens at {opens_s:.4g} s (its PWM starts at {command.start_s:g} s, its opening "
                f"delay is {command.delay_on_s * 1e3:.4g} ms), not before the run ends at {t_end:g} s: the muscle "
                "never sees the supply (raise simulation.duration_s or start the PWM earlier)")
    opens = getattr(command, "time_s", None)  # a step's opening time
    when = f"opens at {opens:g} s, after the run ends at {t_end:g} s" if opens is not None else \
        f"stays closed (command <= 0) until the run ends at {t_end:g} s"
    return (f"the valve {when}: the muscle never sees the supply "
            "(raise simulation.duration_s or open the valve earlier)")


def _first_opening_s(command: Pwm) -> float | None:
    """When the PWM's whole trace (to its ``end_s``, whatever the run's end) first rises above 0, or None."""
    t, level = command.knots_t_s, command.knots
    for k in range(1, len(level)):
        if level[k] > 0.0 >= level[k - 1]:
            return t[k - 1] + (t[k] - t[k - 1]) * (0.0 - level[k - 1]) / (level[k] - level[k - 1])
    return None


def _short_pulses_warning(command: Pwm, key: str) -> str:
    """A PWM whose pulses never move the valve past closed: each moves it toward the supply for the pulse less
    the opening delay plus the closing delay, too short for its opening to get past its middle (a 3/2 valve,
    ``low`` < 0), or no time at all (a 2/2 valve: the opening delay outlasts the pulse and the closing delay)."""
    period_ms = 1e3 / command.frequency_Hz
    pulse_ms = command.duty * period_ms
    moving_ms = max(pulse_ms + 1e3 * (command.delay_off_s - command.delay_on_s), 0.0)
    timing = (f"the pulse, less its {command.delay_on_s * 1e3:.4g} ms opening delay, plus its "
              f"{command.delay_off_s * 1e3:.4g} ms closing delay")
    if command.low < 0.0:
        need_ms = 1e3 * command.rise_s * -command.low / (command.high - command.low)
        side = "toward the supply past its middle (it only vents)"
        why = (f"for {moving_ms:.4g} ms ({timing}), too short for the {need_ms:.4g} ms its "
               f"{command.rise_s * 1e3:.4g} ms opening takes from exhaust to its middle")
    else:
        side, why = "at all", f"for no time ({timing}): it never starts to open"
    return (f"the valve never opens {side}: each PWM pulse, {pulse_ms:.4g} ms of a {period_ms:.4g} ms period at "
            f"{command.frequency_Hz:g} Hz, moves it toward the supply {why}; the muscle never sees the supply "
            f"(lower {key}.frequency_Hz or raise its duty)")


def pointless_run_warnings(model, t_s: np.ndarray, at_rest_at_end: bool, v_end_m_s: float) -> list[str]:
    """The valve never opens, the load is beyond the blocked force, or the load still moves at the end."""
    t_end = float(t_s[-1])
    out = []
    src = model.source
    # ndarray methods, not np.any and np.max: the same reductions without numpy's dispatch, run after run
    if isinstance(src, ValveChamberSource) and not _opens_in_run(src.command, t_s):
        # A pair's inlet is the valve that opens to the supply: its command is pressure.inlet's.
        key = "pressure.inlet.command" if hasattr(src, "exhaust_command") else "pressure.command"
        out.append(_closed_valve_warning(src.command, t_end, key))
    supply = _largest_supply_Pa(src, t_s)
    if supply is not None:
        blocked = float(model.static_force.force_N(0.0, supply))
        weight = model.load.weight_N
        external = model.load.external_force_N
        if weight > blocked + (float(np.asarray(at_samples(external, t_s)).max()) if external is not None else 0.0):
            out.append(f"the load, {weight:.4g} N, is beyond the muscle's blocked force at the supply pressure, "
                       f"{blocked:.4g} N at {supply / PA_PER_BAR:.4g} bar: it cannot lift it")
    if not at_rest_at_end:
        out.append(f"still moving at the end ({v_end_m_s * 1e3:.3g} mm/s at {t_end:g} s): the run ends before the "
                   "load settles (raise simulation.duration_s)")
    return out


def _largest_supply_Pa(source, t_s: np.ndarray) -> float | None:
    """Highest gauge pressure [Pa] the source offers during the run: the valve's supply or the prescribed
    pressure; None for a source driven by something else (a controller)."""
    if isinstance(source, ValveChamberSource):
        return float(np.asarray(at_samples(source.supply_gauge_Pa, t_s)).max())
    if isinstance(source, PrescribedPressure):
        return float(np.asarray(at_samples(source.p_gauge_Pa, t_s)).max())
    return None


_PIECEWISE_CONSTANT = (Constant, Step, PiecewiseConstant)


def at_samples(signal, t_s: np.ndarray) -> np.ndarray:
    """The values ``signal`` takes at the samples ``t_s`` (ascending): ``signal(t_s)``, or for a
    piecewise-constant signal, which changes only at its breakpoints and from them on, its values at
    the first sample and at the first sample at or after each breakpoint: the same values, without
    evaluating it at thousands of samples to take their largest."""
    if type(signal) in _PIECEWISE_CONSTANT and len(t_s):  # a subclass may change between breakpoints
        breakpoints = signal.breakpoints
        # no breakpoints (a constant): the first sample alone, without a search
        t_s = t_s[sorted({0, *t_s.searchsorted(breakpoints, side="left").tolist()} - {len(t_s)})] if breakpoints \
            else t_s[:1]
    return signal(t_s)
