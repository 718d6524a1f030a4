"""Run a :class:`~pamsim.scenario.Scenario` through the FMU with fmpy.

Co-simulation is driven step by step through fmpy's ``FMU2Slave`` /
``FMU3Slave`` so that any (non-uniform) communication grid can be used;
every input jump of the scenario is a communication point.  Model exchange
uses ``fmpy.simulate_fmu`` with CVode, input jumps passed as duplicated time
points (fmpy's event convention).

The trace is turned into a :class:`~pamsim.result.Result` with the Python
model's force breakdown, so ``pamsim run --backend fmu-cs|fmu-me`` writes the
same CSV, JSON and plot as the Python backend.  The work integrals of the
energy balance are trapezoid sums over the sampled trace, and impact losses
are not itemised (the FMU does not report its events).
"""

from __future__ import annotations

import math
import shutil
import time
from pathlib import Path
from typing import Sequence

import numpy as np

from ..constants import PA_PER_BAR
from ..core_table import unimplemented_choice
from ..elements.pressure_source import ValveChamberSource
from ..errors import InputError, SolverFailure
from ..parameters import CHAMBER_DEFAULTS
from ..result import Result
from ..scenario import Scenario
from .build import temp_fmu
from .force_table import DEFAULT_POINTS, ForceTable, tabulate
from .muscle_spec import build, token
from .variables import (BY_NAME, DAMPING_CHOICES, FRICTION_CHOICES, INPUT_SOURCE_CHOICES, INPUTS, NEGATIVE_LEVEL,
                        SOURCE_CHOICES, STATIC_FORCE_CHOICES, VARIABLES, value_reference)

OUTPUTS = ("contraction_m", "velocity_m_s", "p_gauge_Pa", "chamber_pressure_abs_Pa", "air_mass_kg")


def cached_fmu(fmi_version: int = 2, force_table: ForceTable | None = None) -> Path:
    """An FMU built from the current sources (and ``force_table``), kept in the temp folder under its token."""
    return temp_fmu(token(fmi_version, force_table), f"pamsim_muscle_fmi{fmi_version}.fmu",
                    lambda path: build(path, fmi_version, force_table))


def tabulate_model(scenario: Scenario, points: tuple[int, int] = DEFAULT_POINTS, narrow: bool = True) -> ForceTable:
    """The scenario's static force tabulated for the FMU, over its valid domain: the contraction
    between the end stops and the gauge pressure from 0 to ``rated_pressure_gauge_Pa``, narrowed to
    the model's own ``domain`` where it declares one (``narrow``; else over the stops and the rating
    whatever the domain, as the python backend evaluates the model)."""
    model = scenario.build_model()
    # The raw library model: the C core clips a negative force itself, and a table of the clipped
    # force would smear its kink over a cell.
    force = scenario.static_model()
    x_lo, x_hi = model.stops.x_low_m, model.stops.x_high_m
    p_lo, p_hi = 0.0, float(scenario.parameters["rated_pressure_gauge_Pa"])
    domain = getattr(force, "domain", None) if narrow else None
    if domain is not None:
        x_lo, x_hi = max(x_lo, domain.x_min_m), min(x_hi, domain.x_max_m)
        p_lo, p_hi = max(p_lo, domain.p_min_Pa), min(p_hi, domain.p_max_Pa)
    return tabulate(force, (x_lo, x_hi), (p_lo, p_hi), points,
                    model_name=scenario.spec["model"]["static_force"])


def force_table_for(scenario: Scenario) -> ForceTable | None:
    """The force table the FMU needs for the scenario: none for the ACRA 2012 polynomial, which the
    C core computes exactly; any other static model as a table."""
    if scenario.spec["model"]["static_force"] == "acra2012_polynomial":
        return None
    return tabulate_model(scenario)


