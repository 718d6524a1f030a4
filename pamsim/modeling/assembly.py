"""Connecting components into one flat model.

An :class:`Assembly` takes components, connections between their ports and signals, and the
component inputs that the model exposes as its own inputs.  :meth:`Assembly.flatten` checks the
wiring (names given twice, unconnected ports and inputs, ports of different kinds, signals of
different units, two nodes on one net, algebraic loops) and returns a :class:`~.flat.FlatModel`
whose equations are CasADi expressions of the states, inputs, parameters and modes only.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, replace
from typing import Mapping, Sequence

from .component import Component, Equations, Symbols, quiet_numpy_on_symbols
from .flat import External, FlatModel
from .variables import Var


class AssemblyError(ValueError):
    """A wiring mistake; the message names the component and the port or signal."""


@dataclass(frozen=True)
class _Endpoint:
    component: Component
    name: str
    kind: str  # "port", "output" or "input"

    @property
    def label(self) -> str:
        return f"{self.component.name}.{self.name}"


class Assembly:
    """Components, their connections and the model's inputs.

    Parameters
    ----------
    components : the components, each with a name unique in the assembly.
    connections : pairs ``("a.port", "b.port")`` of ports of one kind (a node and a branch, or two
        branches of one net), or ``("a.output", "b.input")`` of signals with one unit.  A node sums
        its branches' through variables in the order they are first connected.
    inputs : ``{model input name: "component.input"}`` (a string or a tuple of them, for one model
        input that drives several component inputs).
    name : the assembly's name (used in generated code).
    """

    def __init__(self, components: Sequence[Component], connections: Sequence[tuple[str, str]] = (),
                 inputs: Mapping[str, str | Sequence[str]] | None = None, name: str = "model"):
        self.name = name
        self.components = tuple(components)
        self.connections = tuple(tuple(c) for c in connections)
        self._key = None
        self._values: tuple[float, ...] | None = None
        self.inputs = {k: (v,) if isinstance(v, str) else tuple(v) for k, v in (inputs or {}).items()}
        by_name: dict[str, Component] = {}
        for c in self.components:
            if c.name in by_name:
                raise AssemblyError(f"component name {c.name!r} is given twice "
                                    f"({type(by_name[c.name]).__name__} and {type(c).__name__})")
            if not c.name.isidentifier():
                raise AssemblyError(f"component name {c.name!r} is not an identifier")
            by_name[c.name] = c
        self.by_name = by_name

    # ------------------------------------------------------------------ wiring
    def _endpoint(self, ref: str) -> _Endpoint:
        comp_name, _, local = ref.partition(".")
        comp = self.by_name.get(comp_name)
        if comp is None or not local:
            raise AssemblyError(f"connection end {ref!r}: no component {comp_name!r} "
                                f"(components: {', '.join(self.by_name)})")
        if any(p.name == local for p in comp.ports):
            return _Endpoint(comp, local, "port")
        if any(v.name == local for v in comp.outputs):
            return _Endpoint(comp, local, "output")
        if any(v.name == local for v in comp.inputs):
            return _Endpoint(comp, local, "input")
        raise AssemblyError(f"connection end {ref!r}: component {comp_name!r} ({type(comp).__name__}) has no port, "
                            f"output or input {local!r}")

    def _nets(self) -> list[list[_Endpoint]]:
        """Connected ports grouped into nets, each checked for one kind and exactly one node."""
        ends = {f"{c.name}.{p.name}": _Endpoint(c, p.name, "port") for c in self.components for p in c.ports}
        parent = {label: label for label in ends}
        for a, b in self._port_connections():
            parent[_root(parent, a.label)] = _root(parent, b.label)
        nets, unconnected = [], []
        for members in self._groups(ends, parent):
            lone = _lone_port(members)
            if lone:
                unconnected.append(lone)
            else:
                nets.append(_with_one_node(members))
        if unconnected:
            raise AssemblyError(f"port{'s' if len(unconnected) > 1 else ''} {', '.join(unconnected)} "
                                f"{'are' if len(unconnected) > 1 else 'is'} not connected")
        return nets

    def _port_connections(self):
        """The connections of two ports, as endpoints, checked one by one as they are read (a signal is skipped)."""
        for a_ref, b_ref in self.connections:
            a, b = self._endpoint(a_ref), self._endpoint(b_ref)
            if (a.kind == "port") != (b.kind == "port"):
                raise AssemblyError(f"cannot connect {a.label} ({a.kind}) to {b.label} ({b.kind}): "
                                    "a port connects to a port, a signal to a signal")
            if a.kind != "port":
                continue
            ka, kb = a.component.port(a.name).kind, b.component.port(b.name).kind
            if ka != kb:
                raise AssemblyError(f"cannot connect port {a.label} ({ka.name}) to port {b.label} ({kb.name}): "
                                    "the kinds differ")
            yield a, b

    def _groups(self, ends: dict[str, _Endpoint], parent: dict[str, str]) -> list[list[_Endpoint]]:
        """The ports of each net (by union-find root), the nets in order of their first member."""
        # A net's branches in the order they were first connected: the node sums their through
        # variables in that order, so a floating-point sum is the same whatever the component order.
        first = {}
        for i, pair in enumerate(self.connections):
            for ref in pair:
                first.setdefault(ref, i)
        groups: dict[str, list[_Endpoint]] = defaultdict(list)
        for label, ep in sorted(ends.items(), key=lambda item: first.get(item[0], len(self.connections))):
            groups[_root(parent, label)].append(ep)
        return list(groups.values())

    def _signal_sources(self) -> dict[str, tuple[str, str]]:
        """``{"comp.input": ("output", "comp.output") or ("input", model input name)}``, every input bound once."""
        bound: dict[str, tuple[str, str]] = {}
        for a, b in self._signal_connections():
            _bind(bound, b, ("output", a.label))
        for model_input, refs in self.inputs.items():
            for ep in self._model_input_ends(model_input, refs):
                _bind(bound, ep, ("input", model_input))
        for c in self.components:
            for v in c.inputs:
                if f"{c.name}.{v.name}" not in bound:
                    raise AssemblyError(f"input {c.name}.{v.name} [{v.unit}] is not connected")
        return bound

    def _signal_connections(self):
        """The connections of an output to an input, as ``(output, input)`` endpoints, checked one by one as
        they are read (a port connection is skipped: :meth:`_port_connections` has it)."""
        for a_ref, b_ref in self.connections:
            a, b = self._endpoint(a_ref), self._endpoint(b_ref)
            if a.kind == "port":
                continue
            if a.kind == "input" and b.kind == "output":
                a, b = b, a
            if not (a.kind == "output" and b.kind == "input"):
                raise AssemblyError(f"cannot connect {a.label} ({a.kind}) to {b.label} ({b.kind}): "
                                    "a signal connects an output to an input")
            ua, ub = _var(a.component.outputs, a.name).unit, _var(b.component.inputs, b.name).unit
            if ua != ub:
                raise AssemblyError(f"cannot connect {a.label} [{ua}] to {b.label} [{ub}]: the units differ")
            yield a, b

    def _model_input_ends(self, model_input: str, refs: Sequence[str]):
        """The component inputs one model input drives, each checked to be an input as it is read, and all of
        one unit (checked after the last)."""
        units = set()
        for ref in refs:
            ep = self._endpoint(ref)
            if ep.kind != "input":
                raise AssemblyError(f"model input {model_input!r}: {ep.label} is a {ep.kind}, not an input")
            units.add(_var(ep.component.inputs, ep.name).unit)
            yield ep
        if len(units) > 1:
            raise AssemblyError(f"model input {model_input!r} drives inputs of different units {sorted(units)}")

    def indicator_names(self) -> list[tuple[str, str]]:
        """``(component, name)`` of each event indicator of the flat model, in its order: a hybrid component's
        are ``indicator<k>`` (its modes name its events), another's its :attr:`Component.indicator_names`."""
        out = []
        for c in self.components:
            names = () if c.modes is not None else c.indicator_names
            out += [(c.name, names[k] if k < len(names) else f"indicator{k}") for k in range(c.n_indicators)]
        return out

    def structure_key(self) -> tuple:
        """Equal for two assemblies that generate the same code (they may differ in parameter values)."""
        if self._key is None:  # kept: an assembly does not change after it is made
            self._key = (self.name, tuple((c.name, c.structure_key()) for c in self.components), self.connections,
                         tuple(self.inputs.items()))  # in their order: the flat model's inputs follow it
        return self._key

    def parameter_values(self) -> list[float]:
        """The parameter vector of the flat model, in its order, without flattening."""
        if self._values is None:  # kept, as the key is: a run asks for it twice (its inputs, its outputs)
            self._values = tuple(float(c.values[v.name]) for c in self.components for v in c.parameter_vars())
        return list(self._values)

    # ------------------------------------------------------------------ flattening
    def flatten(self, modes: Mapping[str, int] | None = None) -> FlatModel:
        """Check the wiring and return the flat model.

        ``modes`` fixes the mode of named hybrid components: their equations are then written for that
        mode alone (no mode logic left in them), for an integrator that runs one mode at a time.  Those
        components have no mode symbol (``q``) in the result; their indicators, jumps and rest modes are
        still there, for that mode.
        """
        import casadi as ca

        nets = self._nets()
        signal_sources = self._signal_sources()
        model_inputs = {name: ca.SX.sym(name) for name in self.inputs}
        work = _Flattening(ca, self.components, dict(modes or {}))
        bindings = _signal_bindings(signal_sources, model_inputs, work.equations)
        bindings.update(_net_bindings(ca, nets, work.equations))
        work.substitute(_resolve(work.placeholders, bindings))
        return work.flat_model(self.name, self._input_vars(), list(model_inputs.values()))

    def _input_vars(self) -> list[Var]:
        """The model's inputs, each with the unit of the (first) component input it drives; one that drives
        none (the supply pressure of a valve whose supply side is a volume of a line) keeps its place, with
        the unit its name ends in (``_Pa``)."""
        return [Var(n, _var(self._endpoint(refs[0]).component.inputs, self._endpoint(refs[0]).name).unit if refs
                    else n.rsplit("_", 1)[-1]) for n, refs in self.inputs.items()]


