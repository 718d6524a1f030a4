"""An element's numbers as a component's parameters, and the element rebuilt around symbols.

The elements are frozen dataclasses of numbers with pure methods.  Rebuilt with CasADi symbols in
place of the numbers, the same methods give the component's equations: the physics is not copied.
Fields that choose a form rather than give a number (``name``, ``negative_level``) stay as they are.

An element that cannot be rebuilt so (not a dataclass, a check of its numbers in ``__post_init__``)
or whose method does not give on symbols what it gives on floats (a table lookup, a numerical solve,
a :mod:`math` call, which turns a symbol into NaN without a word) is called on floats instead, as an
external function (:attr:`pamsim.modeling.component.Symbols.external`): correct, and in generated C
too where the method has a CasADi form (:meth:`ElementParameters.casadi_form`: a spline table's
B-spline), else Python only.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import math
import operator
import struct
import threading
import types
import warnings
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..modeling import Var, code_cache
from ..modeling.component import quiet_numpy_on_symbols
from ..parameter_schema import KNOWN, unit_of

STRUCTURAL = ("name", "negative_level")
"""Fields that are choices or metadata, never parameters."""


@functools.lru_cache(maxsize=None)
def _field_names(cls: type) -> tuple[str, ...]:
    # dataclasses.fields() rebuilds its tuple at every call; components are made per run, many per sweep.
    return tuple(f.name for f in dataclasses.fields(cls))


@functools.lru_cache(maxsize=None)
def _fields(cls: type) -> tuple[tuple[str, bool], ...]:
    """Each field's name and whether it is :data:`STRUCTURAL`, once per class."""
    return tuple((name, name in STRUCTURAL) for name in _field_names(cls))


def _is_instance_of_dataclass(value) -> bool:
    return not isinstance(value, type) and hasattr(type(value), "__dataclass_fields__")


def form_and_numbers(element) -> tuple[tuple, dict[str, float]]:
    """:func:`structure_key` of ``element`` and its numbers (:func:`element_parameters`), in one walk:
    a component takes both from each element, once per run."""
    numbers: dict[str, float] = {}
    if not _is_instance_of_dataclass(element):
        return _stable(element, True), numbers
    return _walk(element, numbers, ""), numbers


def _walk(element, numbers: dict[str, float], path: str, keyed: bool = True) -> tuple | None:
    """The key of a dataclass ``element`` whose numbers are parameters, put into ``numbers`` (a nested
    element's under its plain name unless another number has it already, else under its path).
    ``keyed``: build the key (not for an element that says itself what its code depends on)."""
    items = []
    for name, structural in _fields(type(element)):
        value = getattr(element, name)
        if structural:
            if keyed:
                items.append((name, _stable(value, True)))
        elif type(value) is float or _is_number(value):  # float first: most fields are
            numbers[name if name not in numbers else f"{path}{name}"] = float(value)
        elif _is_instance_of_dataclass(value):
            own = callable(getattr(value, "code_key", None))  # a spline surface: keyed as _stable keys it
            key = _walk(value, numbers, f"{path}{name}.", keyed and not own)
            if keyed:
                items.append((name, value.code_key() if own else key))
        elif keyed:
            items.append((name, _stable(value, False)))
    return (type(element).__module__, type(element).__qualname__, tuple(items)) if keyed else None


def element_parameters(element) -> dict[str, float]:
    """``{name: value}`` of every number of a dataclass ``element`` (nested elements included), named
    by field; a field name met twice is qualified by its path (``orifice.C_m3_per_s_Pa``)."""
    return form_and_numbers(element)[1]


def symbolic(element, symbols: Mapping[str, Any]):
    """``element`` with each number replaced by its symbol (named as :func:`element_parameters` names it);
    an element that is not a dataclass as it is, its numbers constants of the code."""
    if not dataclasses.is_dataclass(element):
        return element
    names = iter(element_parameters(element))

    def rebuild(obj):
        changes = {}
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if f.name in STRUCTURAL:
                continue
            if dataclasses.is_dataclass(value):
                changes[f.name] = rebuild(value)
            elif _is_number(value):
                changes[f.name] = symbols[next(names)]
        return dataclasses.replace(obj, **changes)

    return rebuild(element)


