"""A scenario's ``[[component]]`` tables: components added to the rig, checked and wired.

::

    [[component]]
    name = "spring"            # unique, and not one of the rig's own (load, muscle, chamber, ...)
    type = "linear_spring"     # pamsim.components.COMPONENT_TYPES
    k_N_per_m = 400.0          # each of its parameters, by name
    x_free_m = 0.0
    [component.connect]        # each of its ports and inputs -> a port or output of the rig or of
    flange = "load.flange"     # another added component

Every mistake is refused with the table's index and the key: an unknown type or parameter, a missing
or non-numeric value, a name taken, and every wiring error of the assembly (an unconnected port, a
unit mismatch, an algebraic loop), which :func:`check_wiring` finds by flattening the scenario's
assembly once per structure.
"""

from __future__ import annotations

from typing import Any

from .assemblies.muscle_only import MUSCLE_ONLY_COMPONENTS
from .assemblies.one_muscle import RIG_COMPONENTS, AddedComponent, scenario_assembly
from .components.catalogue import COMPONENT_TYPES
from .components.bouc_wen_friction import BoucWenFriction
from .components.maxwell_slip_friction import MAX_ELEMENTS, MaxwellSlip, prandtl_ishlinskii
from .modeling import PNEUMATIC, AssemblyError
from .table_checks import did_you_mean, number_problem

RESERVED_KEYS = ("name", "type", "connect")

_CHECKED: set = set()
"""Assembly structures whose wiring has been checked in this process (a sweep's cases share one)."""


def added_components(v, entries: list) -> tuple[AddedComponent, ...]:
    """The :class:`AddedComponent` s of a scenario's ``component`` array; ``v`` is the scenario's
    validator (its ``fail(key, value, why, choices=...)`` raises)."""
    out, names = [], set()
    for i, entry in enumerate(entries):
        where = f"component[{i}]"
        if not isinstance(entry, dict):
            v.fail(where, entry, "must be a table ([[component]])")
        name = _component_name(v, where, entry, names)
        names.add(name)
        kind = entry.get("type")
        if kind not in COMPONENT_TYPES:
            v.fail(f"{where}.type", kind, "unknown component type", choices=sorted(COMPONENT_TYPES))
        cls = COMPONENT_TYPES[kind]
        options = _component_options(v, where, cls, entry)
        declared = cls.scenario_parameters(options) if hasattr(cls, "scenario_parameters") else cls.parameters
        values = _component_values(v, where, kind, declared, {k: e for k, e in entry.items() if k not in options},
                                   getattr(cls, "defaults", {}))
        connect = entry.get("connect", {})
        if not isinstance(connect, dict) or not all(isinstance(t, str) for t in connect.values()):
            v.fail(f"{where}.connect", connect, 'must be a table of its ports and inputs, e.g. {flange = "load.flange"}')
        component = cls(name, values, **options)
        _refuse_self_joined(v, where, component, connect)
        out.append(AddedComponent(component, dict(connect)))
    return tuple(out)


def _refuse_self_joined(v, where: str, component: Any, connect: dict) -> None:
    """Two ports of one component wired to one port: it would act between a volume (or a flange) and itself,
    passing nothing (a tube whose ends are on one volume).  Two inputs may read one output."""
    seen: dict[str, str] = {}
    for port in (p.name for p in component.ports):
        target = connect.get(port)
        if target is None:
            continue
        if target in seen:
            v.fail(f"{where}.connect.{port}", target, f"is where its {seen[target]} is connected too: the component "
                   "would join a port to itself and pass nothing")
        seen[target] = port


def _component_options(v, where: str, cls, entry: dict) -> dict[str, str]:
    """The entry's choices of form (a reservoir's ``law``, a tube's ``inlet``): each one of the names the
    class offers (its ``choices``, the first the default when the key is left out), and its ``settings``
    (a tube's ``segments``), each checked by the class's own test of it."""
    options = {}
    for key, names in getattr(cls, "choices", {}).items():
        if key in entry:
            if entry[key] not in names:
                v.fail(f"{where}.{key}", entry[key], "unknown choice", choices=names)
            options[key] = entry[key]
    for key, violation in getattr(cls, "settings", {}).items():
        if key in entry:
            why = violation(entry[key])
            if why:
                v.fail(f"{where}.{key}", entry[key], why)
            options[key] = entry[key]
    return options


