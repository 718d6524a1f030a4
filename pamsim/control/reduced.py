"""The position loop's design model when the valve has dynamics of its own (a spool) or discharges into a line
(a tube): the rig reduced to the proportional valve feeding the chamber directly, and the full linearisation
the design is checked on.

Why reduced: an LQR on the full linearisation feeds back every state, the spool's position and velocity and
the tube's pressure among them.  The Festo MPYE class of valve closes its own spool position loop and does not
give the position out, and the tube's pressure would need a second sensor; a full-state gain whose extra
entries are dropped is no longer the LQR, with none of its guarantees.  So the controller is designed, as
before, on the states it measures or estimates (contraction, velocity, chamber pressure), with the spool taken
as instant and the tube left out, and the loop it makes with the full linearisation (spool, tube) is checked:
its poles are returned with the design, and :func:`pamsim.control.closed_loop.design_lqr` refuses a design
whose full loop is unstable.
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import control as ct
import numpy as np

from ..elements.chamber import MuscleChamber
from ..elements.pressure_source import LineValveSource, ValveChamberSource
from ..errors import InputError
from ..modeling import PNEUMATIC
from ..scenario_components import refuse_added
from .line_rest import held_line_pressures
from .linear import LinearModel, linearize
from .operating_point import OperatingPoint
from .system import FrictionTreatment


def needs_reduction(model, added: tuple) -> bool:
    """Whether ``model`` (with the components ``added`` to its rig) has states beyond the design model's
    contraction, velocity and chamber pressure: a spool's, a line's, or the thermal law's gas temperature
    (its air mass and pressure independent)."""
    return (len(model.source.state_names) > 2 or any(a.component.states for a in added)
            or getattr(model.source.chamber, "law", "") == "thermal")


def reduced_model(model):
    """``model`` with its valve source reduced to the proportional valve feeding the chamber: a spool valve's
    full opening taken as instant (:class:`~pamsim.elements.spool.SpoolValve33`'s ``valve``), the line's
    wiring dropped, and a thermal chamber's gas taken as adiabatic (the polytropic law with the gas's
    ``heat_capacity_ratio``: the thermal law with ``h = 0``; its wall's heat acts over a second or so, far
    slower than the loop)."""
    src = model.source
    valve = getattr(src.valve, "valve", src.valve)
    chamber = src.chamber
    if getattr(chamber, "law", "") == "thermal":
        chamber = MuscleChamber(chamber.L0_m, chamber.thread_length_m, chamber.turns, chamber.dead_volume_m3,
                                chamber.heat_capacity_ratio, chamber.R_J_per_kg_K)
    plain = ValveChamberSource(valve, chamber, src.supply_gauge_Pa, src.command, src.T_supply_K, src.p_atm_Pa)
    return dataclasses.replace(model, source=plain)


def line_components(scenario) -> tuple:
    """The components added to ``scenario``'s rig that are volumes of a line: pneumatic components with states
    (a tube, a reservoir) that say where they rest (``held_state``)."""
    return tuple(a for a in scenario.added_components
                 if any(port.kind is PNEUMATIC for port in a.component.ports) and a.component.states
                 and callable(getattr(a.component, "held_state", None)))


def refuse_unsupported_line(scenario) -> None:
    """Raise :class:`InputError` for what the closed loop's design cannot take: components added to the rig
    other than the volumes of a line and the ``[hysteresis]`` model (whose friction the design drops), as
    :func:`pamsim.scenario_components.refuse_added` says it, or a valve that draws from a line
    (``supply_port``: its volumes rest at the supply's pressure, not at the chamber's)."""
    src = scenario.build_model().source
    if isinstance(src, LineValveSource) and src.supply_port:
        raise InputError(f"{scenario.origin}: pressure.supply_port = {src.supply_port!r}: the closed loop's design "
                         "holds the line at the chamber's pressure; a valve that draws from a line is not taken")
    lines = line_components(scenario)
    others = SimpleNamespace(origin=scenario.origin, spec=scenario.spec,
                             added_components=tuple(a for a in scenario.added_components if a not in lines))
    refuse_added(others, "the closed loop's controller design", InputError, hysteresis=True)


def full_linearisation(model, held: OperatingPoint, added: tuple) -> LinearModel:
    """The linearisation of ``model`` with its spool and the ``added`` line at the held operating point ``held``
    (valve closed): the spool at rest in its centre, every volume of the line at the pressure its resistances
    join it to (the chamber's, behind the closed valve: :mod:`pamsim.control.line_rest`), so nothing flows."""
    p_abs = float(held.states[2])
    rest = held_line_pressures(added, p_abs, float(held.inputs[1]))
    line = {f"{a.component.name}.{k}": v for a in added if a.component.states
            for k, v in a.component.held_state(rest.get(a.component.name, p_abs)).items()}
    return linearize(model, dataclasses.replace(held, line_states=line), FrictionTreatment("dropped"), "mean",
                     added=added)


def loop_poles(plant: LinearModel, controller: ct.StateSpace) -> np.ndarray:
    """The poles of the linear loop of ``controller`` (:func:`pamsim.control.closed_loop.controller_system`)
    around ``plant``'s contraction and chamber pressure."""
    loop = ct.interconnect([plant.sys[["contraction_m", "p_gauge_Pa"], "valve_command"], controller],
                           inplist=["r_m"], outlist=["contraction_m"], inputs=["r_m"], outputs=["contraction_m"])
    return np.linalg.eigvals(loop.A)
