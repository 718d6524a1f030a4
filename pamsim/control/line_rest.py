"""Where the volumes of a supply line rest while the rig's valve is closed (a held operating point).

A closed valve passes nothing, so the line falls apart into groups of volumes joined by resistances (tubes)
alone.  At rest nothing flows through a resistance, so every volume of a group stands at one pressure, and
the physics fixes it only where the group holds a volume whose pressure is given: the muscle's chamber (at
its holding pressure) or a regulated supply (at its set pressure, the rig's supply input).  A group with
neither (a reservoir charged and shut in) could rest at any pressure: it is refused, by name.  A group with
both would carry a steady flow from the supply into the muscle past the closed valve: no equilibrium, also
refused.
"""

from __future__ import annotations

from ..components.supply import RegulatedSupply
from ..errors import InputError
from ..modeling import PNEUMATIC

CHAMBER = "chamber"
"""The rig's chamber, as a line's ``connect`` names it (``"chamber.port"``)."""

SUPPLY_INPUT = "supply_pressure_gauge_Pa"
"""The rig's supply input, which a regulated supply's set pressure reads."""


def _groups(added: tuple) -> dict[str, str]:
    """``{component: its group's representative}``: the components joined by pneumatic connections (the
    rig's valve is not among them, its ports being the ``[pressure]`` table's)."""
    parent: dict[str, str] = {}

    def find(name: str) -> str:
        while parent.setdefault(name, name) != name:
            name = parent[name]
        return name

    for a in added:
        find(a.component.name)
        pneumatic = {port.name for port in a.component.ports if port.kind is PNEUMATIC}
        for own, target in a.connect.items():
            if own in pneumatic:
                parent[find(a.component.name)] = find(target.split(".", 1)[0])
    return {name: find(name) for name in list(parent)}


def _supply_pressure_Pa(component, connect: dict, supply_gauge_Pa: float) -> float | None:
    """The absolute pressure a regulated supply holds at rest, if its set pressure is the rig's supply input."""
    if connect.get("p_set_gauge_Pa") != SUPPLY_INPUT:
        return None
    return component.values["p_atm_Pa"] + supply_gauge_Pa


def held_line_pressures(added: tuple, chamber_p_abs_Pa: float, supply_gauge_Pa: float) -> dict[str, float]:
    """``{component name: absolute pressure}`` at which each volume of the line in ``added`` (a pneumatic
    component with states) rests with the valve closed and the chamber at ``chamber_p_abs_Pa``: its group's fixed pressure (module docstring).

    Raises
    ------
    InputError
        Naming a volume whose pressure nothing fixes, or one that joins the muscle to a supply.
    """
    group = _groups(added)
    fixed: dict[str, tuple[str, float | None]] = {}
    if CHAMBER in group:
        fixed[group[CHAMBER]] = ("the muscle's chamber", chamber_p_abs_Pa)
    for a in added:
        if not isinstance(a.component, RegulatedSupply):
            continue
        root = group[a.component.name]
        if root in fixed:
            raise InputError(f"component {a.component.name!r}: joined through resistances alone to "
                             f"{fixed[root][0]}: with the valve closed air flows between them, no held operating "
                             "point; linearise at the open valve's equilibrium or at a time of its run (--at-time)")
        fixed[root] = (f"supply {a.component.name!r}", _supply_pressure_Pa(a.component, a.connect, supply_gauge_Pa))
    out = {}
    for a in added:
        pneumatic = any(port.kind is PNEUMATIC for port in a.component.ports)
        if not (pneumatic and a.component.states and callable(getattr(a.component, "held_state", None))):
            continue
        owner, p_abs = fixed.get(group.get(a.component.name), (None, None))
        if p_abs is None:
            why = (f"its {owner} takes its set pressure from no model input" if owner
                   else "joined by resistances to neither the muscle nor a supply, it could rest at any pressure")
            raise InputError(f"component {a.component.name!r}: nothing fixes its pressure at a held operating point "
                             f"({why}); linearise at the open valve's equilibrium or at a time of its run (--at-time)")
        out[a.component.name] = float(p_abs)
    return out