def structure_key(element, baked: bool = False) -> tuple:
    """What of ``element`` shapes its equations: its type and every field that is not a parameter
    (a choice, a tuple of coefficients), recursively.  Elements with one key differ only in parameter
    values, so they share one generated model.  ``baked``: the numbers are constants of the generated
    code (an element called on floats, or numbers :func:`symbolic` does not replace), so they count.
    """
    if baked and _is_instance_of_dataclass(element):
        items = tuple((name, _stable(getattr(element, name), True)) for name, _ in _fields(type(element)))
        return (type(element).__module__, type(element).__qualname__, items)
    return form_and_numbers(element)[0]


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _stable(value, baked: bool):
    """``value`` as a key that is equal only for values that give equal code.

    Numbers inside containers and in objects other than dataclasses are constants of the code
    (:func:`symbolic` replaces a dataclass's own numbers only), so they count.  A value whose effect
    cannot be told from outside (a closure, a bound method, an unknown object) keys as itself: only
    the same object shares code.
    """
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if not isinstance(value, type) and callable(getattr(value, "code_key", None)):
        return value.code_key()  # an object that says what its code depends on (a spline surface)
    if isinstance(value, (tuple, list)):
        return (type(value).__name__, tuple(_stable(v, True) for v in value))
    if isinstance(value, np.ndarray):
        return ("ndarray", value.shape, str(value.dtype), hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest())
    if _is_instance_of_dataclass(value):
        return structure_key(value, baked)
    if isinstance(value, Mapping):
        return ("mapping", tuple(sorted((str(k), _stable(v, True)) for k, v in value.items())))
    return _stable_other(value)


def _stable_other(value):
    """:func:`_stable` of a function, a partial or another object: by what it is made of where that can
    be told from outside, else as itself."""
    if isinstance(value, types.FunctionType) and not value.__closure__ and not value.__defaults__:
        return ("function", value.__module__, value.__qualname__, value.__code__)
    if isinstance(value, functools.partial):
        return ("partial", _stable(value.func, True), _stable(value.args, True), _stable(value.keywords, True))
    if not callable(value) and type(value).__eq__ is object.__eq__ and hasattr(value, "__dict__"):
        return (type(value).__module__, type(value).__qualname__,
                tuple(sorted((k, _stable(v, True)) for k, v in vars(value).items())))
    return ("object", _Identity(value))


class _Identity:
    """Equal only to a wrapper of the same object, which it keeps alive (so its id is never reused)."""

    __slots__ = ("obj",)

    def __init__(self, obj):
        self.obj = obj

    def __eq__(self, other):
        return isinstance(other, _Identity) and other.obj is self.obj

    def __hash__(self):
        return id(self.obj)


_NO_KEY = object()
_PACK = struct.Struct("<d").pack


def exact_key(value):
    """A key equal for two values only if they are of the same types and equal to the last bit, or
    :data:`_NO_KEY` if ``value`` holds anything but numbers, strings, None, tuples, lists, string-keyed dicts
    and dataclasses of them.  Unlike ``==``, which takes ``0.0`` for ``-0.0`` and ``1`` for ``1.0`` or
    ``True``: two values with one key behave alike in every computation."""
    kind = type(value)
    if kind is float:
        return _PACK(value)  # the bits (bytes, equal to no other key): -0.0 is not 0.0
    if kind is str or value is None:
        return value
    if kind is int or kind is bool:
        return (kind, value)
    if kind is tuple or kind is list:
        items = value
    elif kind is dict and all(type(k) is str for k in value):
        items = (*value, *value.values())
    elif _is_instance_of_dataclass(value):
        return _dataclass_key(value)
    else:
        return _NO_KEY  # an array, a function, another object: no key that could not mislead
    return _composite_key(kind, items)


def _composite_key(kind: type, items) -> tuple:
    parts = [kind]  # a composite's key starts with its type, a leaf's is not a tuple or starts with int or bool
    for v in items:  # the leaves here, not by a call each: most are floats
        t = type(v)
        if t is float:
            parts.append(_PACK(v))
        elif t is str or v is None:
            parts.append(v)
        else:
            k = exact_key(v)
            if k is _NO_KEY:
                return _NO_KEY
            parts.append(k)
    return tuple(parts)


@functools.lru_cache(maxsize=None)
def _fields_of(cls: type) -> Callable[[Any], tuple]:
    """A function giving the fields of an instance of dataclass ``cls``, as a tuple, in one call."""
    names = _field_names(cls)
    if len(names) == 1:  # attrgetter gives one field as itself
        getter = operator.attrgetter(names[0])
        return lambda obj: (getter(obj),)
    return operator.attrgetter(*names) if names else lambda obj: ()