def _component_name(v, where: str, entry: dict, taken: set) -> str:
    """The entry's name: an identifier, not the rig's own components' (a muscle alone's among them) nor an
    earlier entry's."""
    name = entry.get("name")
    if not isinstance(name, str) or not name.isidentifier():
        v.fail(f"{where}.name", name, "must be a name made of letters, digits and underscores")
    if name in RIG_COMPONENTS or name in MUSCLE_ONLY_COMPONENTS or name in taken:
        v.fail(f"{where}.name", name, "is taken (by the rig's own components, a muscle alone's ("
               f"{', '.join(sorted(MUSCLE_ONLY_COMPONENTS))}) or an earlier [[component]])")
    return name


def _component_values(v, where: str, kind: str, parameters, entry: dict, defaults=None) -> dict[str, float]:
    """The entry's parameter values: each declared, a finite number in its range, none missing that has
    no default (``defaults``: the class's)."""
    declared = {p.name: p for p in parameters}
    values: dict[str, float] = {}
    for key, value in entry.items():
        if key in RESERVED_KEYS:
            continue
        if key not in declared:
            v.fail(f"{where}.{key}", value, f"not a parameter of {kind}" + did_you_mean(key, list(declared)),
                   choices=list(declared))
        why = number_problem(value)
        if why:
            v.fail(f"{where}.{key}", value, why)
        why = declared[key].violation(float(value))
        if why:
            v.fail(f"{where}.{key}", value, why)
        values[key] = float(value)
    needed = [key for key in declared if key not in (defaults or {})]
    for key in needed:
        if key not in values:
            raise v.error(f"{v.origin}: missing key {where}.{key}: {kind} needs {', '.join(needed)}")
    return values


HYSTERESIS_KEYS = {"maxwell_slip": ("slip_displacement_m", "share", "damping_N_s_per_m"),
                   "bouc_wen": ("beta_per_m_n", "gamma_per_m_n", "exponent"),
                   "pi": ("thresholds_m", "weights_N_per_m", "envelope_scale_m")}
"""The hysteresis models a ``[hysteresis]`` table puts in the muscle's force balance, and their keys."""


LEVEL_SHARING = ("maxwell_slip", "bouc_wen")
"""The ``[hysteresis]`` models whose forces are parts of the ``[model] friction`` law's level."""


def hysteresis_component(v, table: dict, law, pressure: str, added: tuple) -> AddedComponent:
    """The ``[hysteresis]`` table's model in place of the rig's Coulomb friction, reading the level of its law
    ``law`` (the ``[model] friction`` one) from the muscle's pressure (``<pressure>.p_gauge_Pa``) and the
    load's mass; ``added``: the ``[[component]]`` s, whose names it must not take.

    ::

        [hysteresis]
        model = "maxwell_slip"
        slip_displacement_m = [2e-4, 1e-3]   # per element, > 0
        share = [0.5, 0.5]                   # per element, >= 0: its part of the friction law's level

        [hysteresis]
        model = "bouc_wen"
        beta_per_m_n = 500.0                 # beta + gamma > 0
        gamma_per_m_n = 500.0
        exponent = 1.0                       # n > 0

        [hysteresis]
        model = "pi"                         # generalized Prandtl-Ishlinskii, its hysteretic (stop) part
        thresholds_m = [2e-4, 1e-3, 4e-3]    # r_j, strictly increasing, > 0
        weights_N_per_m = [3750, 750, 250]   # w_j >= 0
        envelope_scale_m = 0.05              # optional: s of g(x) = s tanh(x / s); none, g(x) = x
    """
    model = v.required(table, "model", prefix="hysteresis.")
    if not isinstance(model, str) or model not in HYSTERESIS_KEYS:
        v.fail("hysteresis.model", model, "unknown hysteresis model", choices=list(HYSTERESIS_KEYS))
    keys = ["model", *HYSTERESIS_KEYS[model]]
    for key in sorted(set(table) - set(keys)):
        v.fail(f"hysteresis.{key}", table[key], f"unknown key for model = {model!r}", choices=keys)
    if any(a.component.name == "hysteresis" for a in added):
        v.fail("component", "hysteresis", "the name is taken by the [hysteresis] table's model")
    zero = _zero_level(law) if model in LEVEL_SHARING else None
    if zero is not None:
        # Their forces are parts of the law's level; at a level of 0 only the presliding damping would act.
        v.fail(*zero, f"the friction law's level is 0 at every point, so the [hysteresis] {model} model that "
               "shares it has no slip force; give the law it shares a level ('load_dependent' or 'constant' with "
               "a nonzero coefficient), or use hysteresis.model = 'pi', whose forces are its own weights")
    component = {"maxwell_slip": _maxwell_slip, "bouc_wen": _bouc_wen, "pi": _prandtl_ishlinskii}[model](v, table, law)
    return AddedComponent(component, {"flange": "load.flange", "p_gauge_Pa": f"{pressure}.p_gauge_Pa",
                                      "mass_kg": "load.mass_kg"})


