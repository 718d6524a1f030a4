"""Python source from the flat model's CasADi functions: straight-line code, one line per operation.

CasADi evaluates a function from Python in tens of microseconds (argument conversion); the
right-hand side of a one-muscle model costs a few microseconds as plain Python arithmetic.  So the
Python backend runs code printed from CasADi's own instruction list: the common subexpressions it
found, in its order, with C's meaning kept where Python's differs (a division by zero, the square
root or logarithm of a negative number give inf or NaN instead of raising, as in the generated C).
The printed text depends only on the model: generating it twice gives the same bytes.
"""

from __future__ import annotations

import math
from typing import Any

from . import code_cache
from .signatures import FUNCTION_SIGNATURES


RUNTIME = '''\
import math as _math

import numpy as _np

_nan = float("nan")
_inf = float("inf")


def _div0(a, b):
    # a / 0 as C computes it (b is +0.0 or -0.0)
    if a != a or a == 0.0:
        return _nan
    return _math.copysign(_inf, a) * _math.copysign(1.0, b)


def _pow(a, b):
    try:
        r = a ** b
    except (ZeroDivisionError, OverflowError):
        # C's pow: a huge or zero base; the sign is a's for an odd integer b, and there is no real
        # power of a negative base to a fractional b.
        if a < 0.0 and b != int(b):
            return _nan
        odd = b == int(b) and int(b) % 2 == 1
        return _math.copysign(_inf, a) if odd else _inf
    return _nan if isinstance(r, complex) else r


def _trig(fn, a):
    return fn(a) if abs(a) != _inf else _nan


def _log1p(a):
    if a > -1.0:
        return _math.log1p(a)
    return -_inf if a == -1.0 else _nan


def _expm1(a):
    try:
        return _math.expm1(a)
    except OverflowError:
        return _inf


def _exp(a):
    try:
        return _math.exp(a)
    except OverflowError:
        return _inf


def _log(a):
    if a > 0.0:
        return _math.log(a)
    return -_inf if a == 0.0 else _nan


def _asin(a):
    return _math.asin(a) if -1.0 <= a <= 1.0 else _nan


def _acos(a):
    return _math.acos(a) if -1.0 <= a <= 1.0 else _nan


def _sign(a):
    return 1.0 if a > 0.0 else (-1.0 if a < 0.0 else (0.0 if a == 0.0 else _nan))


def _fmin(a, b):
    return b if a != a else (a if b != b or a <= b else b)


def _fmax(a, b):
    return b if a != a else (a if b != b or a >= b else b)


def _fmod(a, b):
    return _math.fmod(a, b) if b != 0.0 and abs(a) != _inf else _nan


def _sinh(a):
    try:
        return _math.sinh(a)
    except OverflowError:
        return _math.copysign(_inf, a)


def _cosh(a):
    try:
        return _math.cosh(a)
    except OverflowError:
        return _inf


def _acosh(a):
    return _math.acosh(a) if a >= 1.0 else _nan


def _atanh(a):
    if -1.0 < a < 1.0:
        return _math.atanh(a)
    return _math.copysign(_inf, a) if abs(a) == 1.0 else _nan


def _fmod_remainder(a, b):
    return _math.remainder(a, b) if b != 0.0 and abs(a) != _inf else _nan


def _floor(a):
    return float(_math.floor(a)) if a == a and abs(a) != _inf else a


def _ceil(a):
    return float(_math.ceil(a)) if a == a and abs(a) != _inf else a
'''