@functools.lru_cache(maxsize=None)
def _packer(n: int) -> Callable[..., bytes]:
    return struct.Struct(f"<{n}d").pack


def _dataclass_key(value):
    """:func:`exact_key` of a dataclass."""
    kind = type(value)
    items = _fields_of(kind)(value)
    if all(type(v) is float for v in items):  # most elements: their numbers' bits in one call
        return (kind, _packer(len(items))(*items))
    return _composite_key(kind, items)


KEPT_COMPONENTS = 256
"""Components kept per process by :func:`kept_component`: a sweep's cases share most of theirs."""
_kept: dict = {}
_kept_lock = threading.Lock()


def kept_component(cls: type, *args):
    """``cls(*args)``, the component made before from arguments of the same :func:`exact_key` if there is
    one (the last :data:`KEPT_COMPONENTS`), since a component does not change after it is made and making
    one (walking its element, checking its declarations) costs more than keying its arguments; made anew
    where an argument has no exact key."""
    key = exact_key(args)
    if key is _NO_KEY:
        return cls(*args)
    key = (cls, key)
    component = _kept.get(key)
    if component is None:
        component = cls(*args)
        with _kept_lock:  # a sweep's threads may share this process's components
            _kept[key] = component
            while len(_kept) > KEPT_COMPONENTS:
                del _kept[next(iter(_kept))]  # the oldest first
    return component


def parameter_vars(values: Mapping[str, float], descriptions: Mapping[str, str] | None = None) -> tuple[Var, ...]:
    """Declarations of parameters named with their unit as suffix (``D1_N_s_per_m``)."""
    return _declared(tuple(values), tuple(sorted((descriptions or {}).items())))


@functools.lru_cache(maxsize=256)
def _declared(names: tuple[str, ...], descriptions: tuple[tuple[str, str], ...]) -> tuple[Var, ...]:
    # A name the muscle's parameter schema knows (N0_N_per_bar, D1_N_s_per_m, ...) says what it is there:
    # an element's numbers reach an FMU's parameters, which would otherwise carry no description.
    text = dict(descriptions)
    return tuple(Var(name, unit_of(name), text.get(name) or getattr(KNOWN.get(name), "description", ""))
                 for name in names)


_TRACES: dict = {}
_TRACES_SIZE = 256


def traces(element, method: Callable, points: Sequence[tuple[float, ...]], form: tuple | None = None) -> bool:
    """Whether ``method(element rebuilt around symbols, *args)`` gives, at each of ``points``, the value
    ``method(element, *args)`` gives on floats (compared where that is finite).  Cached by the
    element's form (``form``: its :func:`structure_key`, if the caller has it): whether it traces does
    not depend on its numbers."""
    key = ("traces", form if form is not None else structure_key(element), getattr(method, "__qualname__", repr(method)))
    if key not in _TRACES:
        if len(_TRACES) >= _TRACES_SIZE:
            _TRACES.pop(next(iter(_TRACES), None), None)
        stored = code_cache.load(key)  # a decision of an earlier process spares importing CasADi
        if not isinstance(stored, bool):
            stored = _probe(element, method, points)
            code_cache.store(key, stored)
        _TRACES[key] = stored
    return _TRACES[key]


def _probe(element, method, points) -> bool:
    import casadi as ca

    params = element_parameters(element)
    p = {name: ca.SX.sym(name) for name in params}
    args = [ca.SX.sym(f"a{i}") for i in range(len(points[0]))]
    try:
        with quiet_numpy_on_symbols(), warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)  # a table's array path, probed with a symbol
            sym = symbolic(element, p)
            fn = ca.Function("probe", [ca.vertcat(*args, *p.values())], [ca.SX(method(sym, *args))])
    except Exception:
        return False
    values = list(params.values())
    for point in points:
        try:
            want = method(element, *point)
        except (ValueError, ZeroDivisionError, OverflowError):
            continue  # no value here on floats: nothing to compare
        if isinstance(want, complex) or not math.isfinite(want):
            continue
        got = float(fn([*point, *values]))
        if not abs(got - want) <= 1e-9 * max(1.0, abs(want)):
            return False
    return True