def _zero_level(law) -> tuple[str, Any] | None:
    """``(key, value)`` that makes the ``[model] friction`` law's level 0 at every contraction, pressure and
    load (no law, a constant law of 0 N, the paper's law with its three coefficients 0), or None."""
    name = getattr(law, "name", None)
    if name == "none":
        return "model.friction", "none"
    if name == "constant" and law.level_constant_N == 0.0:
        return "parameters.coulomb_constant_N", law.level_constant_N
    if name == "load_dependent" and law.N2_N_per_bar_m2 == law.N1_N_per_bar_m == law.N0_N_per_bar == 0.0:
        return "parameters.N0_N_per_bar", law.N0_N_per_bar
    return None


def _maxwell_slip(v, table: dict, law) -> MaxwellSlip:
    lists = {}
    for key in ("slip_displacement_m", "share"):
        values = table.get(key)
        if not isinstance(values, list) or not 1 <= len(values) <= MAX_ELEMENTS:
            v.fail(f"hysteresis.{key}", values, f"must be an array of 1 to {MAX_ELEMENTS} numbers, one per element")
        lists[key] = [v.number(f"hysteresis.{key}[{i}]", x) for i, x in enumerate(values)]
    deltas, shares = lists["slip_displacement_m"], lists["share"]
    if len(deltas) != len(shares):
        v.fail("hysteresis.share", table["share"], f"has {len(shares)} values for {len(deltas)} elements")
    for i, (d, w) in enumerate(zip(deltas, shares)):
        if d <= 0:
            v.fail(f"hysteresis.slip_displacement_m[{i}]", d, "must be > 0 (the element's stiffness is its slip "
                   "force over it)")
        if w < 0:
            v.fail(f"hysteresis.share[{i}]", w, "must be >= 0 (a negative slip force)")
    c = v.number("hysteresis.damping_N_s_per_m", table.get("damping_N_s_per_m", 0.0))
    if c < 0:
        v.fail("hysteresis.damping_N_s_per_m", c, "must be >= 0")
    return MaxwellSlip("hysteresis", law, deltas, shares, c)


def _element_list(v, table: dict, key: str) -> list[float]:
    """``hysteresis.KEY``: an array of 1 to :data:`MAX_ELEMENTS` numbers."""
    values = table.get(key)
    if not isinstance(values, list) or not 1 <= len(values) <= MAX_ELEMENTS:
        v.fail(f"hysteresis.{key}", values, f"must be an array of 1 to {MAX_ELEMENTS} numbers, one per element")
    return [v.number(f"hysteresis.{key}[{i}]", x) for i, x in enumerate(values)]