def _op_table() -> dict[int, str]:
    import casadi as ca

    t = {
        "ASSIGN": "{0}", "ADD": "{0} + {1}", "SUB": "{0} - {1}", "MUL": "{0} * {1}",
        "DIV": "({0} / {1} if {1} else _div0({0}, {1}))", "NEG": "-{0}", "EXP": "_exp({0})",
        "LOG": "_log({0})", "POW": "_pow({0}, {1})", "CONSTPOW": "_pow({0}, {1})",
        # x ** 0.5 (C's pow), not math.sqrt: the elements write roots so, and CasADi records them as
        # square roots; pow and sqrt may differ in the last bit, and the Python backend's numbers
        # stay those of the elements on floats.
        "SQRT": "({0} ** 0.5 if {0} >= 0.0 else _nan)", "SQ": "{0} * {0}", "TWICE": "{0} + {0}",
        "SIN": "_trig(_math.sin, {0})", "COS": "_trig(_math.cos, {0})", "TAN": "_trig(_math.tan, {0})",
        "ASIN": "_asin({0})",
        "ACOS": "_acos({0})", "ATAN": "_math.atan({0})",
        "LT": "(1.0 if {0} < {1} else 0.0)", "LE": "(1.0 if {0} <= {1} else 0.0)",
        "EQ": "(1.0 if {0} == {1} else 0.0)", "NE": "(1.0 if {0} != {1} else 0.0)",
        "NOT": "(0.0 if {0} else 1.0)", "AND": "(1.0 if {0} and {1} else 0.0)",
        "OR": "(1.0 if {0} or {1} else 0.0)", "FLOOR": "_floor({0})", "CEIL": "_ceil({0})",
        "FMOD": "_fmod({0}, {1})", "FABS": "abs({0})", "SIGN": "_sign({0})",
        "COPYSIGN": "_math.copysign({0}, {1})", "IF_ELSE_ZERO": "({1} if {0} else 0.0)", "ERF": "_math.erf({0})",
        "FMIN": "_fmin({0}, {1})", "FMAX": "_fmax({0}, {1})", "INV": "(1.0 / {0} if {0} else _div0(1.0, {0}))",
        "SINH": "_sinh({0})", "COSH": "_cosh({0})", "TANH": "_math.tanh({0})",
        "ASINH": "_math.asinh({0})", "ACOSH": "_acosh({0})", "ATANH": "_atanh({0})",
        "ATAN2": "_math.atan2({0}, {1})", "LOG1P": "_log1p({0})", "EXPM1": "_expm1({0})",
        "HYPOT": "_math.hypot({0}, {1})", "REMAINDER": "_fmod_remainder({0}, {1})",
    }
    return {getattr(ca, "OP_" + k): v for k, v in t.items() if hasattr(ca, "OP_" + k)}


def _numpy_op_table() -> dict[int, str]:
    """The operations on numpy arrays, with C's results where numpy's differ only by raising (numpy's
    IEEE arithmetic gives C's inf and NaN once its warnings are silenced, which the caller does)."""
    import casadi as ca

    flag = "_np.where({0}, 1.0, 0.0)"
    t = {
        "ASSIGN": "{0}", "ADD": "{0} + {1}", "SUB": "{0} - {1}", "MUL": "{0} * {1}", "DIV": "_np.divide({0}, {1})",
        "NEG": "-{0}", "EXP": "_np.exp({0})", "LOG": "_np.log({0})", "POW": "_np.power({0}, {1})",
        "CONSTPOW": "_np.power({0}, {1})", "SQRT": "_np.sqrt({0})", "SQ": "{0} * {0}", "TWICE": "{0} + {0}",
        "SIN": "_np.sin({0})", "COS": "_np.cos({0})", "TAN": "_np.tan({0})", "ASIN": "_np.arcsin({0})",
        "ACOS": "_np.arccos({0})", "ATAN": "_np.arctan({0})",
        "LT": flag.format("{0} < {1}"), "LE": flag.format("{0} <= {1}"), "EQ": flag.format("{0} == {1}"),
        "NE": flag.format("{0} != {1}"), "NOT": flag.format("_np.logical_not({0})"),
        "AND": flag.format("_np.logical_and({0}, {1})"), "OR": flag.format("_np.logical_or({0}, {1})"),
        "FLOOR": "_np.floor({0})", "CEIL": "_np.ceil({0})", "FMOD": "_np.fmod({0}, {1})", "FABS": "_np.abs({0})",
        "SIGN": "_np.sign({0})", "COPYSIGN": "_np.copysign({0}, {1})", "IF_ELSE_ZERO": "_np.where({0}, {1}, 0.0)",
        "ERF": "_np.vectorize(_math.erf, otypes=[float])({0})", "FMIN": "_np.fmin({0}, {1})",
        "FMAX": "_np.fmax({0}, {1})", "INV": "_np.divide(1.0, {0})", "SINH": "_np.sinh({0})",
        "COSH": "_np.cosh({0})", "TANH": "_np.tanh({0})", "ASINH": "_np.arcsinh({0})", "ACOSH": "_np.arccosh({0})",
        "ATANH": "_np.arctanh({0})", "ATAN2": "_np.arctan2({0}, {1})", "LOG1P": "_np.log1p({0})",
        "EXPM1": "_np.expm1({0})", "HYPOT": "_np.hypot({0}, {1})",
        "REMAINDER": "_np.vectorize(_fmod_remainder, otypes=[float])({0}, {1})",
    }
    return {getattr(ca, "OP_" + k): v for k, v in t.items() if hasattr(ca, "OP_" + k)}


