"""The one-muscle FMU generated from components, under the names its variables have always had.

The FMU's parameters are a muscle's (``L0_m``, ``r0_m``, ``theta0_deg``, ``K1_N_per_bar_m2``, ...)
and its run-time choices (``friction_model``, ``damping_model``, ``pressure_source``,
``static_force_model``, ``friction_negative_level``); its load's mass is an input.  The generated
model's parameters are its components' (``chamber.thread_length_m``, ``friction.choice``, ...).  The
*parameter map* between them is generated code too: the elements' own ``from_parameters`` builders,
run on CasADi symbols (:func:`knob_map`), so the braid geometry, the upper stop at the braid lock and
the laws' parameters are derived in C exactly as Python derives them.  Each run-time choice is a
:class:`pamsim.components.choice.Selected` component holding every law it may pick.

The FMU's C core is the generic one of every assembly (``pam_gcore.c``): it computes the generated
model's parameters from the FMU's through the map whenever a parameter or the mass changes, and
chains the map's exact Jacobian into the directional derivatives.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from ..components import Chamber, CoulombFriction, HangingLoad, MuscleStaticForce, ProportionalValve
from ..components import ViscousDamping
from ..components.choice import SEPARATOR, PressureChoice, Selected
from ..components.element import STRUCTURAL, _field_names, _is_instance_of_dataclass, _is_number
from ..core_table import C_CHOICES, MIN_REBOUND_SPEED_M_S
from ..elements.chamber import MuscleChamber
from ..elements.damping import DAMPING_MODELS
from ..elements.force_clip import ClippedStaticForce
from ..elements.friction import FRICTION_MODELS
from ..elements.valve import Iso6358Orifice, ProportionalValve33
from ..modeling.smath import fmin, if_else
from ..static_models.acra2012 import Acra2012Polynomial
from ..static_models.geometry import Braid

MASS_INPUT = "load_mass_kg"
"""The FMU input that is a parameter of the generated model (the load's mass)."""

STATE_NAMES = {"load.x_m": "contraction_m", "load.v_m_s": "velocity_m_s", "chamber.p_abs_Pa": "chamber_pressure_abs_Pa",
               "chamber.air_mass_kg": "air_mass_kg"}
"""The FMU's names of the generated model's states (the work integrals keep their namespaced names)."""
OUTPUT_NAMES = {"pressure.p_gauge_Pa": "p_gauge_Pa", "muscle.F_static_N": "F_static_N",
                "load.F_friction_N": "F_friction_N"}
"""The FMU's names of the generated model's outputs (the others keep their namespaced names)."""
MODE_NAME = "friction_mode"
"""The FMU's name of the load's mode."""


def _friction_options() -> tuple[tuple[str, str, str], ...]:
    """``(option, law, negative level)`` of each friction law a ``friction_model`` and
    ``friction_negative_level`` pick: the load-dependent law once per treatment of a negative level."""
    out = []
    for law in C_CHOICES["friction"]:
        levels = C_CHOICES["friction_negative_level"] if law == "load_dependent" else ("clamp",)
        out += [(f"{law}_{level}" if law == "load_dependent" else law, law, level) for level in levels]
    return tuple(out)


FRICTION_OPTIONS = _friction_options()


def _friction_choice(k: Mapping[str, Any]):
    """The index in :data:`FRICTION_OPTIONS` of the FMU's ``friction_model`` and ``friction_negative_level``."""
    choice = float(len(FRICTION_OPTIONS) - 1)
    for index, (_, law, level) in reversed(list(enumerate(FRICTION_OPTIONS))):
        law_k = float(C_CHOICES["friction"].index(law))
        picked = k["friction_model"] == law_k
        if law == "load_dependent":
            picked = picked * (k["friction_negative_level"] == float(C_CHOICES["friction_negative_level"].index(level)))
        choice = if_else(picked, float(index), choice)
    return choice


@dataclass(frozen=True)
class NoTable:
    """The ``static_force_model = table`` option of an FMU built without one: refused at the end of
    initialisation (a generated check), and NaN where the model is evaluated before that (a derivative
    read in initialisation mode), so that nothing reads a force that is not there."""

    name: str = "no_table"

    def force_N(self, x_m, p_gauge_Pa):
        """NaN, of the shape of ``x_m``."""
        return float("nan") * x_m


@dataclass(frozen=True)
class RigLaws:
    """The rig's elements and component values as a function of the FMU's knobs ``k`` (floats, or
    CasADi symbols for the generated map): see :func:`rig_laws`."""

    load: dict
    chamber: tuple
    valve: tuple
    pressure: dict
    muscle: tuple
    friction: tuple
    damping: tuple


def own_upper_stop(k: Mapping[str, Any]):
    """The upper stop ``x_high_m`` gives: its value, or with 0 the braid lock of the geometry."""
    return if_else(k["x_high_m"] > 0.0, k["x_high_m"], Braid.from_parameters(k).x_lock_m)


def on_table(k: Mapping[str, Any], table) -> Any:
    """1 where the FMU runs on its force ``table`` (``static_force_model = table``), else 0."""
    return k["static_force_model"] == float(C_CHOICES["static_force_model"].index("table")) if table else 0.0


def rig_laws(k: Mapping[str, Any], table=None) -> RigLaws:
    """The elements of the rig for the FMU's knobs ``k`` (its parameters, choices as numbers, and the
    load's mass), built by the elements' own ``from_parameters``: on floats the FMU's start values, on
    symbols the generated parameter map.  ``table``: the :class:`pamsim.fmu.force_table.ForceTable`
    the ``static_force_model = table`` option runs on, clipped at zero as the polynomial is (None: the
    FMU has the ACRA 2012 polynomial only).  On the table the travel stays within its contraction range."""
    muscle = {"acra2012_polynomial": ClippedStaticForce(Acra2012Polynomial.from_parameters(k)),
              "table": ClippedStaticForce(table) if table is not None else NoTable()}
    x_high, inside = own_upper_stop(k), on_table(k, table)
    if table is not None:
        x_low = if_else(inside, max(0.0, table.x_min_m), 0.0)
        x_high = if_else(inside, fmin(x_high, table.x_max_m), x_high)
    else:
        x_low = 0.0
    friction = {name: FRICTION_MODELS[law](k, {"friction_negative_level": level})
                for name, law, level in FRICTION_OPTIONS}
    return RigLaws(
        load={"mass_kg": k[MASS_INPUT], "g_m_s2": k["g_m_s2"], "x_low_m": x_low, "x_high_m": x_high,
              "restitution": k["stop_restitution"], "min_rebound_speed_m_s": MIN_REBOUND_SPEED_M_S,
              "stick_margin_N": k["stick_margin_N"], "release_margin_N": k["release_margin_N"],
              "initial_contraction_m": k["initial_contraction_m"]},
        chamber=(MuscleChamber.from_parameters(k), {"p_atm_Pa": k["p_atm_Pa"],
                                                    "initial_pressure_gauge_Pa": k["initial_pressure_gauge_Pa"],
                                                    "T_initial_K": k["T_supply_K"]}),
        valve=(ProportionalValve33(Iso6358Orifice.from_parameters(k)),
               {"T_supply_K": k["T_supply_K"], "p_atm_Pa": k["p_atm_Pa"], "R_J_per_kg_K": k["R_J_per_kg_K"]}),
        pressure={"prescribed": k["pressure_source"]},
        muscle=(muscle, k["static_force_model"]),
        friction=(friction, _friction_choice(k)),
        damping=({name: DAMPING_MODELS[name](k) for name in C_CHOICES["damping"]}, k["damping_model"]))


def _numbers_of(element, like) -> list:
    """The values in ``element`` (built on symbols) at the places :func:`pamsim.components.element.element_parameters`
    finds numbers in ``like`` (the same element built on floats), in its order."""
    out = []
    for name in _field_names(type(like)):
        if name in STRUCTURAL:
            continue
        value = getattr(like, name)
        if _is_instance_of_dataclass(value):
            out += _numbers_of(getattr(element, name), value)
        elif _is_number(value):
            out.append(getattr(element, name))
    return out


def _element_values(component, element, like) -> dict:
    """``{parameter: value}`` of a component around ``like`` whose numbers come from ``element``."""
    names = [v.name for v in component.parameter_vars()]
    return dict(zip(names, _numbers_of(element, like))) if names else {}


def _selected_values(component: Selected, choice, elements: Mapping[str, Any], like: Mapping[str, Any]) -> dict:
    out = {"choice": choice}
    for option, c in component.options.items():
        own = _element_values(c, elements[option], like[option])
        out.update({f"{option}{SEPARATOR}{name}": value for name, value in own.items()})
    return out


def rig_components(laws: RigLaws) -> dict:
    """The rig's components, built from ``laws`` on floats, by name."""
    muscle, friction, damping = laws.muscle[0], laws.friction[0], laws.damping[0]
    return {
        "load": HangingLoad("load", laws.load),
        "chamber": Chamber("chamber", laws.chamber[0], **laws.chamber[1]),
        "valve": ProportionalValve("valve", laws.valve[0], **laws.valve[1]),
        "pressure": PressureChoice("pressure", laws.pressure),
        "muscle": Selected("muscle", {n: MuscleStaticForce(n, e) for n, e in muscle.items()}, laws.muscle[1]),
        "friction": Selected("friction", {n: CoulombFriction(n, e) for n, e in friction.items()}, laws.friction[1]),
        "damping": Selected("damping", {n: ViscousDamping(n, e) for n, e in damping.items()}, laws.damping[1]),
    }


def component_values(components: Mapping[str, Any], laws: RigLaws, like: RigLaws) -> dict[str, Any]:
    """``{flat parameter name: value}`` of ``components`` (built from ``like``, on floats) with the
    numbers of ``laws`` (on symbols: the parameter map)."""
    out = {}
    out.update({f"load.{k}": v for k, v in laws.load.items()})
    out.update({f"pressure.{k}": v for k, v in laws.pressure.items()})
    for name in ("chamber", "valve"):
        element, extra = getattr(laws, name)
        own = _element_values(components[name], element, getattr(like, name)[0])
        out.update({f"{name}.{k}": v for k, v in {**own, **extra}.items()})
    for name in ("muscle", "friction", "damping"):
        elements, choice = getattr(laws, name)
        own = _selected_values(components[name], choice, elements, getattr(like, name)[0])
        out.update({f"{name}.{k}": v for k, v in own.items()})
    return out


def knob_map(knobs: tuple[str, ...], flat_parameters: tuple[str, ...], start: Mapping[str, float], table=None):
    """The CasADi Function ``pm_kmap(k) -> p``: the generated model's parameters ``flat_parameters``
    from the FMU's knobs ``knobs`` (in that order), and its forward derivative ``pm_dkmap(k, dk) -> dp``."""
    import casadi as ca

    sym = {name: ca.SX.sym(name) for name in knobs}
    like = rig_laws(start, table)
    values = component_values(rig_components(like), rig_laws(sym, table), like)
    missing = sorted(set(flat_parameters) - set(values))
    if missing:
        raise ValueError(f"the parameter map leaves out {missing}")
    k = ca.vertcat(*sym.values())
    p = ca.vertcat(*[ca.SX(values[name]) for name in flat_parameters])
    dk = ca.SX.sym("dk", k.shape[0])
    return (ca.Function("pm_kmap_fn", [k], [ca.cse(ca.densify(p))]),
            ca.Function("pm_dkmap_fn", [k, dk], [ca.cse(ca.densify(ca.jtimes(p, k, dk)))]))


SOURCE_WIRING = (("chamber.port", "valve.port"), ("load.x_m", "chamber.x_m"), ("pressure.v_chamber_m_s", "chamber.v_m_s"),
                 ("valve.p_settle_abs_Pa", "chamber.p_settle_abs_Pa"), ("pressure.command_out", "valve.command"),
                 ("chamber.p_gauge_Pa", "pressure.chamber_gauge_Pa"), ("load.v_m_s", "pressure.v_m_s"))
"""The valve and chamber as :data:`pamsim.assemblies.one_muscle.VALVE_CHAMBER_WIRING` wires them, with the
pressure choice between them (it stills the chamber while the pressure is prescribed)."""
SOURCE_INPUTS = {"valve_command": "pressure.command", "supply_pressure_gauge_Pa": "valve.supply_gauge_Pa",
                 "prescribed_pressure_gauge_Pa": "pressure.prescribed_gauge_Pa"}


def muscle_assembly(start: Mapping[str, float], table=None):
    """The one-muscle FMU's assembly at the knobs' values ``start`` (see :func:`rig_laws`)."""
    from ..assemblies.one_muscle import SourceParts, rig_assembly

    c = rig_components(rig_laws(start, table))
    source = SourceParts([c["chamber"], c["valve"], c["pressure"]], list(SOURCE_WIRING), dict(SOURCE_INPUTS), "pressure")
    return rig_assembly(c["load"], source, (c["muscle"], c["friction"], c["damping"]), name="one_muscle_fmu")
