"""Scenarios: a TOML file (or a dict) that names a muscle, overrides of its
parameters, the static force model and the other element choices, the load, the pressure source, the duration and the
solver settings.  The schema is documented in ``docs/scenarios.md``.

Every mistake raises :class:`ScenarioError` naming the file, the key and the
offending value; the CLI turns it into a one-line message and exit code 2.
"""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping


from .assemblies.one_muscle import source_parts
from .constants import PA_PER_BAR
from .errors import InputError
from .elements.chamber import CHAMBER_LAWS, IsothermalChamber, MuscleChamber, ThermalChamber
from .elements.damping import DAMPING_MODELS
from .elements.friction import FRICTION_MODELS, NEGATIVE_LEVEL_CHOICES, NoCoulomb
from .elements.load import HangingLoad
from .elements.pressure_source import LineValveSource, PrescribedPressure, ValveChamberSource
from .elements.pwm_average import PWM_MODELS, averaged_source, mean_opening_signal
from .elements.spool import spool_source
from .elements.force_clip import NEGATIVE_FORCE_CHOICES
from .elements.static_force import STATIC_FORCE_MODELS
from .elements.stops import UPPER_STOPS, EndStops
from .elements.valve import Iso6358Orifice, OnOffValvePair, ProportionalValve33
from .elements.valve_pair import VALVE_DEFAULTS, ValvePairSource
from .model import FitRange, MuscleModel
from .muscle_setup import applicable_model, model_inputs, with_overrides
from .muscles import Muscle, load_muscle, shipped_names
from .paperdata import STEADY_STATE_SETS, SteadyState, steady_state
from .parameters import CHAMBER_DEFAULTS, CHAMBER_LAW_KEYS, LOAD_MASS, ParameterSet, dynamics_parameters
from .scenario_components import added_components, check_pressure_ports, check_wiring, hysteresis_component
from .static_models import REGISTRY
from .signal_tables import VALVE_TIMING, on_off_command, signal_from_table, signal_range
from .signals import Constant, Step
from .simulator import MIN_MAX_STEP_S, MIN_RTOL, NATIVE_RTOL_FACTOR, SolverOptions
from .table_checks import TableChecker, choices_hint, did_you_mean, value_phrase


# Schema: section -> {key: (type, required)}; a nested dict is a sub-table.
_SCHEMA: dict[str, dict[str, Any]] = {
    "": {"name": str, "description": str, "model": dict, "parameters": dict, "load": dict, "pressure": dict,
         "simulation": dict, "solver": dict, "controller": dict, "component": list, "measured": dict,
         "chamber": dict, "hysteresis": dict, "compensation": dict, "motion": dict},
    "model": {"muscle": str, "parameter_set": str, "static_force": str, "static_force_variant": str,
              "static_force_negative": str, "friction": str, "damping": str, "friction_negative_level": str,
              "upper_stop": str},
    "load": {"weight_N": float, "mass_kg": float, "external_force": dict},
    "pressure": {"source": str, "supply_gauge_bar": float, "supply_gauge_Pa": float, "valve_open_time_s": float,
                 "command": dict, "prescribed": dict, "initial_gauge_bar": float, "supply_port": str,
                 "outlet_port": str, "spool": dict, "inlet": dict, "exhaust": dict, "supply_C_m3_per_s_Pa": float,
                 "supply_b": float, "exhaust_C_m3_per_s_Pa": float, "exhaust_b": float},
    "simulation": {"duration_s": float, "sample_rate_Hz": float, "initial_contraction_m": float},
    "solver": {"method": str, "rtol": float, "max_events": int, "max_step_s": float, "native_rtol_factor": float,
               "stick_margin_N": float, "release_margin_N": float},
    "measured": {"steady_state": str},
    "chamber": {"law": str, **{key: float for key in CHAMBER_DEFAULTS if key != "law"}},
}
NO_LOAD_MASS_KG = 1.0
"""The mass [kg] of the hanging load a scenario without one (a muscle driven by its length, ``[motion]``)
puts in its :class:`~pamsim.model.MuscleModel`, which has a load by construction.  No run of such a
scenario reads it: the muscle alone (:mod:`pamsim.assemblies.muscle_only`) has no load, and its friction
law's mass is the static force over g."""
_MAX_SAMPLES = 1e7  # 8 s at 1 kHz is 8,001; beyond this the output would not fit in memory comfortably
MAX_STEPS = 1e7
"""``solver.max_step_s`` may not ask for more steps than this over the run (minutes of computing)."""
_METHODS = ("LSODA", "RK45", "DOP853", "Radau", "BDF", "RK23", "DOPRI5")