def _literal(value: float) -> str:
    if math.isnan(value):
        return "_nan"
    if math.isinf(value):
        return "_inf" if value > 0 else "-_inf"
    return repr(float(value))


def function_source(fn, py_name: str, arrays: bool = False) -> str:
    """One CasADi SX ``Function`` as a Python ``def``: dense vector arguments (sequences of floats), each
    result a list of floats (a matrix column by column).

    ``arrays``: each argument entry may be a numpy array (all of one length, or floats), and so is each
    result entry (of the arguments' length ``_n``, the last argument): the function at many points at
    once, for results' columns rather than an integrator.
    """
    args = [fn.name_in(i) for i in range(fn.n_in())]
    lines = [f"def {py_name}({', '.join(args + (['_n'] if arrays else []))}):"]
    writer = _Instructions(fn, args, arrays)
    lines += [writer.line(k) for k in range(fn.n_instructions())]
    results = writer.results
    if arrays:
        results = [[f"_np.broadcast_to(_np.asarray({r}, dtype=float), (_n,))" for r in res] for res in results]
    returned = ", ".join("[" + ", ".join(r) + "]" for r in results)
    lines.append(f"    return {returned}" + ("," if len(results) == 1 else ""))
    return "\n".join(lines) + "\n"


class _Instructions:
    """The lines of a CasADi ``Function``'s instructions, one by one, and the names of its results.

    Parameters
    ----------
    fn : casadi.Function
        The SX function.
    args : list of str
        Its arguments' names.
    arrays : bool
        Lines for numpy arrays (see :func:`function_source`).
    """

    def __init__(self, fn, args: list[str], arrays: bool):
        import casadi as ca

        self.ca, self.fn, self.args, self.arrays = ca, fn, args, arrays
        self.ops = _numpy_op_table() if arrays else _op_table()
        self.dense_index = [fn.sparsity_out(i).find() for i in range(fn.n_out())]
        self.results = [["0.0"] * fn.sparsity_out(i).numel() for i in range(fn.n_out())]
        """Each result's entries, dense: the name of its output line, "0.0" where it is structurally zero."""
        self.constant: dict[int, float] = {}  # work slots that hold a constant, for a division that needs no guard

    def line(self, k: int) -> str:
        """The line of instruction ``k``; a work slot it writes no longer holds a constant (unless it is one)."""
        ca, fn = self.ca, self.fn
        op, ins, outs = fn.instruction_id(k), fn.instruction_input(k), fn.instruction_output(k)
        if op == ca.OP_OUTPUT:
            name = f"r{outs[0]}_{outs[1]}"
            self.results[outs[0]][self.dense_index[outs[0]][outs[1]]] = name
            return f"    {name} = w{ins[0]}"
        if op == ca.OP_CONST:
            value = fn.instruction_constant(k)
            self.constant[outs[0]] = value
            return f"    w{outs[0]} = {_literal(value)}"
        if op == ca.OP_INPUT:
            line = f"    w{outs[0]} = {self.args[ins[0]]}[{ins[1]}]"
        elif op == ca.OP_DIV and self._by_nonzero_constant(ins[1]):
            line = f"    w{outs[0]} = w{ins[0]} / w{ins[1]}"
        elif op in self.ops:
            line = f"    w{outs[0]} = {self.ops[op].format(*(f'w{j}' for j in ins))}"
        else:
            raise NotImplementedError(f"{fn.name()}: CasADi operation {op} has no Python form")
        self.constant.pop(outs[0], None)
        return line

    def _by_nonzero_constant(self, slot: int) -> bool:
        """A division (on floats) by work slot ``slot`` needs no guard: it holds a finite nonzero constant."""
        divisor = self.constant.get(slot, 0.0)
        return not self.arrays and math.isfinite(divisor) and divisor != 0.0