def _prandtl_ishlinskii(v, table: dict, law) -> MaxwellSlip:
    """The ``pi`` model: its forces are its own weights and thresholds, not the friction law's level."""
    r, w = _element_list(v, table, "thresholds_m"), _element_list(v, table, "weights_N_per_m")
    if len(w) != len(r):
        v.fail("hysteresis.weights_N_per_m", table["weights_N_per_m"], f"has {len(w)} values for {len(r)} thresholds")
    if r[0] <= 0:
        v.fail("hysteresis.thresholds_m[0]", r[0], "must be > 0 (a play of threshold 0 has no hysteretic part)")
    for i in range(1, len(r)):
        if r[i] <= r[i - 1]:
            v.fail(f"hysteresis.thresholds_m[{i}]", r[i], f"thresholds must increase strictly "
                   f"(thresholds_m[{i - 1}] = {r[i - 1]!r})")
    for i, x in enumerate(w):
        if x < 0:
            v.fail(f"hysteresis.weights_N_per_m[{i}]", x, "must be >= 0")
    s = table.get("envelope_scale_m")
    if s is not None and v.number("hysteresis.envelope_scale_m", s) <= 0:
        v.fail("hysteresis.envelope_scale_m", s, "must be > 0 (leave it out for the classical operator)")
    return prandtl_ishlinskii("hysteresis", r, w, None if s is None else float(s))


def _bouc_wen(v, table: dict, law) -> BoucWenFriction:
    values = {key: v.number(f"hysteresis.{key}", v.required(table, key, prefix="hysteresis."))
              for key in HYSTERESIS_KEYS["bouc_wen"]}
    if values["exponent"] <= 0:
        v.fail("hysteresis.exponent", values["exponent"], "must be > 0")
    if values["beta_per_m_n"] + values["gamma_per_m_n"] <= 0:
        v.fail("hysteresis.gamma_per_m_n", values["gamma_per_m_n"], f"beta + gamma must be > 0 (beta = "
               f"{values['beta_per_m_n']:g}): else z grows without bound on loading")
    return BoucWenFriction("hysteresis", law, **values)


def refuse_added(scenario: Any, what: str, error: type[Exception], hysteresis: bool = False,
                 lines_allowed: bool = False) -> None:
    """Raise ``error`` if ``scenario`` adds components to the rig: ``what`` (a command, a study) works
    on the rig alone and would leave them out without a word.  ``hysteresis``: the ``[hysteresis]`` table's
    model is welcome (``what`` runs it, and designs without the muscle's friction anyway).

    With ``lines_allowed``, components whose every port is pneumatic (a supply, a reservoir, a tube: a
    line to the valve or from it) pass: ``what`` takes the chamber at the supply's pressure, where such a
    line leaves it once its flows have stopped, and it needs nothing else of them.
    """
    refused = [a for a in scenario.added_components
               if not (hysteresis and "hysteresis" in scenario.spec and a.component.name == "hysteresis")
               and not (lines_allowed and is_line_component(a.component))]
    if refused:
        names = ", ".join(repr(a.component.name) for a in refused)
        alone = "the rig and its pneumatic line alone" if lines_allowed else "the rig alone"
        raise error(f"{scenario.origin}: component: {what} takes {alone}, not the components added to it "
                    f"({names}); run the scenario with `pamsim run` (python or native backend)")


def check_pressure_ports(v, pressure: dict, added: tuple) -> None:
    """``pressure.supply_port`` and ``pressure.outlet_port`` must each name a pneumatic port of a
    ``[[component]]`` (the rig's own chamber is the valve's outlet when ``outlet_port`` is left out), not
    both the same: refused naming the key, with the closest name."""
    components = {a.component.name: a.component for a in added}
    for key in ("supply_port", "outlet_port"):
        if key not in pressure:
            continue
        name, _, port = pressure[key].partition(".")
        if name not in components:
            where = (f"{name!r} is the rig's own component, not a [[component]]" if name in RIG_COMPONENTS
                     else f"no [[component]] is named {name!r}" if components
                     else "the scenario has no [[component]] for the valve to be wired to")
            v.fail(f"pressure.{key}", pressure[key], f"{where}; the key names a port of one as \"name.port\"",
                   choices=[f"{n}.{p.name}" for n, c in components.items() for p in c.ports if p.kind is PNEUMATIC]
                   or None)
        ports = [p.name for p in components[name].ports if p.kind is PNEUMATIC]
        if port not in ports:
            v.fail(f"pressure.{key}", pressure[key], f"component {name!r} ({type(components[name]).__name__}) has "
                   "no pneumatic port so named", choices=[f"{name}.{p}" for p in ports] or None)
    if "supply_port" in pressure and pressure.get("outlet_port") == pressure["supply_port"]:
        # The valve's two sides on one volume: it passes nothing, and the muscle never sees the supply.
        v.fail("pressure.outlet_port", pressure["outlet_port"], "is the valve's supply side too (pressure.supply_port): "
               "the valve would join a volume to itself; its outlet is the port toward the muscle")


