"""A component: declared parameters, states, inputs, outputs and ports, and its equations written once.

A component's :meth:`Component.equations` receives :class:`Symbols` (CasADi symbols for its own
parameters, states, inputs, port variables and mode) and returns :class:`Equations`.  The assembly
calls it once; every generated form (Python, C, Jacobians, FMU variables) comes from what it returns.
Equations may use Python arithmetic, ``abs``, comparisons and :mod:`pamsim.modeling.smath`; never
:mod:`math`, which turns a symbol into NaN without a word.
"""

from __future__ import annotations

import contextlib
import warnings
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any, ClassVar, Mapping

from .variables import Port, Var


@dataclass
class Symbols:
    """What a component's equations read: each a mapping from local name to a CasADi expression.

    ``port[name]`` holds, for a node port, the summed through variables of the branches connected to
    it; for a branch port, the across variables of the node it is connected to.  ``mode`` is the
    component's discrete mode (a symbol that the generated code holds constant between events), or
    None for a component without modes; ``fired`` has one flag per indicator, 1 for those that have
    crossed at an event (for :attr:`Equations.transition`).  ``external(name, fn, *args, casadi=None)``
    stands for ``fn(*args)`` computed by the host on floats: for physics that has no SX form (a table
    lookup, a numerical solve).  Without ``casadi`` (the same function as a CasADi ``Function`` of the
    stacked arguments, on MX) the model runs in Python only, without exact Jacobians; with it, the
    generated C and the Jacobians go through that function.  ``tol`` is the relative tolerance of the integrator that asks for
    :attr:`Equations.settle`.
    """

    p: Mapping[str, Any]
    x: Mapping[str, Any]
    u: Mapping[str, Any]
    port: Mapping[str, Mapping[str, Any]]
    mode: Any = None
    fired: tuple[Any, ...] = ()
    external: Any = None
    tol: Any = None


@dataclass
class Equations:
    """What a component gives the assembly.

    ``der``: the time derivative of each state.  ``outputs``: each declared output.  ``port``: for a
    node port its across variables, for a branch port its through variables.  For a component with
    modes: ``indicators``, event indicators that are positive inside the current mode (a crossing to
    zero is an event), and ``indicator_margins``, non-negative shifts that an integrator which cannot
    tell the start of a segment from a crossing adds to them, so that a new mode starts strictly inside
    its region (the C core; the Python simulator guards the segment's start instead); ``transition``, the new mode and any state resets (``{"mode": ..., state:
    ...}``) at an event, from the flags of the indicators that crossed (``Symbols.fired``); ``rest_mode``, the mode of the component decided
    afresh from its forces (at the start and where an input jumps).  ``initial``: the state at the
    start, as expressions that may read parameters, inputs and other states (the assembly resolves
    them in order), and for a component with modes its starting mode (key ``"mode"``).

    ``settle``: for an explicit integrator, the component's states set to the steady state they are
    approaching, where they are already within the integrator's tolerance (``Symbols.tol``) of it, and
    unchanged elsewhere.  A chamber approaches its source's pressure exponentially, with a time constant
    of milliseconds; an explicit integrator would follow the rest of that approach, far below its
    tolerance, in steps of that size for as long as the load is held.  The C core asks for it while the
    load is held; the Python simulator (LSODA) does not need it.
    """

    der: dict[str, Any] = field(default_factory=dict)
    outputs: dict[str, Any] = field(default_factory=dict)
    port: dict[str, dict[str, Any]] = field(default_factory=dict)
    indicators: tuple[Any, ...] = ()
    indicator_margins: tuple[Any, ...] = ()
    transition: dict[str, Any] = field(default_factory=dict)
    rest_mode: Any = None
    initial: dict[str, Any] = field(default_factory=dict)
    settle: dict[str, Any] = field(default_factory=dict)


_NAMES_CHECKED: set[type] = set()
"""Component classes whose declared ports, inputs and outputs have no name twice."""


class Component:
    """Base of every component.  A subclass declares its variables as class attributes and writes
    :meth:`equations`; an instance has a name (unique in its assembly) and parameter values.

    ``parameters`` declares the parameters with their units; ``values`` gives a number for each, taken
    from a parameter set that says where each comes from (a paper, a data sheet, or "assumed").
    """

    parameters: ClassVar[tuple[Var, ...]] = ()
    states: ClassVar[tuple[Var, ...]] = ()
    inputs: ClassVar[tuple[Var, ...]] = ()
    outputs: ClassVar[tuple[Var, ...]] = ()
    ports: ClassVar[tuple[Port, ...]] = ()
    modes: ClassVar[type[IntEnum] | None] = None
    n_indicators: ClassVar[int] = 0
    indicator_names: ClassVar[tuple[str, ...]] = ()
    """What a crossing of each indicator of a component without modes means (an event's name in results);
    a hybrid component's events are named by its modes."""

    def __init__(self, name: str, values: Mapping[str, float] | None = None):
        self.name = name
        values = dict(values or {})
        declared = {v.name for v in self.parameter_vars()}
        if values.keys() != declared:
            unknown, missing = sorted(set(values) - declared), sorted(declared - set(values))
            raise ValueError(f"component {name!r} ({type(self).__name__}): "
                             + "; ".join(filter(None, [unknown and f"unknown parameters {unknown}",
                                                       missing and f"missing parameters {missing}"])))
        self.values = values
        # A class's own ports, inputs and outputs are checked once: components are made per run.
        own = self.__dict__.keys() & {"ports", "inputs", "outputs"}
        if own or type(self) not in _NAMES_CHECKED:
            self._check_names()
            if not own:
                _NAMES_CHECKED.add(type(self))

    def _check_names(self) -> None:
        """``ValueError`` if a name is given to more than one port, input or output."""
        names = [p.name for p in self.ports] + [v.name for v in self.inputs] + [v.name for v in self.outputs]
        clash = sorted({n for n in names if names.count(n) > 1})
        if clash:
            raise ValueError(f"component {self.name!r} ({type(self).__name__}): {clash} name more than one "
                             "port, input or output")

    def parameter_vars(self) -> tuple[Var, ...]:
        """The parameters this instance declares (a subclass may declare them per instance)."""
        return self.parameters

    def equations(self, s: Symbols) -> Equations:
        """The component's equations, written on the symbols ``s`` (:class:`Symbols`); every subclass writes its own."""
        raise NotImplementedError

    def structure_key(self) -> tuple:
        """What shapes this component's equations besides its parameter values (its class, and for a
        component around an element, the element's form): components with equal keys generate equal
        code."""
        return (type(self).__module__, type(self).__qualname__)

    def port(self, name: str) -> Port:
        """The declared port called ``name`` (``KeyError`` if there is none)."""
        for p in self.ports:
            if p.name == name:
                return p
        raise KeyError(name)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


@contextlib.contextmanager
def quiet_numpy_on_symbols():
    """Silence CasADi's notice that a numpy function met a symbol.

    Elements written for floats and arrays call numpy functions (``np.clip``, ``np.sqrt``); on a
    symbol CasADi answers with the symbolic function, which is what tracing wants.  Every traced
    element is checked against its float values (the static forces at build time, all of them in the
    tests), so the notice says nothing the checks do not.
    """
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"\s*casadi: a numpy function was called on a casadi value")
        yield