def module_source(model, names=None) -> str:
    """The module: the runtime helpers, then one ``def`` per function of the flat model (all of
    :data:`pamsim.modeling.signatures.FUNCTION_SIGNATURES`, or those in ``names``).

    A model with external functions (:attr:`pamsim.modeling.component.Symbols.external`) gets, for
    each function, a wrapper that computes their arguments, calls them (``_ext0``, ``_ext1``... in the
    module's namespace) and passes their values on.
    """
    parts = [f'"""Generated by pamsim.modeling.pygen from the flat model {model.name!r}.  Do not edit."""\n',
             RUNTIME]
    if model.externals:
        parts.append(function_source(model.function("externals"), "_externals"))
        if names is None or "y" in names:
            parts.append(function_source(model.function("externals"), "_externals_arrays", arrays=True))
    for name in FUNCTION_SIGNATURES:
        if names is not None and name not in names:
            continue
        for arrays in ((False, True) if name == "y" else (False,)):
            suffix = "_arrays" if arrays else ""
            if not model.externals:
                parts.append(function_source(model.function(name), name + suffix, arrays))
                continue
            parts.append(function_source(model.function(name), f"_body_{name}{suffix}", arrays))
            parts.append(_wrapper(model, name, arrays))
    return "\n\n".join(parts)


def _wrapper(model, name: str, arrays: bool = False) -> str:
    import casadi as ca

    args = FUNCTION_SIGNATURES[name][0] + (("_n",) if arrays else ())
    suffix = "_arrays" if arrays else ""
    lines = [f"def {name}{suffix}({', '.join(args)}):"]
    if "x" not in args:
        w = ca.vertcat(*[ext.symbol for ext in model.externals])
        if any(ca.depends_on(ca.vertcat(*exprs), w) for exprs in model._expressions(name) if exprs):
            raise NotImplementedError(f"{model.name}: {name} reads an external function, which needs the states")
        lines.append(f"    return _body_{name}({', '.join(args)}, ())")
        return "\n".join(lines) + "\n"
    lines.append(f"    a = _externals{suffix}(x, u, p, q{', _n' if arrays else ''})[0]")
    calls, k = [], 0
    for i, ext in enumerate(model.externals):
        fn = f"_np.vectorize(_ext{i}, otypes=[float])" if arrays else f"_ext{i}"
        calls.append(f"{fn}({', '.join(f'a[{k + j}]' for j in range(len(ext.args)))})")
        k += len(ext.args)
    lines.append(f"    w = [{', '.join(calls)}]")
    body_args = [a for a in args if a != "_n"] + ["w"] + (["_n"] if arrays else [])
    lines.append(f"    return _body_{name}{suffix}({', '.join(body_args)})")
    return "\n".join(lines) + "\n"


class GeneratedModel:
    """The compiled functions of a flat model, each taking sequences and returning lists of floats.

    ``f(x, u, p, q)`` returns ``(xdot,)``, ``transition(x, u, p, q)`` returns ``(x_next, q_next)`` and
    so on (:data:`pamsim.modeling.signatures.FUNCTION_SIGNATURES`); :meth:`jacobian` gives numpy
    matrices.  ``names`` limits the functions generated (a function not generated is None).
    """

    def __init__(self, model, names=None):
        made = [name for name in FUNCTION_SIGNATURES if (names is None or name in names)
                and not (name == "jacobian" and model.externals)]  # no Jacobian through an external
        fn = model.function("jacobian") if "jacobian" in made else None
        self._load(module_source(model, made), model.name,
                   {kind: [v.name for v in getattr(model, kind)] for kind in ("states", "inputs", "outputs", "parameters")},
                   {name: model.depends_on_inputs(name) for name in made},
                   [ext.fn for ext in model.externals],
                   [(fn.size1_out(i), fn.size2_out(i)) for i in range(fn.n_out())] if fn is not None else None)

    @classmethod
    def from_payload(cls, payload: dict) -> "GeneratedModel":
        """A model generated in another process (:meth:`payload`), without CasADi."""
        self = cls.__new__(cls)
        self._load(payload["source"], payload["model"], payload["names"], payload["reads_inputs"], [],
                   payload["jacobian_shapes"])
        return self

    def payload(self) -> dict:
        """What :meth:`from_payload` needs, as JSON values (a model with external functions has none)."""
        return {"source": self.source, "model": self.model_name, "names": self.names,
                "reads_inputs": self.reads_inputs, "jacobian_shapes": self._jacobian_shapes}

    def _load(self, source, model_name, names, reads_inputs, externals, jacobian_shapes):
        self.source, self.model_name, self.names = source, model_name, names
        self.reads_inputs, self._jacobian_shapes = reads_inputs, jacobian_shapes
        self.has_externals = bool(externals)
        namespace: dict[str, Any] = {"__name__": f"pamsim_generated_{model_name}"}
        namespace.update({f"_ext{i}": fn for i, fn in enumerate(externals)})
        exec(compile(source, f"<pamsim generated {model_name}>", "exec"), namespace)
        self.f = namespace.get("f")
        self.y = namespace.get("y")
        self._y_arrays = namespace.get("y_arrays")
        self.z = namespace.get("z")
        self.transition = namespace.get("transition")
        self.rest_mode = namespace.get("rest_mode")
        self.x0 = namespace.get("x0")
        self.settle = namespace.get("settle")
        self._jacobian = namespace.get("jacobian")

    def y_arrays(self, X, U, p, q=()) -> list:
        """The outputs at many points: ``X`` one row per state and ``U`` one row per input (arrays of
        one length n, or floats), ``p`` the parameters; a list of n-arrays, one per output."""
        import numpy as np

        n = max([np.size(r) for r in (*X, *U)] or [1])
        with np.errstate(all="ignore"):  # C's inf and NaN, as the scalar code gives them
            return self._y_arrays(X, U, p, q, n)[0]

    def jacobian(self, x, u, p, q):
        """``(A, B, C, D)`` as numpy arrays: df/dx, df/du, dy/dx, dy/du."""
        import numpy as np

        return tuple(np.array(b, dtype=float).reshape(shape, order="F")
                     for b, shape in zip(self._jacobian(x, u, p, q), self._jacobian_shapes))


