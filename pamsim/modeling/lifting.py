"""Generated functions through external functions that have a CasADi form.

A flat model is SX: scalar expressions, which CasADi prints as flat C.  An external function
(:attr:`pamsim.modeling.component.Symbols.external`) is a placeholder symbol there.  One with a CasADi
form (:attr:`pamsim.modeling.flat.External.casadi`: a spline table's lookup, which exists on MX only)
still becomes C: the SX expressions are a function of the arguments and of the placeholders, the
placeholders' arguments a second one, and an MX function calls the first with the CasADi forms of
the second's results.  CasADi differentiates through that composition, so its Jacobians stay exact,
and writes it as C with the spline's evaluation among the helpers.  A function that reads no external
stays the SX function it always was, so its code does not change.
"""

from __future__ import annotations


def _column(ca, exprs):
    return ca.vertcat(*exprs) if exprs else ca.SX(0, 1)


def read_externals(ca, outs: list, externals) -> list:
    """The externals any of ``outs`` (SX expressions) reads."""
    return [ext for ext in externals if any(ca.depends_on(o, ext.symbol) for o in outs)]


def lifted(ca, name: str, args: list, outs: list, externals, jacobian_by: int | None = None,
           forward: bool = False):
    """``name(*args) -> outs`` with every external placeholder replaced by its CasADi form of its arguments.

    Parameters
    ----------
    ca : the casadi module.
    name : the function's name.
    args : SX column vectors of symbols, the function's arguments.
    outs : SX expressions (each a column), its results.
    externals : the flat model's :class:`~pamsim.modeling.flat.External` s.
    jacobian_by : if given, the one result is the dense Jacobian of ``outs`` stacked by ``args[jacobian_by]``.
    forward : if True the function takes a seed per argument after the arguments, and its one result is
        the derivative of ``outs`` stacked along the seeds (the Jacobian times the seeds, in forward mode).

    Raises
    ------
    NotImplementedError
        If a result reads an external that has no CasADi form, or one whose arguments read another.
    """
    if forward:
        return _forward(ca, name, args, outs, externals)
    if not read_externals(ca, outs, externals):
        if jacobian_by is not None:
            jac = ca.jacobian(_column(ca, outs), args[jacobian_by])
            return ca.Function(name, args, [ca.cse(ca.densify(jac))])
        return ca.Function(name, args, [ca.cse(ca.densify(o)) for o in outs])
    mx, res = composed(ca, name, args, outs, externals)
    if jacobian_by is not None:
        return ca.Function(name, mx, [ca.densify(ca.jacobian(ca.vertcat(*res), mx[jacobian_by]))])
    return ca.Function(name, mx, [ca.densify(r) for r in res])


def composed(ca, name: str, args: list, outs: list, externals) -> tuple[list, list]:
    """MX symbols shaped as ``args`` and ``outs`` in them, each external placeholder replaced by its CasADi
    form of its arguments (:func:`lifted`, whose errors it raises)."""
    used = read_externals(ca, outs, externals)
    lacking = [ext.name for ext in used if ext.casadi is None]
    if lacking:
        raise NotImplementedError(f"no C for the external functions {', '.join(lacking)} (Python-only physics)")
    w = ca.vertcat(*[ext.symbol for ext in used]) if used else ca.SX(0, 1)
    ext_args = _column(ca, [a for ext in used for a in ext.args])
    if ca.depends_on(ext_args, w):
        raise NotImplementedError(f"{name}: an external function's argument reads another external function")
    G = ca.Function(f"{name}_sx", [*args, w], [ca.cse(o) for o in outs])
    A = ca.Function(f"{name}_args", args, [ca.cse(ext_args)])
    mx = [ca.MX.sym(f"arg{i}", a.sparsity()) for i, a in enumerate(args)]
    stacked = A(*mx)
    values, at = [], 0
    for ext in used:
        values.append(ext.casadi(stacked[at:at + len(ext.args)]))
        at += len(ext.args)
    res = G(*mx, ca.vertcat(*values) if values else ca.MX(0, 1))
    return mx, list(res) if isinstance(res, (list, tuple)) else [res]


def _forward(ca, name: str, args: list, outs: list, externals):
    """:func:`lifted` with ``forward``: ``name(*args, *seeds)`` -> the derivative of ``outs`` along the seeds."""
    if not read_externals(ca, outs, externals):
        sym, out = args, _column(ca, outs)
        seeds = [ca.SX.sym(f"d{k}", a.sparsity()) for k, a in enumerate(args)]
    else:
        sym, res = composed(ca, name, args, outs, externals)
        out = ca.vertcat(*res)
        seeds = [ca.MX.sym(f"d{k}", a.sparsity()) for k, a in enumerate(args)]
    wrt, seed = ca.vertcat(*sym), ca.vertcat(*seeds)
    d = ca.jtimes(out, wrt, seed) if wrt.shape[0] else type(out).zeros(out.shape[0], 1)
    return ca.Function(name, [*sym, *seeds], [ca.cse(ca.densify(d)) if isinstance(d, ca.SX) else ca.densify(d)])