class ScenarioError(InputError):
    """A scenario that cannot be run; the message names file, key and value."""


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.  Build one with :func:`load_scenario` or :meth:`from_dict`.

    ``spec`` is the validated dict (the TOML content); ``muscle`` the muscle it
    names; ``parameters`` the muscle's parameters completed with the dynamics'
    defaults, with the scenario's overrides applied.
    """

    name: str
    spec: Mapping[str, Any] = field(repr=False)
    parameters: ParameterSet = field(repr=False)
    duration_s: float
    solver: SolverOptions
    base_dir: Path = field(default=Path("."), repr=False)
    origin: str = "<dict>"
    muscle: Muscle | None = field(default=None, repr=False)

    # ------------------------------------------------------------ construction
    @classmethod
    def from_dict(cls, spec: Mapping[str, Any], name: str | None = None, base_dir: str | Path = ".",
                  origin: str = "<dict>") -> "Scenario":
        """Validate ``spec`` (the same structure as a TOML file) and return a Scenario."""
        return cls._from_own_dict(copy.deepcopy(dict(spec)), name, base_dir, origin)

    @classmethod
    def _from_own_dict(cls, spec: dict, name: str | None, base_dir: str | Path, origin: str) -> "Scenario":
        """:meth:`from_dict` of a dict nobody else holds (it is completed in place and kept)."""
        v = _Validator(origin, Path(base_dir))
        _check_sections(v, spec)
        model = spec.setdefault("model", {})
        muscle = _muscle(v, model)
        _default_choices(v, model)
        params = with_overrides(dynamics_parameters(muscle.parameters), spec.get("parameters", {}), v.fail, _key,
                                f"override in {origin}")
        applicable_model(model.setdefault("static_force", muscle.default_static_force),
                         model.get("static_force_variant"), muscle, model_inputs(muscle, params), v.fail, _key)
        duration, sample_rate, x0 = _simulation(v, spec["simulation"])
        opts = _solver_options(v, spec.get("solver", {}), duration, sample_rate)
        name = _checked_name(v, name or spec.get("name") or "scenario")
        scenario = cls(name, spec, params, duration, opts, Path(base_dir), origin, muscle)
        if duration * sample_rate > _MAX_SAMPLES:
            v.fail("simulation.sample_rate_Hz", sample_rate,
                   f"with duration_s = {duration:g} this asks for more than {_MAX_SAMPLES:.0e} output samples")
        scenario._check_load(v)
        scenario._build_elements(v, x0)
        return scenario

    def with_changes(self, changes: Mapping[str, Mapping[str, Any]], name: str | None = None) -> "Scenario":
        """A new scenario with some keys of some sections replaced (for sweeps and scripts).

        Keys are merged into each section, except that a change of
        ``pressure.source`` replaces the whole ``[pressure]`` table (the keys of
        one source mean nothing to the other), a change of ``chamber.law`` the whole
        ``[chamber]`` table (likewise), and naming one of a pair of
        alternatives (``weight_N``/``mass_kg``, ``supply_gauge_bar``/``supply_gauge_Pa``,
        ``muscle``/``parameter_set``) drops the other.  A new muscle without a
        new ``static_force`` takes its own default model if the old muscle ran its default.
        """
        spec = copy.deepcopy(dict(self.spec))
        for section, values in changes.items():
            spec[section] = self._changed_section(section, spec.get(section, {}), values)
        return Scenario._from_own_dict(spec, name or self.name, self.base_dir, self.origin)

    def _changed_section(self, section: str, old: dict, values: Mapping[str, Any]) -> dict:
        """The table ``old`` of ``section`` with ``values`` merged in, less the keys they replace."""
        if section == "pressure" and "source" in values and values["source"] != old.get("source"):
            old = {}
        if section == "chamber" and "law" in values and values["law"] != old.get("law", CHAMBER_DEFAULTS["law"][0]):
            old = {}  # the keys of one law mean nothing to another
        if section == "model" and ({"muscle", "parameter_set"} & set(values)):
            old = self._model_without_muscle(old, values)
        return _without_alternatives({**old, **copy.deepcopy(dict(values))}, values)

    def _model_without_muscle(self, model: dict, values: Mapping[str, Any]) -> dict:
        """``[model]`` less its muscle, and less its static force if that is the old muscle's default and
        ``values`` names none (the new muscle then takes its own default)."""
        model = {k: v for k, v in model.items() if k not in ("muscle", "parameter_set")}
        if "static_force" not in values and model.get("static_force") == self.muscle.default_static_force:
            model.pop("static_force", None)
            model.pop("static_force_variant", None)
        return model

    # ------------------------------------------------------------ model build
    @property
    def mass_kg(self) -> float:
        """Mass of the load [kg], given or from its weight."""
        load = self.spec.get("load")
        if load is None:  # a muscle driven by its length
            return NO_LOAD_MASS_KG
        return load["mass_kg"] if "mass_kg" in load else load["weight_N"] / self.parameters["g_m_s2"]

    @property
    def final_pressure_gauge_Pa(self) -> float:
        """Supply pressure of the valve, or the final prescribed pressure [Pa gauge]."""
        src = self._source
        signal = src.supply_gauge_Pa if isinstance(src, ValveChamberSource) else src.p_gauge_Pa
        return float(signal.final_value)

    def _check_load(self, v: "_Validator") -> None:
        if "load" not in self.spec:  # a muscle driven by its length ([motion]; _check_sections)
            return
        load = self.spec["load"]
        if ("weight_N" in load) == ("mass_kg" in load):
            raise ScenarioError(f"{self.origin}: [load] needs exactly one of weight_N or mass_kg")
        key = "weight_N" if "weight_N" in load else "mass_kg"
        value = v.number(f"load.{key}", load[key])
        if value <= 0:
            v.fail(f"load.{key}", value, "must be positive")
        why = LOAD_MASS.violation(self.mass_kg)  # the FMU's load_mass_kg input has the same range
        if why:
            v.fail(f"load.{key}", value, f"the mass {self.mass_kg:g} kg {why} kg")

    def _build_elements(self, v: "_Validator", x0: float) -> None:
        """Build the pressure source, external force, static force and added components once, here, so that
        a bad pressure section, trace file or external force fails now, not at run time."""
        ext = self.spec.get("load", {}).get("external_force")
        object.__setattr__(self, "_source", self._build_source(v))
        object.__setattr__(self, "_external_force",
                           signal_from_table(v, "load.external_force", ext, "_N", 1.0, self.base_dir) if ext else None)
        stops = self._end_stops(v)
        object.__setattr__(self, "_stops", stops)
        if not stops.x_low_m <= x0 <= stops.x_high_m:
            v.fail("simulation.initial_contraction_m", x0, f"must lie between the stops, 0 and {stops.x_high_m:.4f} m")
        try:
            object.__setattr__(self, "_static_force", self._build_static_force())
        except ValueError as exc:  # an implicit model that cannot be tabulated over the muscle's range
            v.fail("model.static_force", self.spec["model"]["static_force"], str(exc))
        added = added_components(v, self.spec.get("component", []))
        if "hysteresis" in self.spec:
            m = self.spec["model"]
            added += (hysteresis_component(v, self.spec["hysteresis"], FRICTION_MODELS[m["friction"]](self.parameters, m),
                                           source_parts(self._source, None).pressure, added),)
            object.__setattr__(self, "solver", self._margins_without_coulomb())
        check_pressure_ports(v, self.spec.get("pressure", {}), added)
        object.__setattr__(self, "_added", added)
        if self._added or isinstance(self._source, LineValveSource):
            check_wiring(self, ScenarioError)

    def _margins_without_coulomb(self) -> SolverOptions:
        """The solver's options with the load's stick and release margins for a rig whose friction is a
        ``[hysteresis]`` model's alone.

        The load then has no Coulomb level of its own: it sticks where its velocity reaches zero with a net
        force within the stick margin, and only the elements' springs and dampers bring it to rest, the
        swing decaying for ever.  The margins of the Coulomb rig (1e-7 N) lie far below what the integrator
        resolves of the forces, so the swing was followed, and a held load released and stuck again on the
        integrator's noise in the pressure, long after it had come to rest within the tolerance.  Here the
        load is held where its net force is within ``rtol`` of its weight (the forces' resolution at the
        integrator's tolerance) and released at twice that (docs/hysteresis.md, "Where the load rests")."""
        if {"stick_margin_N", "release_margin_N"} & set(self.spec.get("solver", {})):
            return self.solver  # the scenario's own
        resolution_N = self.solver.rtol * self.mass_kg * self.parameters["g_m_s2"]
        return replace(self.solver, stick_margin_N=resolution_N, release_margin_N=2.0 * resolution_N)

    @property
    def upper_stop(self) -> str:
        """Where the upper stop stands (:data:`pamsim.elements.stops.UPPER_STOPS`): ``[model] upper_stop``,
        else the muscle file's choice."""
        return self.spec["model"].get("upper_stop", self.muscle.upper_stop)

    def _end_stops(self, v: "_Validator") -> EndStops:
        """The stops of the scenario's muscle and static model; a choice that cannot be met fails naming its key."""
        try:
            return EndStops.for_model(self.parameters, self.static_model().domain.x_max_m, self.upper_stop)
        except ValueError as exc:
            if "upper_stop" in self.spec["model"]:
                v.fail("model.upper_stop", self.upper_stop, str(exc))
            v.fail("model.muscle", self.spec["model"]["muscle"], f"its upper stop ({self.upper_stop}): {exc}")

    def _build_source(self, v: "_Validator"):
        pr = self.spec["pressure"]
        source = v.required(pr, "source", prefix="pressure.")
        if not isinstance(source, str):
            v.fail("pressure.source", source, "must be a string", choices=("valve", "prescribed"))
        if source == "valve":
            return self._valve_source(v, pr)
        if source == "prescribed":
            return self._prescribed_source(v, pr)
        v.fail("pressure.source", source, "unknown source", choices=("valve", "prescribed"))

    def _valve_source(self, v: "_Validator", pr: Mapping[str, Any]) -> ValveChamberSource:
        p = self.parameters
        v.allowed("pressure", pr, {"source", "supply_gauge_bar", "supply_gauge_Pa", "valve_open_time_s",
                                   "command", "initial_gauge_bar", "supply_port", "outlet_port", "spool", "inlet",
                                   "exhaust", *PATH_KEYS})
        supply = self._supply_gauge_Pa(v, pr)
        if "initial_gauge_bar" in pr:
            rating = p["rated_pressure_gauge_Pa"]
            p0 = v.number("pressure.initial_gauge_bar", pr["initial_gauge_bar"]) * PA_PER_BAR
            if not 0.0 <= p0 <= rating:
                v.fail("pressure.initial_gauge_bar", pr["initial_gauge_bar"],
                       f"must lie between 0 and the rating, {rating / PA_PER_BAR:g} bar")
        if "inlet" in pr or "exhaust" in pr:
            return self._valve_pair_source(v, pr, supply)
        command = self._valve_command(v, pr)
        parts = (_three_way_valve(v, pr, p), _chamber(v, self.spec.get("chamber", {}), p),
                 Constant(supply), command, p["T_supply_K"], p["p_atm_Pa"])
        ports = {key: _port_ref(v, f"pressure.{key}", pr[key]) for key in ("supply_port", "outlet_port") if key in pr}
        if "spool" in pr:
            return spool_source(v, pr, parts, ports)
        if _pwm_model(v, pr) == "averaged":
            if ports:
                v.fail(f"pressure.{next(iter(ports))}", pr[next(iter(ports))], "the averaged PWM valve takes its "
                       "supply input and feeds the chamber: it is not wired into a line (use model = 'switching')")
            return averaged_source(ValveChamberSource(*parts), command)
        return LineValveSource(*parts, **ports) if ports else ValveChamberSource(*parts)

    def _valve_pair_source(self, v: "_Validator", pr: Mapping[str, Any], supply: float):
        """Two 2/2 valves, ``[pressure.inlet]`` and ``[pressure.exhaust]``, each with its ISO 6358 (C, b), its
        timing and its command (the exhaust's may be the inlet's inverted).  With ``model = "averaged"`` in the
        inlet's PWM command and the exhaust complementary, their averaged model at the inlet's duty (the input
        ``pwm_duty``); otherwise each valve whose PWM command has ``model = "averaged"`` opens by its mean
        opening over a period (:func:`~pamsim.elements.pwm_average.mean_opening_signal`)."""
        p = self.parameters
        for section in ("controller", "compensation"):
            if section in self.spec:
                v.fail("pressure.inlet", "{...}", f"a [{section}] table drives the rig's single valve: two 2/2 valves "
                       "take their commands from their own tables")
        for key in ("command", "valve_open_time_s", "spool", "supply_port", "outlet_port", *PATH_KEYS):
            if key in pr:
                v.fail(f"pressure.{key}", pr[key], "two 2/2 valves ([pressure.inlet], [pressure.exhaust]) take "
                       "their commands and (C, b) in their own tables, and feed the chamber from the supply input")
        tables, orifices, timings = {}, {}, {}
        for name in ("inlet", "exhaust"):
            table = v.required(pr, name, prefix="pressure.")
            if not isinstance(table, dict):
                v.fail(f"pressure.{name}", table, "must be a table of the valve's C_m3_per_s_Pa, b, timing and command")
            for key in table:
                if key not in ("C_m3_per_s_Pa", "b", "command", *VALVE_TIMING):
                    v.fail(f"pressure.{name}.{key}", table[key], "unknown key of an on/off valve",
                           choices=("C_m3_per_s_Pa", "b", "command", *VALVE_TIMING))
            tables[name] = table
            orifices[name] = _orifice(v, f"pressure.{name}.", table.get("C_m3_per_s_Pa"), table.get("b"), p)
            timings[name] = {key: _not_negative(v, f"pressure.{name}.{key}", table.get(key, default))
                             for key, (default, _) in VALVE_DEFAULTS.items()}
        inlet = on_off_command(v, "pressure.inlet.command", v.required(tables["inlet"], "command", prefix="pressure.inlet."),
                               timings["inlet"])
        exhaust_table = v.required(tables["exhaust"], "command", prefix="pressure.exhaust.")
        exhaust = on_off_command(v, "pressure.exhaust.command", exhaust_table, timings["exhaust"], inlet=inlet)
        valve = ProportionalValve33(orifices["inlet"], orifices["exhaust"])
        parts = (OnOffValvePair(valve), _chamber(v, self.spec.get("chamber", {}), p), Constant(supply), inlet,
                 p["T_supply_K"], p["p_atm_Pa"])
        averaged = {name: _pwm_model(v, tables[name], f"pressure.{name}.command") == "averaged"
                    for name in ("inlet", "exhaust")}
        if averaged["inlet"] and exhaust_table.get("kind") == "complementary":
            return averaged_source(ValveChamberSource(valve, *parts[1:]), inlet, exhaust)
        # Each valve whose PWM command says model = "averaged" opens by its mean opening over a period.
        if averaged["inlet"]:
            parts = (*parts[:3], mean_opening_signal(inlet), *parts[4:])
        return ValvePairSource(*parts, exhaust_command=mean_opening_signal(exhaust) if averaged["exhaust"] else exhaust,
                               averaged_inlet=inlet if averaged["inlet"] else None)

    def _supply_gauge_Pa(self, v: "_Validator", pr: Mapping[str, Any]) -> float:
        """The valve's supply pressure [Pa gauge], given in bar or in Pa, within the muscle's rating."""
        if ("supply_gauge_bar" in pr) == ("supply_gauge_Pa" in pr):
            raise ScenarioError(f"{self.origin}: [pressure] needs exactly one of supply_gauge_bar or supply_gauge_Pa")
        key = "supply_gauge_bar" if "supply_gauge_bar" in pr else "supply_gauge_Pa"
        supply = v.number(f"pressure.{key}", pr[key]) * (PA_PER_BAR if key.endswith("bar") else 1.0)
        if supply < 0:
            v.fail(f"pressure.{key}", pr[key], "must not be negative")
        rating = self.parameters["rated_pressure_gauge_Pa"]
        if supply > rating:
            v.fail(f"pressure.{key}", pr[key], f"exceeds the muscle's rating of {rating / PA_PER_BAR:g} bar "
                   f"(parameter rated_pressure_gauge_Pa: {self.parameters.entries['rated_pressure_gauge_Pa'].source})")
        return supply

    def _valve_command(self, v: "_Validator", pr: Mapping[str, Any]):
        """The valve's command: a ``[pressure.command]`` signal within [-1, 1], or a full opening at
        ``valve_open_time_s``."""
        if ("command" in pr) == ("valve_open_time_s" in pr):
            raise ScenarioError(f"{self.origin}: [pressure] needs exactly one of valve_open_time_s or [pressure.command]")
        if "command" in pr:
            table = pr["command"]
            if isinstance(table, dict) and "model" in table:  # the valve's choice, not the signal's
                table = {k: val for k, val in table.items() if k != "model"}
            command = signal_from_table(v, "pressure.command", table, "", 1.0, self.base_dir)
            lo, hi = signal_range(command)
            if lo < -1 or hi > 1:
                v.fail("pressure.command", f"{lo:g}..{hi:g}", "valve command must stay within [-1, 1]")
            return command
        t_open = v.number("pressure.valve_open_time_s", pr["valve_open_time_s"])
        if t_open < 0:
            v.fail("pressure.valve_open_time_s", t_open, "must not be negative")
        return Step(t_open, 0.0, 1.0)

    def _prescribed_source(self, v: "_Validator", pr: Mapping[str, Any]) -> PrescribedPressure:
        v.allowed("pressure", pr, {"source", "prescribed"})
        if "chamber" in self.spec:
            v.fail("chamber", self.spec["chamber"], "a prescribed pressure has no chamber: [chamber] takes "
                   'pressure.source = "valve"')
        sig = signal_from_table(v, "pressure.prescribed", v.required(pr, "prescribed", prefix="pressure."),
                                "_gauge_bar", PA_PER_BAR, self.base_dir, alt_suffix=("_gauge_Pa", 1.0))
        lo, hi = signal_range(sig)
        rating = self.parameters["rated_pressure_gauge_Pa"]
        if hi > rating:
            v.fail("pressure.prescribed", f"{hi / PA_PER_BAR:g} bar", f"exceeds the muscle's rating of {rating / PA_PER_BAR:g} bar")
        if lo < -self.parameters["p_atm_Pa"]:
            v.fail("pressure.prescribed", f"{lo / PA_PER_BAR:g} bar", "is below vacuum")
        return PrescribedPressure(sig)

    def static_model(self):
        """The library model the scenario names, built for its muscle, raw (unclipped, untabulated)."""
        m = self.spec["model"]
        return REGISTRY[m["static_force"]].build(model_inputs(self.muscle, self.parameters),
                                                 m.get("static_force_variant"))

    def _build_static_force(self):
        m = self.spec["model"]
        return STATIC_FORCE_MODELS[m["static_force"]](model_inputs(self.muscle, self.parameters),
                                                      {**m, "upper_stop": self.upper_stop})

    def build_model(self) -> MuscleModel:
        """Compose the elements this scenario names into a :class:`MuscleModel`."""
        p = self.parameters
        m = self.spec["model"]
        domain = self._static_force.domain
        return MuscleModel(
            static_force=self._static_force,
            # Maxwell-slip elements take the friction law's place, reading its level ([hysteresis]).
            friction=NoCoulomb() if "hysteresis" in self.spec else FRICTION_MODELS[m["friction"]](p, m),
            damping=DAMPING_MODELS[m["damping"]](p, m),
            load=HangingLoad(self.mass_kg, p["g_m_s2"], self._external_force),
            stops=self._stops,
            source=self._source,
            fit_range=FitRange(domain.x_min_m, domain.x_max_m, domain.p_max_Pa),
        )

    @property
    def added_components(self) -> tuple:
        """The components the scenario adds to the rig (``[[component]]`` tables), as
        :class:`pamsim.assemblies.one_muscle.AddedComponent` s."""
        return self._added

    @property
    def chamber_law(self) -> str:
        """The chamber's law (``[chamber] law``, :data:`pamsim.elements.chamber.CHAMBER_LAWS`); ``"polytropic"``
        without the table."""
        return self.spec.get("chamber", {}).get("law", CHAMBER_DEFAULTS["law"][0])

    @property
    def initial_contraction_m(self) -> float:
        """Contraction [m] at the start (``simulation.initial_contraction_m``, default 0)."""
        return float(self.spec["simulation"].get("initial_contraction_m", 0.0))

    def measured_steady_state(self) -> SteadyState | None:
        """The measured end of this test that ``[measured] steady_state`` names, for the scenario's supply step
        (a valve source) and hung weight: None without the table, or when the data have no such test.

        It says what a run should end at, so that its figure can show it (``pamsim run``); it does not
        enter the model.
        """
        name = self.spec.get("measured", {}).get("steady_state")
        if name is None or self.spec["pressure"]["source"] != "valve":
            return None
        return steady_state(name, self.final_pressure_gauge_Pa / PA_PER_BAR, self.mass_kg * self.parameters["g_m_s2"])

    @property
    def pwm_model(self) -> str | None:
        """How the valve's ``pwm`` command runs: ``"switching"``, ``"averaged"``
        (:mod:`pamsim.elements.pwm_average`), or None without a PWM command."""
        pressure = self.spec["pressure"]
        command = pressure["inlet"].get("command") if "inlet" in pressure else pressure.get("command")
        if not isinstance(command, dict) or command.get("kind") != "pwm":
            return None
        return command.get("model", "switching")

    @property
    def beyond_one_muscle_fmu(self) -> bool:
        """Whether the one-muscle FMU, with the rig alone, the polytropic chamber and the proportional valve,
        lacks something this scenario has (components added to the rig, another chamber law, an averaged
        PWM valve, a spool valve, valve paths with their own (C, b), two 2/2 valves): the FMU of its assembly
        then runs it."""
        pressure = self.spec["pressure"]
        return (bool(self.added_components) or self.chamber_law != "polytropic" or self.pwm_model == "averaged"
                or any(key in pressure for key in ("spool", "inlet", *PATH_KEYS)))

    def with_pwm_averaged(self) -> "Scenario":
        """This scenario with its PWM valve command run by the averaged valve (``model = "averaged"``)."""
        pressure = self.spec["pressure"]
        if "inlet" in pressure:
            inlet = pressure["inlet"]
            return self.with_changes({"pressure": {"inlet": {**inlet, "command": {**inlet["command"],
                                                                                   "model": "averaged"}}}})
        return self.with_changes({"pressure": {"command": {**pressure["command"], "model": "averaged"}}})

    @property
    def initial_pressure_gauge_Pa(self) -> float | None:
        """Initial chamber pressure of a valve source [Pa gauge], or None for ambient."""
        bar = self.spec["pressure"].get("initial_gauge_bar")
        return None if bar is None else float(bar) * PA_PER_BAR


def read_toml(path: Path, kind: str, error: type[InputError] = InputError) -> dict:
    """Parse a TOML file, turning every way it can be unreadable into ``error`` naming the file."""
    if not path.is_file():
        raise error(f"{path}: no such {kind} file")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML: {exc}") from None
    except (UnicodeDecodeError, OSError) as exc:
        raise error(f"{path}: cannot read it as text: {exc}") from None


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file."""
    path = Path(path)
    spec = read_toml(path, "scenario", ScenarioError)
    return Scenario.from_dict(spec, name=spec.get("name") or path.stem, base_dir=path.parent, origin=str(path))


# ---------------------------------------------------------------- model section
def _muscle(v: "_Validator", model: dict) -> Muscle:
    """The muscle ``[model]`` names: ``muscle`` (a shipped name or a path relative to the scenario)
    or the older ``parameter_set`` (a shipped name); the Shadow muscle by default."""
    if "muscle" in model and "parameter_set" in model:
        v.fail("model.parameter_set", model["parameter_set"], "give either muscle or parameter_set, not both")
    key = "muscle" if "muscle" in model else "parameter_set"
    name = model.get(key, "shadow_6x300_acra2012")
    is_path = "/" in name or name.endswith(".toml")
    if key == "parameter_set" and is_path or not is_path and name not in shipped_names():
        v.fail(f"model.{key}", name, "unknown muscle (`pamsim muscles` lists them)", choices=shipped_names())
    try:
        muscle = load_muscle(v.base_dir / name if is_path else name)
    except InputError as exc:
        v.fail(f"model.{key}", name, f"invalid muscle file: {exc}")
    model["muscle"] = name
    model.pop("parameter_set", None)
    return muscle


_ALTERNATIVES = (("weight_N", "mass_kg"), ("supply_gauge_bar", "supply_gauge_Pa"))
"""Pairs of keys of which a table gives one."""


def _without_alternatives(table: dict, values: Mapping[str, Any]) -> dict:
    """``table`` less the other key of each pair of :data:`_ALTERNATIVES` that ``values`` names one of."""
    for pair in _ALTERNATIVES:
        if any(k in values for k in pair):
            for k in pair:
                if k not in values:
                    table.pop(k, None)
    return table


def _default_choices(v: "_Validator", model: dict) -> None:
    """Fill in the element choices ``[model]`` leaves out, and refuse an unknown one."""
    for key, registry, default in (("friction", FRICTION_MODELS, "load_dependent"),
                                   ("damping", DAMPING_MODELS, "paper"),
                                   ("friction_negative_level", NEGATIVE_LEVEL_CHOICES, "clamp"),
                                   ("static_force_negative", NEGATIVE_FORCE_CHOICES, "clip")):
        choice = model.setdefault(key, default)
        if choice not in registry:
            v.fail(f"model.{key}", choice, "unknown choice", choices=registry)
    # No default is filled in: without the key the muscle file chooses, and the FMU refuses the key.
    if "upper_stop" in model and model["upper_stop"] not in UPPER_STOPS:
        v.fail("model.upper_stop", model["upper_stop"], "unknown choice", choices=UPPER_STOPS)


def _key(kind: str, name: str) -> str:
    return {"parameter": f"parameters.{name}", "model": "model.static_force",
            "variant": "model.static_force_variant"}[kind]


def _port_ref(v: "_Validator", key: str, value: Any) -> str:
    """``value`` as a reference to a port of a component added to the rig (``"reservoir.port"``); whether
    that component and port exist is the assembly's check (:func:`pamsim.scenario_components.check_wiring`)."""
    name, _, port = str(value).partition(".")
    if not (isinstance(value, str) and name.isidentifier() and port.isidentifier()):
        v.fail(key, value, 'must name a port of a [[component]] as "name.port"')
    return value


# ---------------------------------------------------------------- chamber section
def _chamber(v: "_Validator", table: Mapping[str, Any], p: ParameterSet):
    """The chamber element of ``[chamber]`` (:data:`pamsim.parameters.CHAMBER_DEFAULTS` for what it
    leaves out) and the muscle's parameters ``p``; a key of another law, or a value out of range, fails
    naming the key."""
    law = table.get("law", CHAMBER_DEFAULTS["law"][0])
    if law not in CHAMBER_LAWS:
        v.fail("chamber.law", law, "unknown law", choices=CHAMBER_LAWS)
    keys = CHAMBER_LAW_KEYS[law]
    for key in table:
        if key != "law" and key not in keys:
            v.fail(f"chamber.{key}", table[key], f"does not apply to law = {law!r}"
                   + (f" (it takes {', '.join(keys)})" if keys else ""))
    values = {key: v.number(f"chamber.{key}", table.get(key, CHAMBER_DEFAULTS[key][0])) for key in keys}
    for key, ok, why in (("T_wall_K", lambda T: T > 0.0, "must be positive"),
                         ("h_W_per_m2_K", lambda h: h >= 0.0, "must not be negative"),
                         ("heat_capacity_ratio", lambda g: 1.0 < g <= 5.0 / 3.0,
                          "must lie in (1, 5/3], the ratio c_p / c_v of a gas")):
        if key in values and not ok(values[key]):
            v.fail(f"chamber.{key}", values[key], why)
    if law == "isothermal":
        return IsothermalChamber.from_parameters(p, values["T_wall_K"])
    if law == "thermal":
        return ThermalChamber.from_parameters(p, values["heat_capacity_ratio"], values["h_W_per_m2_K"],
                                              values["T_wall_K"])
    return MuscleChamber.from_parameters(p)


# ---------------------------------------------------------------- simulation and solver sections
def _simulation(v: "_Validator", sim: dict) -> tuple[float, float, float]:
    """``[simulation]``'s duration [s], output rate [Hz] and initial contraction [m] (checked against the
    stops once the muscle's end stops are built)."""
    duration = v.positive("simulation.duration_s", v.required(sim, "duration_s", prefix="simulation."))
    sample_rate = v.positive("simulation.sample_rate_Hz", sim.get("sample_rate_Hz", 1000.0))
    x0 = v.number("simulation.initial_contraction_m", sim.get("initial_contraction_m", 0.0))
    return duration, sample_rate, x0


def _solver_options(v: "_Validator", solver: dict, duration: float, sample_rate: float) -> SolverOptions:
    """``[solver]`` with its defaults, each value checked."""
    method = solver.get("method", "LSODA")
    if method not in _METHODS:
        v.fail("solver.method", method, "unknown method", choices=_METHODS)
    rtol = v.number("solver.rtol", solver.get("rtol", 1e-6))
    if not MIN_RTOL <= rtol <= 1e-2:
        v.fail("solver.rtol", rtol, f"must lie in [{MIN_RTOL:g}, 1e-2]")
    max_events = solver.get("max_events", 20000)
    if max_events < 1:
        v.fail("solver.max_events", max_events, "must be at least 1")
    max_step = v.positive("solver.max_step_s", solver.get("max_step_s", math.inf))
    smallest_step = max(MIN_MAX_STEP_S, duration / MAX_STEPS)
    if max_step < smallest_step:
        v.fail("solver.max_step_s", max_step, f"must be at least {smallest_step:.3g} s (1 us, and no more than "
               f"{MAX_STEPS:.0e} steps over duration_s = {duration:g} s)")
    return SolverOptions(method=method, rtol=rtol, sample_rate_Hz=sample_rate, max_events=int(max_events),
                         max_step_s=max_step, native_rtol_factor=_native_rtol_factor(v, solver),
                         **_margins(v, solver))


def _margins(v: "_Validator", solver: dict) -> dict:
    """``solver.stick_margin_N`` and ``solver.release_margin_N`` where given: ``0 <= stick < release``."""
    given = {key: v.number(f"solver.{key}", solver[key]) for key in ("stick_margin_N", "release_margin_N")
             if key in solver}
    defaults = SolverOptions()
    stick = given.get("stick_margin_N", defaults.stick_margin_N)
    release = given.get("release_margin_N", defaults.release_margin_N)
    if stick < 0.0:
        v.fail("solver.stick_margin_N", stick, "must be >= 0")
    if not release > stick:
        key = "release_margin_N" if "release_margin_N" in given else "stick_margin_N"
        v.fail(f"solver.{key}", given[key], f"the release margin must exceed the stick margin ({stick:g} N)")
    return given


def _native_rtol_factor(v: "_Validator", solver: dict) -> float:
    """``solver.native_rtol_factor``, in (0, 1]."""
    factor = v.number("solver.native_rtol_factor", solver.get("native_rtol_factor", NATIVE_RTOL_FACTOR))
    if not 0.0 < factor <= 1.0:
        v.fail("solver.native_rtol_factor", factor, "must lie in (0, 1]")
    return factor


def _checked_name(v: "_Validator", name: str) -> str:
    if any(bad in name for bad in ("/", "\\", "..", "\0")):
        # The name is the stem of the output files: it must not lead out of the output folder.
        v.fail("name", name, "must be a plain file name stem, without path separators or '..'")
    return name


# ---------------------------------------------------------------- validation
def _check_sections(v: "_Validator", spec: dict) -> None:
    """Every table's keys and types, and the sections a scenario cannot do without."""
    if "joint" in spec or isinstance(spec.get("muscle"), list):
        raise ScenarioError(f"{v.origin}: [joint] and [[muscle]] tables make muscles on a joint: run it with "
                            "`pamsim run`, or read it with pamsim.joints.load_joint_scenario")
    v.check_table("", spec)
    for section in ("model", "load", "pressure", "simulation", "solver", "measured", "chamber"):
        if section in spec:
            v.check_table(section, spec[section])
    if "measured" in spec:
        _check_measured(v, spec["measured"])
    if "motion" in spec and "load" in spec:
        # Decided: the length is prescribed, so nothing hangs on the muscle; a weight or an external force
        # there would be a load the run silently ignores.
        raise ScenarioError(f"{v.origin}: [load] = {spec['load']!r}: a muscle driven by its length ([motion]) has "
                            "no load; leave [load] out")
    for section in [s for s in ("load", "pressure", "simulation") if s != "load" or "motion" not in spec]:
        if section not in spec:
            raise ScenarioError(f"{v.origin}: missing section [{section}]")


def _check_measured(v: "_Validator", table: dict) -> None:
    """``[measured] steady_state``: a set of measured steady states that pamsim ships."""
    measured = v.required(table, "steady_state", prefix="measured.")
    if measured not in STEADY_STATE_SETS:
        v.fail("measured.steady_state", measured, "unknown measured steady states", choices=STEADY_STATE_SETS)


class _Validator(TableChecker):
    """The scenario file's checks; ``error`` (a :class:`ScenarioError`) also serves helpers such as
    :mod:`pamsim.signal_tables`.  Its numbers say what type they must be, and ``positive`` takes inf."""

    def __init__(self, origin: str, base_dir: Path):
        super().__init__(origin, ScenarioError)
        self.base_dir = base_dir

    def check_table(self, section: str, table: Any):
        where = f"[{section}]" if section else "the top level"
        if not isinstance(table, dict):
            raise ScenarioError(f"{self.origin}: {section} = {table!r}: must be a table")
        schema = _SCHEMA[section]
        for key, value in table.items():
            full = f"{section}.{key}" if section else key
            if key not in schema:
                raise ScenarioError(f"{self.origin}: unknown key {full!r} in {where}"
                                    + choices_hint(key, schema, f"known keys in {where}:"))
            self.type_of(full, value, schema[key])

    def allowed(self, section: str, table: Mapping, keys: set[str]):
        for key in table:
            if key not in keys:
                raise ScenarioError(f"{self.origin}: key {section}.{key} does not apply to "
                                    f"source = {table.get('source')!r}" + did_you_mean(key, keys))

    def type_of(self, key: str, value: Any, expected: type):
        ok = {float: isinstance(value, (int, float)) and not isinstance(value, bool),
              int: isinstance(value, int) and not isinstance(value, bool),
              str: isinstance(value, str), dict: isinstance(value, dict), list: isinstance(value, list)}[expected]
        if not ok:
            names = {float: "a number", int: "an integer", str: "a string", dict: "a table",
                     list: "an array of tables ([[...]])"}
            self.fail(key, value, f"must be {names[expected]}, not {value_phrase(value)}")
        if expected is float and not math.isfinite(value):
            self.fail(key, value, "must be a finite number")

    def number(self, key: str, value: Any) -> float:
        self.type_of(key, value, float)
        return float(value)

    def positive(self, key: str, value: Any) -> float:
        value = self.number(key, value) if value != math.inf else value
        if not value > 0:
            self.fail(key, value, "must be positive")
        return value


def _pwm_model(v: "_Validator", pr: Mapping[str, Any], where: str = "pressure.command") -> str:
    """How a ``pwm`` valve command runs (``[pressure.command] model``, or the table at ``where``): its
    switching (the default), or the averaged valve, whose input is the duty."""
    command = pr.get("command")
    if not isinstance(command, dict) or "model" not in command:
        return "switching"
    model = command["model"]
    if command.get("kind") != "pwm":
        v.fail(f"{where}.model", model, f"only a pwm command has a model, not kind = {command.get('kind')!r}")
    if not isinstance(model, str) or model not in PWM_MODELS:
        v.fail(f"{where}.model", model, "unknown PWM model", choices=PWM_MODELS)
    return model


PATH_KEYS = ("supply_C_m3_per_s_Pa", "supply_b", "exhaust_C_m3_per_s_Pa", "exhaust_b")
"""``[pressure]`` keys of the 3/2 (and spool) valve's paths' own ISO 6358 (C, b); each defaults to the muscle's
``valve_C_m3_per_s_Pa`` or ``valve_b``."""


def _three_way_valve(v: "_Validator", pr: Mapping[str, Any], p) -> ProportionalValve33:
    """The rig's valve of the muscle's parameters, its paths with their own (C, b) where :data:`PATH_KEYS`
    give them (without any, the one orifice of both paths, as it always was)."""
    if not any(key in pr for key in PATH_KEYS):
        return ProportionalValve33(Iso6358Orifice.from_parameters(p))
    return ProportionalValve33(*(_orifice(v, f"pressure.{path}_", pr.get(f"{path}_C_m3_per_s_Pa"), pr.get(f"{path}_b"), p)
                                 for path in ("supply", "exhaust")))


def _orifice(v: "_Validator", prefix: str, C, b, p) -> Iso6358Orifice:
    """The muscle's valve orifice with sonic conductance ``C`` and critical ratio ``b`` where given (not
    None), named in a refusal as ``<prefix>C_m3_per_s_Pa`` and ``<prefix>b``: C > 0, 0 <= b < 1 and b below
    the laminar ratio."""
    muscle = Iso6358Orifice.from_parameters(p)
    if C is not None and not v.number(f"{prefix}C_m3_per_s_Pa", C) > 0.0:
        v.fail(f"{prefix}C_m3_per_s_Pa", C, "must be > 0: a sonic conductance")
    if b is not None and not 0.0 <= v.number(f"{prefix}b", b) < min(1.0, muscle.laminar_ratio):
        v.fail(f"{prefix}b", b, f"must lie in [0, 1) and below the valve's laminar ratio {muscle.laminar_ratio:g}")
    return replace(muscle, C_m3_per_s_Pa=muscle.C_m3_per_s_Pa if C is None else float(C),
                   b=muscle.b if b is None else float(b))


def _not_negative(v: "_Validator", key: str, value: Any) -> float:
    """``value`` as a number of seconds that is not negative, refused naming ``key``."""
    if v.number(key, value) < 0.0:
        v.fail(key, value, "must not be negative")
    return float(value)