# The scenario keys the FMU represents, by section; any other key is refused (InputError) rather
# than dropped, so a setting added to scenarios later cannot silently run a different model.
# [solver] sets the Python integrator: the FMU's integrators are CVode at solver.rtol (ME) and its
# own Dormand-Prince 5(4) (CS), at solver.rtol (native_rtol_factor is the native backend's alone).  [controller] is read by pamsim.control, which designs the controller
# and runs its model through the FMU of its assembly (pamsim.fmu.assembly_runner), not this FMU.
# [chamber]: the polytropic law is this FMU's chamber; another law runs through the FMU of the scenario's
# assembly (pamsim.backends.simulate), which the check below lets through.
REPRESENTED = {
    "": {"name", "description", "model", "parameters", "load", "pressure", "simulation", "solver", "controller",
         "measured", "chamber", "compensation"},  # [measured] names what the figure draws beside the run, not the
    # model; [compensation] is a study (pamsim.hysteresis.compensation) that runs the scenario's closed loop
    "model": {"muscle", "parameter_set", "static_force", "static_force_negative", "friction", "damping",
              "friction_negative_level", "upper_stop"},
    "load": {"weight_N", "mass_kg", "external_force"},
    "pressure": {"source", "supply_gauge_bar", "supply_gauge_Pa", "valve_open_time_s", "command", "prescribed",
                 "initial_gauge_bar", "supply_port", "outlet_port", "spool", "inlet", "exhaust", "supply_C_m3_per_s_Pa",
                 "supply_b", "exhaust_C_m3_per_s_Pa", "exhaust_b"},  # supply_port, outlet_port: a line; the rest:
    # valves the FMU of the scenario's assembly carries (Scenario.beyond_one_muscle_fmu)
    "simulation": {"duration_s", "sample_rate_Hz", "initial_contraction_m"},
    "solver": {"method", "rtol", "max_events", "max_step_s", "native_rtol_factor", "stick_margin_N",
               "release_margin_N"},
    "chamber": set(CHAMBER_DEFAULTS),
}


def check_scenario(scenario: Scenario) -> None:
    """Raise :class:`~pamsim.errors.InputError` for a scenario the FMU backends cannot run: through this FMU
    (:func:`start_values`), or, for what it lacks (:attr:`Scenario.beyond_one_muscle_fmu`), through the
    FMU of its assembly (:func:`pamsim.backends.simulate` routes it there), which carries them and refuses,
    when it is built, an input it cannot carry."""
    if not scenario.beyond_one_muscle_fmu:
        start_values(scenario)


def _refuse_chamber_law(scenario: Scenario) -> None:
    """The one-muscle FMU has the polytropic chamber: another law is refused, naming the key."""
    if scenario.chamber_law != "polytropic":
        raise InputError(f"{scenario.origin}: chamber.law = {scenario.chamber_law!r}: the one-muscle FMU has the "
                         "polytropic chamber; pamsim.simulate runs this scenario through the FMU of its assembly")


def _refuse_unrepresented(scenario: Scenario) -> None:
    spec = scenario.spec
    for section, keys in REPRESENTED.items():
        table = spec if not section else spec.get(section, {})
        for key in table:
            if key not in keys:
                full = f"{section}.{key}" if section else key
                raise InputError(f"{scenario.origin}: the FMU cannot represent scenario key {full!r}; "
                                 "run it with the python backend")
    _refuse_chamber_law(scenario)
    model = spec["model"]
    if model["static_force_negative"] != "clip":
        raise InputError(f"{scenario.origin}: the FMU clips a negative static force at zero, "
                         f"not model.static_force_negative = {model['static_force_negative']!r}")
    # A muscle parameter that is not an FMU parameter (wall_thickness_m, E_bladder_Pa, ...) can only
    # shape the static force; the FMU gets it baked into the force table.
    lacking = unimplemented_choice(spec, skip=("static_force",))  # any static force: through the force table
    if lacking:
        raise InputError(f"{scenario.origin}: {lacking[0]} = {lacking[1]!r}: the C core does not implement it; "
                         "run it with the python backend")
    names = {v.name for v in VARIABLES if v.causality == "parameter" and v.kind == "real"}
    missing = [k for k in scenario.parameters if k not in names]
    if missing and model["static_force"] == "acra2012_polynomial":
        raise InputError(f"{scenario.origin}: the FMU has no parameter {missing[0]!r} "
                         f"(muscle {model['muscle']!r})")


def upper_stop_start(model) -> float:
    """The FMU's ``x_high_m`` for ``model``: its upper stop, or 0 where that is the braid lock, which the FMU
    then derives from its geometry parameters (so that changing them moves it, as before)."""
    stops = model.stops
    return 0.0 if stops.upper_basis == "braid_lock" else float(stops.x_high_m)