class _Flattening:
    """One flattening: the components' symbols and equations, then their expressions in the flat model's terms.

    Symbols are made in the components' order, which is the flat model's order of states, parameters,
    modes and event flags.
    """

    def __init__(self, ca, components: Sequence[Component], modes: dict[str, int]):
        self.ca, self.components, self.modes = ca, components, modes
        self.params, self.states, self.placeholders = [], [], {}
        self.symbols: dict[str, Symbols] = {}
        self.mode_syms = {}
        self.fired_syms: tuple = ()
        self.externals: list[External] = []
        self.tol = ca.SX.sym("tol")
        self.resolved: dict = {}
        for c in components:
            self._declare(c)
        with quiet_numpy_on_symbols():
            self.equations = {c.name: _checked(c, c.equations(self.symbols[c.name])) for c in components}

    def _syms(self, c: Component, vs, infix: str = "") -> dict:
        """A symbol for each variable, named ``component.[infix]variable``."""
        return {v.name: self.ca.SX.sym(f"{c.name}.{infix}{v.name}") for v in vs}

    def _declare(self, c: Component) -> None:
        """Make the component's symbols and note its parameters, states and placeholders."""
        p, x, u = self._syms(c, c.parameter_vars()), self._syms(c, c.states), self._syms(c, c.inputs)
        # A node reads the sum of its branches' through variables, a branch its node's across ones.
        port = {pt.name: self._syms(c, pt.kind.through if pt.role == "node" else pt.kind.across, f"{pt.name}.")
                for pt in c.ports}
        mode, fired = self._mode(c)
        self.symbols[c.name] = Symbols(p, x, u, port, mode, fired, self._external(c), self.tol)
        self.params += [(c, v, p[v.name]) for v in c.parameter_vars()]
        self.states += [(c, v, x[v.name]) for v in c.states]
        self.placeholders.update({f"{c.name}.{k}": s for k, s in u.items()})
        for pt_name, vs in port.items():
            self.placeholders.update({f"{c.name}.{pt_name}.{k}": s for k, s in vs.items()})

    def _mode(self, c: Component) -> tuple:
        """The component's mode (a number if fixed, a symbol if free, None without modes) and its event flags."""
        mode = None
        if c.name in self.modes:
            mode = float(c.modes(self.modes[c.name]))
        elif c.modes is not None:
            mode = self.mode_syms[c.name] = self.ca.SX.sym(f"{c.name}.mode")
        fired = ()
        if c.n_indicators:
            fired = tuple(self.ca.SX.sym(f"{c.name}.fired{k}") for k in range(c.n_indicators))
            self.fired_syms += fired
        return mode, fired

    def _external(self, component: Component):
        """The component's :attr:`Symbols.external`: a symbol for each call, noted with its function and arguments."""
        def call(name: str, fn, *args, casadi=None):
            sym = self.ca.SX.sym(f"{component.name}.{name}#{len(self.externals)}")
            self.externals.append(External(f"{component.name}.{name}", fn, sym, [self.ca.SX(a) for a in args], casadi))
            return sym
        return call

    def substitute(self, resolved: dict) -> None:
        """From now on :meth:`_flat` replaces each placeholder by its resolved expression."""
        self.resolved = resolved

    def _flat(self, expr):
        """``expr`` with no placeholder left: in states, inputs, parameters and modes only."""
        ca, resolved = self.ca, self.resolved
        return ca.substitute([ca.SX(expr)], list(resolved), list(resolved.values()))[0] if resolved else ca.SX(expr)

    def _mode_of(self, c: Component):
        """The mode a component keeps when no event moves it: its symbol if free, else its fixed value."""
        return self.mode_syms[c.name] if c.name in self.mode_syms else float(c.modes(self.modes[c.name]))

    def flat_model(self, name: str, inputs: list[Var], u: list) -> FlatModel:
        """The flat model (``inputs``: the model's input variables, ``u``: their symbols)."""
        hybrid = [c for c in self.components if c.modes is not None]
        # Made in the order the flat model lists them, as they always were, so that nothing that may follow
        # the order in which CasADi's nodes are made can change the generated code.
        state_exprs = self._state_expressions()
        outputs = [self._flat(self.equations[c.name].outputs[v.name]) for c in self.components for v in c.outputs]
        # Components with events but no modes (their state jumps at a crossing, as an elasto-slide element's
        # deflection is held at its slip limit) list their indicators among the hybrid ones, in component order.
        mode_exprs = self._indicators([c for c in self.components if c.n_indicators])
        mode_exprs.update(self._mode_expressions(hybrid, state_exprs["x0"]))
        externals = [External(e.name, e.fn, e.symbol, [self._flat(a) for a in e.args], e.casadi) for e in self.externals]
        return FlatModel(name=name, inputs=inputs, u=u, y=outputs, tol=self.tol, externals=externals,
                         **self._variables(), **self._symbol_lists(hybrid), **state_exprs, **mode_exprs)

    def _symbol_lists(self, hybrid: list[Component]) -> dict:
        """The hybrid components with their modes, and the state, parameter, mode and event flag symbols."""
        return {"modes": [(c.name, c.modes) for c in hybrid], "x": [s for _, _, s in self.states],
                "p": [s for _, _, s in self.params],
                "q": [self.mode_syms[c.name] for c in hybrid if c.name not in self.modes], "e": list(self.fired_syms)}

    def _variables(self) -> dict:
        """The flat model's states, outputs and parameters (namespaced) and the parameters' values."""
        return {"states": [_namespaced(c, v) for c, v, _ in self.states],
                "outputs": [_namespaced(c, v) for c in self.components for v in c.outputs],
                "parameters": [_namespaced(c, v) for c, v, _ in self.params],
                "parameter_values": [float(c.values[v.name]) for c, v, _ in self.params]}

    def _state_expressions(self) -> dict:
        """Per state: its initial value, its value after an event and settled, and its derivative."""
        eq, states = self.equations, self.states
        initial = _initial_states(states, {c.name: eq[c.name].initial for c in self.components}, self._flat)
        return {"x0": initial,
                "transition_x": [self._flat(eq[c.name].transition.get(v.name, sym)) for c, v, sym in states],
                "settle_x": [self._flat(eq[c.name].settle.get(v.name, sym)) for c, v, sym in states],
                "f": [self._flat(eq[c.name].der[v.name]) for c, v, _ in states]}

    def _indicators(self, eventful: list[Component]) -> dict:
        """The indicators of the components that have them, and their margins, in the components' order."""
        eq, flat = self.equations, self._flat
        return {"z": [flat(z) for c in eventful for z in eq[c.name].indicators],
                "z_margin": [flat(m) for c in eventful for m in (eq[c.name].indicator_margins or (0.0,) * c.n_indicators)]}

    def _mode_expressions(self, hybrid: list[Component], initial: list) -> dict:
        """Per hybrid component: its mode after an event, at rest and at the start."""
        ca, eq, flat = self.ca, self.equations, self._flat
        out = {"transition_q": [flat(eq[c.name].transition.get("mode", self._mode_of(c))) for c in hybrid],
               "rest_q": [flat(eq[c.name].rest_mode) for c in hybrid]}
        out["q0"] = [flat(ca.substitute([ca.SX(eq[c.name].initial.get("mode", 0.0))],
                                        [sym for _, _, sym in self.states], initial)[0]) for c in hybrid]
        return out