def _mx_function(name: str, element, call: Callable, points: Sequence[tuple[float, ...]]):
    """``call(element, *args)`` as a CasADi ``Function`` of the stacked arguments, built on MX symbols, or
    None where it does not take them (a numerical solve, a :mod:`math` call) or does not give at
    ``points`` what it gives on floats there."""
    import casadi as ca

    a = ca.MX.sym("a", len(points[0]))
    try:
        with quiet_numpy_on_symbols(), warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            out = ca.MX(call(element, *ca.vertsplit(a)))
        fn = ca.Function(name, [a], [out])
    except Exception:  # whatever a float-only element raises on a symbol: it has no C form
        return None
    if fn.has_free():
        return None
    for point in points:
        try:
            want = float(call(element, *point))
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            continue  # no value here on floats: nothing to compare
        if math.isfinite(want) and not abs(float(fn(ca.DM(point))) - want) <= 1e-9 * max(1.0, abs(want)):
            return None
    return fn


class ElementParameters:
    """Mixin: a component whose parameters are the numbers of its element (``self.element``) when the
    element takes symbols (``self.traces``); otherwise it has none and calls the element on floats."""

    element: Any
    traces: bool = True
    extra_parameters: tuple[Var, ...] = ()

    def parameter_vars(self) -> tuple[Var, ...]:
        """The parameters: the element's numbers (if it takes symbols), then the component's own."""
        # Kept: the element does not change after wrap, and an assembly asks many times.
        if "_parameter_vars" not in self.__dict__:
            own = parameter_vars(self.element_values()) if self.traces else ()
            self._parameter_vars = own + self.extra_parameters
        return self._parameter_vars

    def element_values(self) -> dict[str, float]:
        """``{name: value}`` of the element's numbers that are parameters (none if it is called on floats)."""
        if "_element_values" not in self.__dict__:  # kept: the element does not change after wrap
            self._element_values = element_parameters(self.element) if self.traces else {}
        return dict(self._element_values)  # a copy: a component adds its own parameters to what wrap returns

    def symbolic_element(self, p: Mapping[str, Any]):
        """The element rebuilt with its numbers replaced by the symbols ``p``."""
        return symbolic(self.element, p)

    def wrap(self, element, probe: Callable, points, required: str = "") -> dict[str, float]:
        """Take ``element``, decide whether it takes symbols (``probe`` at ``points``, :func:`traces`)
        and return its parameter values.  ``required``: what to call it in the ``TypeError`` raised when
        it must take symbols and does not (an element the python backend cannot call on floats)."""
        self.element = element
        for kept in [k for k in self.__dict__ if k in ("_element_values", "_parameter_vars")
                     or (isinstance(k, tuple) and k[0] == "_casadi_form")]:
            self.__dict__.pop(kept, None)
        self._form, numbers = form_and_numbers(element)
        self._probe, self._probe_points = probe, tuple(points)
        self.traces = traces(element, probe, points, self._form)
        if required and not self.traces:
            raise TypeError(f"{required} {type(element).__name__} cannot be written with symbols")
        self._element_values = numbers if self.traces else {}
        return self.element_values()

    def element_call(self, s, method: str, *args):
        """``element.method(*args)``: as equations if the element takes symbols, else on floats, with its
        CasADi form (:meth:`casadi_form`) if it has one."""
        if self.traces:
            return getattr(self.symbolic_element(s.p), method)(*args)
        return s.external(method, getattr(self.element, method), *args, casadi=self.casadi_form(method, len(args)))

    def casadi_form(self, method: str, n_args: int):
        """``element.method`` as a CasADi ``Function`` of its ``n_args`` arguments stacked, built on MX
        symbols (a spline table's lookup has an MX form but no SX form), or None if the method does not
        take MX symbols: then the element runs in Python only."""
        if n_args != len(self._probe_points[0]):
            return None
        return self._casadi_of(method, lambda element, *a: getattr(element, method)(*a))

    def _casadi_of(self, name: str, call: Callable):
        # Checked at the probe points of wrap: the method a component calls takes the probe's arguments.
        key = ("_casadi_form", name)
        if key not in self.__dict__:
            self.__dict__[key] = _mx_function(f"{type(self.element).__name__}_{name}", self.element, call,
                                              self._probe_points)
        return self.__dict__[key]

    def has_c_form(self) -> bool:
        """Whether the element runs in generated C: it takes symbols, or it has a CasADi form (its probe's)."""
        return self.traces or self._casadi_of("probe", self._probe) is not None

    def structure_key(self) -> tuple:
        """The component's key, with the element's form (and its numbers, if they are baked into the code)."""
        # An element called on floats is part of the generated code: its numbers are too.
        form = self._form if self.traces else structure_key(self.element, baked=True)
        return super().structure_key() + (form,)