def start_values(scenario: Scenario) -> dict[str, float | int]:
    """The scenario's parameters and element choices as FMU start values.

    Raises :class:`~pamsim.errors.InputError` for a scenario setting the FMU cannot represent.
    """
    _refuse_unrepresented(scenario)
    model = scenario.spec["model"]
    pressure = scenario.spec["pressure"]
    names = {v.name for v in VARIABLES if v.causality == "parameter" and v.kind == "real"}
    values: dict[str, float | int] = {k: float(scenario.parameters[k]) for k in scenario.parameters if k in names}
    values["static_force_model"] = STATIC_FORCE_CHOICES.index(
        "acra2012_polynomial" if model["static_force"] == "acra2012_polynomial" else "table")
    values["friction_model"] = FRICTION_CHOICES.index(model["friction"])
    values["damping_model"] = DAMPING_CHOICES.index(model["damping"])
    values["friction_negative_level"] = NEGATIVE_LEVEL.index(model.get("friction_negative_level", "clamp"))
    values["pressure_source"] = SOURCE_CHOICES.index(pressure["source"])
    values["initial_contraction_m"] = scenario.initial_contraction_m
    values["initial_pressure_gauge_Pa"] = float(pressure.get("initial_gauge_bar", 0.0)) * PA_PER_BAR
    values["x_high_m"] = upper_stop_start(scenario.build_model())
    values["stick_margin_N"] = scenario.solver.stick_margin_N
    values["release_margin_N"] = scenario.solver.release_margin_N
    # The runner drives the inputs, also of an FMU built from a scenario (which starts on its signals).
    values["input_source"] = INPUT_SOURCE_CHOICES.index("importer")
    return values


class ScenarioInputs:
    """The scenario's input signals as FMU inputs: values at a time and the times they jump."""

    def __init__(self, scenario: Scenario):
        self.model = scenario.build_model()
        src = self.model.source
        self.valve = isinstance(src, ValveChamberSource)
        self.mass_kg = scenario.mass_kg
        self.breakpoints = sorted({float(b) for b in self.model.breakpoints if 0.0 < b < scenario.duration_s})

    def __call__(self, t_s: float) -> dict[str, float]:
        src = self.model.source
        values = {"load_mass_kg": self.mass_kg, "external_force_N": float(self.model.load.external_N(t_s)),
                  "valve_command": 0.0, "supply_pressure_gauge_Pa": 0.0, "prescribed_pressure_gauge_Pa": 0.0}
        if self.valve:
            u, supply = src.inputs(t_s)
            values["valve_command"] = float(u)
            values["supply_pressure_gauge_Pa"] = float(supply)
        else:
            values["prescribed_pressure_gauge_Pa"] = float(src.inputs(t_s)[0])
        return values


def _instantiate(fmu_path: Path, fmi_version: int, interface: str):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Model, FMU2Slave
    from fmpy.fmi3 import FMU3Model, FMU3Slave

    md = read_model_description(fmu_path)
    unzipdir = extract(fmu_path)
    classes = {(2, "cs"): FMU2Slave, (2, "me"): FMU2Model, (3, "cs"): FMU3Slave, (3, "me"): FMU3Model}
    cls = classes[fmi_version, interface]
    ident = md.coSimulation.modelIdentifier if interface == "cs" else md.modelExchange.modelIdentifier
    fmu = cls(guid=md.guid if fmi_version == 2 else md.instantiationToken, unzipDirectory=unzipdir,
              modelIdentifier=ident, instanceName="muscle")
    return md, fmu, unzipdir


def set_values(fmu, fmi_version: int, values: dict) -> None:
    """Set ``{name: value}`` on an fmpy instance: floats as Real / Float64, the rest as Integer
    (FMI 2.0) or, in FMI 3.0, Int32 and, for the Enumerations (integer choices), Int64."""
    groups: dict[str, dict[int, float | int]] = {"real": {}, "int": {}, "enum": {}}
    for k, v in values.items():
        group = "real" if isinstance(v, float) else "enum" if BY_NAME[k].choices and fmi_version == 3 else "int"
        groups[group][value_reference(k)] = v
    setters = {"real": fmu.setReal if fmi_version == 2 else fmu.setFloat64,
               "int": fmu.setInteger if fmi_version == 2 else fmu.setInt32,
               "enum": None if fmi_version == 2 else fmu.setInt64}
    for group, vrs in groups.items():
        if vrs:
            setters[group](list(vrs), list(vrs.values()))