def _signal_bindings(signal_sources: dict[str, tuple[str, str]], model_inputs: dict, equations: dict) -> dict:
    """Each component input's placeholder name -> the model input or the component output that drives it."""
    bindings: dict[str, object] = {}
    for label, (kind, source) in signal_sources.items():
        if kind == "input":
            bindings[label] = model_inputs[source]
        else:
            comp, out = source.split(".", 1)
            bindings[label] = equations[comp].outputs[out]
    return bindings


def _net_bindings(ca, nets: list[list[_Endpoint]], equations: dict) -> dict:
    """Each port variable's placeholder name -> its value: a branch reads its node's across variables,
    a node the sum of its branches' through variables, in the net's order."""
    bindings: dict[str, object] = {}
    for members in nets:
        node = _nodes(members)[0]
        kind = node.component.port(node.name).kind
        branches = [e for e in members if e is not node]
        for v in kind.across:
            for b in branches:
                bindings[f"{b.label}.{v.name}"] = equations[node.component.name].port[node.name][v.name]
        for v in kind.through:
            total = ca.SX(0.0)
            for b in branches:
                total = total + equations[b.component.name].port[b.name][v.name]
            bindings[f"{node.label}.{v.name}"] = total
    return bindings


def _namespaced(c: Component, v: Var) -> Var:
    """The component's variable under its flat model name, ``component.variable``."""
    return replace(v, name=f"{c.name}.{v.name}")