def is_line_component(component: Any) -> bool:
    """Whether every port of ``component`` is pneumatic (a supply, a reservoir, a tube): it adds no force
    to the load and changes no static equilibrium."""
    return bool(component.ports) and all(port.kind is PNEUMATIC for port in component.ports)


def check_wiring(scenario: Any, error: type[Exception]) -> None:
    """Refuse (``error``, the scenario's) a scenario whose added components do not wire into the rig,
    naming the component and the port."""
    try:
        assembly = scenario_assembly(scenario)
        key = assembly.structure_key()
        if key not in _CHECKED:
            assembly.flatten()
            _CHECKED.add(key)
        _refuse_isolated(scenario, assembly)
    except (AssemblyError, KeyError, ValueError) as exc:
        text = str(exc.args[0] if isinstance(exc, KeyError) and exc.args else exc)
        raise error(f"{scenario.origin}: [[component]]: {text}{_valve_port_hint(scenario, text)}") from None


def _valve_port_hint(scenario: Any, text: str) -> str:
    """Where a wiring error names a port of a component the valve is wired to (``pressure.supply_port``,
    ``pressure.outlet_port``) on a port a ``connect`` table joins too, which of those keys wired it: the
    likely cause (the valve on the tube's outlet, which the tube joins to the chamber, leaves its inlet
    unconnected).  A valve alone on its port is wired as it should be: the error is elsewhere."""
    pressure = scenario.spec.get("pressure", {})
    joined = set()
    for table in scenario.spec.get("component", []):
        connect = table.get("connect") if isinstance(table, dict) else None
        if isinstance(connect, dict):
            joined |= {f"{table.get('name')}.{port}" for port in connect} | {v for v in connect.values()
                                                                            if isinstance(v, str)}
    keys = [f"pressure.{k} = {pressure[k]!r}" for k in ("supply_port", "outlet_port")
            if isinstance(pressure.get(k), str) and pressure[k] in joined
            and f" {pressure[k].partition('.')[0]}." in f" {text}"]
    return f" (the valve is wired by {' and '.join(keys)})" if keys else ""


def _refuse_isolated(scenario: Any, assembly: Any) -> None:
    """Refuse added components that no chain of connections joins to the rig or to its inputs (their own
    ``connect`` tables, another component's, or the valve's ``pressure.supply_port`` and ``outlet_port``): a
    chain that is not connected.  A lone node port is valid inside the assembly (a volume a branch may join),
    so the assembly's own check lets such a component through, alone or with others joined only to each
    other, and they would be integrated beside the rig, doing nothing."""
    parent: dict[str, str] = {}

    def root(name: str) -> str:
        while parent.setdefault(name, name) != name:
            name = parent[name]
        return name
    for a_ref, b_ref in assembly.connections:
        parent[root(a_ref.split(".", 1)[0])] = root(b_ref.split(".", 1)[0])
    # the rig, and what reads the rig's own inputs (a supply set to the scenario's supply pressure)
    joined = {root(name) for name in RIG_COMPONENTS}
    joined |= {root(ref.split(".", 1)[0]) for refs in assembly.inputs.values() for ref in refs}
    tables = [e.get("name") if isinstance(e, dict) else None for e in scenario.spec.get("component", [])]
    for added in scenario.added_components:
        c = added.component
        if c.ports and c.name in tables and root(c.name) not in joined:
            raise AssemblyError(f"component[{tables.index(c.name)}] ({c.name!r}, {type(c).__name__}) is connected "
                                "to nothing that reaches the rig: connect one of its ports (its [component.connect] "
                                "table, another component's, or pressure.supply_port / pressure.outlet_port)")
