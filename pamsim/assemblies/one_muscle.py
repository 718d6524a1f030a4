"""One muscle lifting a hanging load: the ACRA 2012 test rig as an assembly of components.

::

    valve --port-- chamber --p_gauge_Pa--> muscle, friction
                      ^ x_m, v_m_s               |
    muscle, damping, external --flange-- load <--level_N-- friction

Model inputs: ``valve_command`` and ``supply_pressure_gauge_Pa`` (valve source) or
``prescribed_pressure_gauge_Pa`` (prescribed source), and ``external_force_N``.
"""

from __future__ import annotations

from ..components import (CoulombFriction, ExternalForce, HangingLoad, MuscleStaticForce, PolytropicChamber,
                          PressureSignal, ProportionalValve, ViscousDamping)
from ..elements.pressure_source import PrescribedPressure, ValveChamberSource
from ..modeling import Assembly

INPUTS_VALVE = ("valve_command", "supply_pressure_gauge_Pa", "external_force_N")
INPUTS_PRESCRIBED = ("prescribed_pressure_gauge_Pa", "external_force_N")


def one_muscle_assembly(model, x0_m: float = 0.0, p0_gauge_Pa: float | None = None,
                        stick_margin_N: float = 1e-7, release_margin_N: float = 2e-7) -> Assembly:
    """The assembly of a :class:`pamsim.model.MuscleModel`'s elements (its static force, friction,
    damping, load, stops and pressure source), starting at rest at ``x0_m`` with the chamber at
    ``p0_gauge_Pa`` (ambient if None).  The margins are the simulator's
    (:class:`pamsim.simulator.SolverOptions`)."""
    load = HangingLoad("load", {
        "mass_kg": model.load.mass_kg, "g_m_s2": model.load.g_m_s2, "x_low_m": model.stops.x_low_m,
        "x_high_m": model.stops.x_high_m, "restitution": model.stops.restitution,
        "stick_margin_N": stick_margin_N, "release_margin_N": release_margin_N, "initial_contraction_m": x0_m})
    parts = [load]
    src = model.source
    if isinstance(src, ValveChamberSource):
        parts += [PolytropicChamber("chamber", src.chamber, src.p_atm_Pa, p0_gauge_Pa or 0.0, src.T_supply_K),
                  ProportionalValve("valve", src.valve, src.T_supply_K, src.p_atm_Pa, src.chamber.R_J_per_kg_K)]
        pressure = "chamber"
        wiring = [("chamber.port", "valve.port"), ("load.x_m", "chamber.x_m"), ("load.v_m_s", "chamber.v_m_s")]
        inputs = {"valve_command": "valve.command", "supply_pressure_gauge_Pa": "valve.supply_gauge_Pa"}
    elif isinstance(src, PrescribedPressure):
        parts.append(PressureSignal("pressure"))
        pressure, wiring = "pressure", []
        inputs = {"prescribed_pressure_gauge_Pa": "pressure.p_in_gauge_Pa"}
    else:
        raise TypeError(f"no component for the pressure source {type(src).__name__}")
    parts += [MuscleStaticForce("muscle", model.static_force), CoulombFriction("friction", model.friction),
              ViscousDamping("damping", model.damping), ExternalForce("external")]
    wiring += [("load.flange", "muscle.flange"), ("load.flange", "damping.flange"), ("load.flange", "external.flange"),
               (f"{pressure}.p_gauge_Pa", "muscle.p_gauge_Pa"), (f"{pressure}.p_gauge_Pa", "friction.p_gauge_Pa"),
               ("load.x_m", "friction.x_m"), ("load.v_m_s", "friction.v_m_s"), ("load.mass_kg", "friction.mass_kg"),
               ("friction.level_N", "load.friction_level_N")]
    inputs["external_force_N"] = "external.F_N"
    return Assembly(parts, wiring, inputs, name="one_muscle")


def scenario_assembly(scenario) -> Assembly:
    """The assembly of a :class:`pamsim.scenario.Scenario`: its model, start and the solver's margins."""
    opts = scenario.solver
    return one_muscle_assembly(scenario.build_model(), scenario.initial_contraction_m,
                               scenario.initial_pressure_gauge_Pa, opts.stick_margin_N, opts.release_margin_N)