def _var(vs: Sequence[Var], name: str) -> Var:
    return next(v for v in vs if v.name == name)


def _bind(bound: dict[str, tuple[str, str]], ep: _Endpoint, source: tuple[str, str]) -> None:
    """Bind input ``ep`` to ``source`` (``("output", label)`` or ``("input", model input)``), once only.

    Raises
    ------
    AssemblyError
        The input is bound already, naming both of its sources.
    """
    if ep.label in bound:
        raise AssemblyError(f"input {ep.label} is connected twice ({bound[ep.label][1]} and {source[1]})")
    bound[ep.label] = source


def _root(parent: dict[str, str], k: str) -> str:
    """The union-find root of ``k``, halving the path to it on the way."""
    while parent[k] != k:
        parent[k] = parent[parent[k]]
        k = parent[k]
    return k


def _nodes(members: list[_Endpoint]) -> list[_Endpoint]:
    """The node ports among a net's members."""
    return [e for e in members if e.component.port(e.name).role == "node"]


def _with_one_node(members: list[_Endpoint]) -> list[_Endpoint]:
    """A net's members, refused unless exactly one of them is a node."""
    nodes = _nodes(members)
    if len(nodes) != 1:
        labels = ", ".join(e.label for e in members)
        raise AssemblyError(f"ports {labels} form a net with {len(nodes)} nodes; it needs exactly one "
                            "(a body or a volume that the others act on)")
    return members