def run_cs(scenario: Scenario, fmi_version: int = 2, communication_times: Sequence[float] | None = None,
           fmu_path: Path | None = None) -> dict[str, np.ndarray]:
    """Co-simulate ``scenario``; outputs sampled at ``communication_times`` (default: the scenario's
    sample grid).  Every input jump is added as a communication point.  Returns named arrays."""
    start = start_values(scenario)  # refuses what the FMU cannot represent before anything runs
    fmu_path = fmu_path or cached_fmu(fmi_version, force_table_for(scenario))
    inputs = ScenarioInputs(scenario)
    if communication_times is None:
        n = int(round(scenario.duration_s * scenario.solver.sample_rate_Hz))
        communication_times = np.linspace(0.0, scenario.duration_s, n + 1)
    grid = np.asarray(communication_times, dtype=float)
    times = np.union1d(grid, inputs.breakpoints)
    md, fmu, unzipdir = _instantiate(fmu_path, fmi_version, "cs")
    out_vrs = [value_reference(n) for n in OUTPUTS]
    mode_vr = [value_reference("friction_mode")]
    get_real = fmu.getReal if fmi_version == 2 else fmu.getFloat64
    get_int = fmu.getInteger if fmi_version == 2 else fmu.getInt32
    rows, modes = [], []
    try:
        fmu.instantiate()
        if fmi_version == 2:
            fmu.setupExperiment(startTime=times[0], stopTime=times[-1])
        set_values(fmu, fmi_version, start)
        set_values(fmu, fmi_version, inputs(times[0]))
        if fmi_version == 2:
            fmu.enterInitializationMode()
        else:
            fmu.enterInitializationMode(startTime=times[0], stopTime=times[-1])
        fmu.exitInitializationMode()
        for k, t in enumerate(times):
            rows.append(get_real(out_vrs))
            modes.append(get_int(mode_vr)[0])
            if k + 1 < len(times):
                # Inputs are held over a step; the midpoint value is the second-order choice for
                # smooth signals, and jumps fall on communication points.
                set_values(fmu, fmi_version, inputs(0.5 * (t + times[k + 1])))
                fmu.doStep(currentCommunicationPoint=t, communicationStepSize=times[k + 1] - t)
        fmu.terminate()
    except Exception as exc:  # fmpy raises a bare Exception carrying the FMI status
        raise SolverFailure(f"FMU co-simulation failed: {exc}") from None
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzipdir, ignore_errors=True)
    data = np.array(rows)
    keep = np.isin(times, grid)
    out = {name: data[keep, i] for i, name in enumerate(OUTPUTS)}
    out["t_s"] = times[keep]
    out["friction_mode"] = np.array(modes)[keep]
    return out