def outputs_by_mode(code: dict, p, X, U, modes) -> dict:
    """``{output name: array}``: the outputs of per-mode code (:func:`compiled_by_mode`) at samples whose
    states are the columns of ``X``, inputs the columns of ``U`` (rows may be floats) and modes
    ``modes``; each sample in its own mode's code."""
    import numpy as np

    modes = np.asarray(modes)
    names = next(iter(code.values())).names["outputs"]
    out = np.full((len(names), modes.size), np.nan)
    for mode in np.unique(modes):
        at = modes == mode
        rows = lambda M: [np.asarray(r, dtype=float)[at] if np.ndim(r) else r for r in M]  # noqa: E731
        out[:, at] = code[int(mode)].y_arrays(rows(X), rows(U), p)
    return dict(zip(names, out))


_BY_MODE_CACHE: dict = {}
BY_MODE_CACHE_SIZE = 32
"""Structures kept per process (a sweep's runs share one)."""


def compiled_by_mode(assembly, component: str | None, names=("f", "z", "transition", "rest_mode")) -> dict:
    """``{mode: GeneratedModel}``: the assembly flattened and generated once for each mode of its hybrid
    component ``component``, with no mode logic left in the code an integrator runs in that mode; for an
    assembly without one (``component`` None), ``{0: GeneratedModel}``.

    Cached by the assembly's structure, so runs that differ only in parameter values (or the assembly's
    name, which the code does not use) share the code,
    in this process and, through :mod:`pamsim.modeling.code_cache`, in the next ones.
    """
    # Without the assembly's name, which the generated functions do not use: scenarios that differ in
    # name alone (a sweep's cases) share the code.
    key = (assembly.structure_key()[1:], component, tuple(names))
    if key not in _BY_MODE_CACHE:
        if len(_BY_MODE_CACHE) >= BY_MODE_CACHE_SIZE:
            _BY_MODE_CACHE.pop(next(iter(_BY_MODE_CACHE), None), None)
        _BY_MODE_CACHE[key] = _by_mode_from_disk(key) or _generate_by_mode(assembly, component, names, key)
    return _BY_MODE_CACHE[key]


def _by_mode_from_disk(key) -> dict | None:
    stored = code_cache.load(key)
    if not isinstance(stored, dict):
        return None
    try:
        return {int(mode): GeneratedModel.from_payload(payload) for mode, payload in stored.items()}
    except Exception:  # an entry that does not load (an older layout, a damaged file) is generated again
        return None


def _generate_by_mode(assembly, component: str | None, names, key) -> dict:
    if component is None:  # no hybrid component: one mode, 0, as the C engine numbers it
        generated = {0: GeneratedModel(assembly.flatten(), names)}
    else:
        modes = assembly.by_name[component].modes
        generated = {int(m): GeneratedModel(assembly.flatten({component: int(m)}), names) for m in modes}
    if not any(g.has_externals for g in generated.values()):
        code_cache.store(key, {str(mode): g.payload() for mode, g in generated.items()})
    return generated