def _lone_port(members: list[_Endpoint]) -> str | None:
    """A port alone in its net that must be connected (any branch, a node unless optional), described; else None."""
    if len(members) != 1:
        return None
    port = members[0].component.port(members[0].name)
    if port.role == "branch" or not port.optional:
        return f"{members[0].label} ({port.kind.name} {port.role})"
    return None


def _checked(c: Component, eq: Equations) -> Equations:
    """The component's equations, refused if they leave out a state, an output or a port variable."""
    def need(what, have, names):
        lacking = [n for n in names if n not in have]
        if lacking:
            raise AssemblyError(f"component {c.name} ({type(c).__name__}) gives no {what} for {', '.join(lacking)}")

    need("derivative", eq.der, [v.name for v in c.states])
    foreign = sorted(set(eq.settle) - {v.name for v in c.states})
    if foreign:
        raise AssemblyError(f"component {c.name} ({type(c).__name__}) settles {', '.join(foreign)}, "
                            "which are not its states")
    need("value", eq.outputs, [v.name for v in c.outputs])
    for pt in c.ports:
        given = pt.kind.across if pt.role == "node" else pt.kind.through
        need(f"port {pt.name} variable", eq.port.get(pt.name, {}), [v.name for v in given])
    if c.modes is not None and eq.rest_mode is None:
        raise AssemblyError(f"component {c.name} ({type(c).__name__}) has modes but gives no rest mode")
    if len(eq.indicators) != c.n_indicators:
        raise AssemblyError(f"component {c.name} ({type(c).__name__}) gives {len(eq.indicators)} of its "
                            f"{c.n_indicators} indicators")
    return eq