def run_me(scenario: Scenario, fmi_version: int = 2, fmu_path: Path | None = None,
           relative_tolerance: float | None = None) -> dict[str, np.ndarray]:
    """Model exchange with fmpy's CVode at the scenario's tolerance; outputs on the sample grid."""
    from fmpy import simulate_fmu

    start = start_values(scenario)
    fmu_path = fmu_path or cached_fmu(fmi_version, force_table_for(scenario))
    inputs = ScenarioInputs(scenario)
    dt = 1.0 / scenario.solver.sample_rate_Hz
    grid = np.linspace(0.0, scenario.duration_s, int(round(scenario.duration_s / dt)) + 1)
    # fmpy interpolates inputs linearly: sample smooth signals on the output grid and
    # duplicate the jump times (fmpy's convention for a discontinuity).
    bps = np.array(inputs.breakpoints)
    smooth = [t for t in grid if not np.any(np.abs(bps - t) < 1e-9)]
    t_in = sorted(smooth + 2 * list(bps))
    vals = []
    for j, t in enumerate(t_in):
        # At a duplicated time point the first row holds the value before the jump.
        left = j + 1 < len(t_in) and t_in[j + 1] == t
        vals.append(inputs(math.nextafter(t, -math.inf) if left else t))
    signals = np.array([tuple([t] + [v[n] for n in INPUTS]) for t, v in zip(t_in, vals)],
                       dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    try:
        res = simulate_fmu(str(fmu_path), fmi_type="ModelExchange", solver="CVode", start_time=0.0,
                           stop_time=scenario.duration_s, output_interval=dt,
                           relative_tolerance=relative_tolerance or scenario.solver.rtol,
                           start_values=start, input=signals, output=list(OUTPUTS) + ["friction_mode"],
                           validate=False)
    except Exception as exc:
        raise SolverFailure(f"FMU model exchange failed: {exc}") from None
    t = res["time"]
    on_grid, out_t = grid_rows(t, dt)
    out = {name: np.asarray(res[name][on_grid], dtype=float) for name in OUTPUTS}
    out["t_s"] = out_t
    out["friction_mode"] = np.asarray(res["friction_mode"][on_grid], dtype=int)
    return out


N_WORK_STATES = 4
"""The work integrals after the states: the muscle's, friction's, damping's and the external force's."""


def grid_rows(t_s: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The rows of an fmpy result (times ``t_s`` [s]) on the output grid of interval ``dt_s`` [s], and their
    grid times ``k dt_s`` [s].

    fmpy records both sides of an event at one time, and model exchange may record an event a few
    roundings after a grid time as well as the grid time (a load released 4e-10 s after the time event of a
    step at 0.5 s that opens a valve): of the rows within rounding of a grid time (1e-9 of the time or of
    the interval, the FMU's own tolerance for one instant), the last is kept (after the events), one row
    per grid time, at that grid time.
    """
    t = np.asarray(t_s, dtype=float)
    k = np.round(t / dt_s)
    idx = np.flatnonzero(np.abs(t - k * dt_s) <= 1e-9 * np.maximum(np.abs(t), dt_s))
    rows = idx[np.r_[k[idx][1:] != k[idx][:-1], True]]
    return rows, k[rows] * dt_s


def trace_stats(modes: np.ndarray, backend: str, rtol: float) -> dict:
    """A Result's solver statistics from an FMU trace: events counted as the mode changes between samples
    (the FMU does not report its events), no right-hand-side count."""
    n_events = int(np.count_nonzero(np.diff(modes)))
    return {"rhs_evaluations": 0, "events": n_events, "segments": n_events + 1, "method": backend, "rtol": rtol}


def to_result(scenario: Scenario, trace: dict[str, np.ndarray], wall_time_s: float, backend: str) -> Result:
    """A :class:`Result` from an FMU trace: its forces are the assembly's generated outputs at the FMU's
    states and modes (:class:`pamsim.assemblies.one_muscle.RigOutputs`, as the python and native
    backends' are), and its work integrals the trapezoidal integrals of their powers at the samples
    (the FMU does not carry them)."""
    from ..assemblies.one_muscle import RigOutputs, scenario_assembly

    model = ScenarioInputs(scenario).model
    t = trace["t_s"]
    states = [trace["contraction_m"], trace["velocity_m_s"]]
    if model.n_source:
        states += [trace["chamber_pressure_abs_Pa"], trace["air_mass_kg"]]
    modes = trace["friction_mode"].astype(int)
    Y = np.vstack([np.array(states), np.zeros((N_WORK_STATES, len(t)))])
    outputs = RigOutputs(scenario_assembly(scenario, model), model, t, Y, modes)
    sig = outputs.sampled()
    v = trace["velocity_m_s"]
    # the rates of the work integrals (pamsim.components): W_muscle, E_friction, E_damping, W_external
    power = [sig["F_static_N"] * v, -sig["F_friction_N"] * v, -sig["F_damping_N"] * v, sig["F_external_N"] * v]
    for k, pw in enumerate(power):
        Y[len(states) + k] = np.concatenate([[0.0], np.cumsum(0.5 * (pw[1:] + pw[:-1]) * np.diff(t))])
    stats = trace_stats(modes, backend, scenario.solver.rtol)
    return Result.from_trace(model, scenario.name, t, Y, modes, [], [], stats, wall_time_s, outputs=outputs)


def simulate_fmu(scenario: Scenario, interface: str = "cs", fmi_version: int = 2) -> Result:
    """Run ``scenario`` through the FMU (``interface`` "cs" or "me") and return a :class:`Result`."""
    if interface not in ("cs", "me"):
        raise InputError(f"FMU interface must be 'cs' or 'me', not {interface!r}")
    fmu_path = cached_fmu(fmi_version, force_table_for(scenario))
    wall0 = time.perf_counter()
    trace = run_cs(scenario, fmi_version, fmu_path=fmu_path) if interface == "cs" else \
        run_me(scenario, fmi_version, fmu_path=fmu_path)
    return to_result(scenario, trace, time.perf_counter() - wall0, f"fmu-{interface}")


def simulate_cs(scenario: Scenario) -> Result:
    """Backend ``fmu-cs``: FMI 2.0 co-simulation through fmpy."""
    return simulate_fmu(scenario, "cs")


def simulate_me(scenario: Scenario) -> Result:
    """Backend ``fmu-me``: FMI 2.0 model exchange through fmpy with CVode."""
    return simulate_fmu(scenario, "me")