def _resolve(placeholders: dict, bindings: dict) -> dict:
    """Each placeholder symbol -> its expression free of placeholders, in dependency order.

    A placeholder whose expression depends on itself through others is an algebraic loop: the message
    lists the inputs and ports around it.
    """
    import casadi as ca

    names = list(placeholders)
    index = {placeholders[n].name(): n for n in names}
    deps = {}
    for n in names:
        expr = ca.SX(bindings[n])
        deps[n] = {index[s.name()] for s in ca.symvar(expr) if s.name() in index}
    order, state = [], {}

    def visit(n, path):
        if state.get(n) == "done":
            return
        if state.get(n) == "active":
            loop = path[path.index(n):] + [n]
            raise AssemblyError("algebraic loop: " + " -> ".join(loop))
        state[n] = "active"
        for d in sorted(deps[n]):
            visit(d, path + [n])
        state[n] = "done"
        order.append(n)

    for n in names:
        visit(n, [])
    resolved: dict = {}
    for n in order:
        expr = ca.SX(bindings[n])
        if resolved:
            expr = ca.substitute([expr], list(resolved), list(resolved.values()))[0]
        resolved[placeholders[n]] = expr
    return resolved


def _initial_states(states, initial_by_component, flat) -> list:
    """Initial state expressions in the parameters and model inputs only.

    A component's initial value may read other states (a chamber's air mass reads the load's
    position); they are substituted until none is left.  A state with no initial expression starts at 0.
    """
    import casadi as ca

    syms = [s for _, _, s in states]
    exprs = [flat(initial_by_component[c.name].get(v.name, 0.0)) for c, v, _ in states]
    for _ in range(len(syms) + 1):
        if not any(ca.depends_on(e, ca.vertcat(*syms)) for e in exprs if syms):
            return exprs
        exprs = list(ca.substitute(exprs, syms, exprs))
    raise AssemblyError("the initial states depend on each other in a loop")
