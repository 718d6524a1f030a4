"""The flat model: one hybrid ODE in states x, inputs u, parameters p and modes q.

Everything downstream is sized from its counts and named from its lists: the generated Python and C,
the Jacobians and their sparsity (the FMU's ``ModelStructure``), and python-control's named signals.
Names are namespaced by component (``chamber.p_abs_Pa``); model inputs keep the names the assembly
gives them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .lifting import composed
from .signatures import FUNCTION_SIGNATURES
from .variables import Var



@dataclass(frozen=True, eq=False)
class External:
    """``symbol`` stands for ``fn(*args)``, computed by the host on floats (:attr:`Symbols.external`).

    ``casadi``, if not None, is the same function as a CasADi ``Function`` of the stacked arguments (built
    on MX: a table lookup has no SX form), through which the generated C and the exact Jacobians go
    (:mod:`pamsim.modeling.lifting`)."""

    name: str
    fn: Any
    symbol: Any
    args: list[Any]
    casadi: Any = None


@dataclass(eq=False)
class FlatModel:
    """Counts, names and CasADi expressions of an assembled model (built by :meth:`Assembly.flatten`).

    ``f``: state derivatives; ``y``: outputs; ``z``: event indicators, positive inside the current
    modes, and ``z_margin`` what an integrator that cannot tell a segment's start from a crossing adds
    to them (:attr:`pamsim.modeling.component.Equations.indicator_margins`); ``transition_x``/``transition_q``: states and modes after an event; ``rest_q``: the modes
    decided afresh from the forces at rest; ``x0``/``q0``: the initial states and the modes where the
    hybrid components start, before :attr:`rest_q` decides them (of ``u`` and ``p``); ``settle_x``:
    the states settled within the integrator's relative tolerance ``tol``
    (:attr:`pamsim.modeling.component.Equations.settle`).
    """

    name: str
    states: list[Var]
    inputs: list[Var]
    outputs: list[Var]
    parameters: list[Var]
    parameter_values: list[float]
    modes: list[tuple[str, Any]]
    x: list[Any]
    u: list[Any]
    p: list[Any]
    q: list[Any]
    e: list[Any]
    f: list[Any]
    y: list[Any]
    z: list[Any]
    z_margin: list[Any]
    transition_x: list[Any]
    transition_q: list[Any]
    rest_q: list[Any]
    x0: list[Any]
    q0: list[Any]
    settle_x: list[Any] = field(default_factory=list)
    tol: Any = None
    externals: list[External] = field(default_factory=list)
    _cache: dict = field(default_factory=dict, repr=False)

    # ------------------------------------------------------------------ names
    @property
    def counts(self) -> dict[str, int]:
        """How many states, inputs, outputs, parameters, hybrid components (``modes``) and event indicators."""
        return {"states": len(self.states), "inputs": len(self.inputs), "outputs": len(self.outputs),
                "parameters": len(self.parameters), "modes": len(self.modes), "indicators": len(self.z)}

    def index(self, kind: str, name: str) -> int:
        """Position of ``name`` among the model's ``kind`` (``states``, ``inputs``, ``outputs``, ``parameters``)."""
        names = [v.name for v in getattr(self, kind)]
        try:
            return names.index(name)
        except ValueError:
            raise KeyError(f"{self.name} has no {kind[:-1]} {name!r}; it has {', '.join(names)}") from None

    # ------------------------------------------------------------------ CasADi
    def _vectors(self):
        import casadi as ca
        return tuple(ca.vertcat(*v) if v else ca.SX(0, 1) for v in (self.x, self.u, self.p, self.q, self.e,
                                                                      [self._tol()]))

    def _tol(self):
        if self.tol is None:
            import casadi as ca
            self.tol = ca.SX.sym("tol")
        return self.tol

    def function(self, name: str):
        """One of the model's CasADi ``Function`` s, by its name in :data:`FUNCTION_SIGNATURES`."""
        import casadi as ca

        key = ("function", name)
        if key not in self._cache:
            x, u, p, q, e, tol = self._vectors()
            w = ca.vertcat(*[ext.symbol for ext in self.externals]) if self.externals else ca.SX(0, 1)
            col = lambda es: ca.vertcat(*es) if es else ca.SX(0, 1)  # noqa: E731
            ins, outs = self.signature(name)
            if name == "jacobian":
                self._cache[key] = self._jacobian(x, u, p, q, ins, outs)
                return self._cache[key]
            if name == "externals":
                exprs = [col([a for ext in self.externals for a in ext.args])]
            else:
                exprs = [col(e) for e in self._expressions(name)]
            # SX keeps a subexpression once only where the components shared it; cse finds the rest.
            exprs = [ca.cse(e) for e in exprs]
            args = {"x": x, "u": u, "p": p, "q": q, "e": e, "tol": tol, "w": w}
            self._cache[key] = ca.Function(f"{self.name}_{name}", [args[a] for a in ins], exprs, list(ins), list(outs))
        return self._cache[key]

    def _jacobian(self, x, u, p, q, ins, outs):
        """The exact Jacobians (A, B, C, D): on the SX expressions, or through the CasADi forms of the
        external functions (:mod:`pamsim.modeling.lifting`; NotImplementedError where one has none)."""
        import casadi as ca

        col = lambda es: ca.vertcat(*es) if es else ca.SX(0, 1)  # noqa: E731
        f, y = col(self.f), col(self.y)
        if not self.externals:
            exprs = [ca.cse(j) for j in (ca.jacobian(f, x), ca.jacobian(f, u), ca.jacobian(y, x), ca.jacobian(y, u))]
            return ca.Function(f"{self.name}_jacobian", [x, u, p, q], exprs, list(ins), list(outs))
        try:
            (X, U, P, Q), (F, Y) = composed(ca, f"{self.name}_jacobian", [x, u, p, q], [f, y], self.externals)
        except NotImplementedError as exc:
            raise NotImplementedError(f"{self.name}: no exact Jacobian through the external functions: {exc}") from None
        jac = [ca.jacobian(F, X), ca.jacobian(F, U), ca.jacobian(Y, X), ca.jacobian(Y, U)]
        return ca.Function(f"{self.name}_jacobian", [X, U, P, Q], jac, list(ins), list(outs))

    def signature(self, name: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Arguments and results of generated function ``name``.  With external functions, each
        function but the Jacobians (which go through the externals' CasADi forms) also takes ``w``, their
        values, and ``externals(x, u, p, q)`` gives their arguments."""
        if name == "externals":
            return ("x", "u", "p", "q"), ("args",)
        ins, outs = FUNCTION_SIGNATURES[name]
        # The Jacobians go through the externals' CasADi forms rather than take their values.
        return (ins + ("w",) if self.externals and name != "jacobian" else ins), outs

    def depends_on_inputs(self, name: str) -> bool:
        """Whether function ``name`` reads the inputs at all (a sliding load's indicators do not),
        directly or through the arguments of an external function it reads."""
        import casadi as ca

        if not self.u:
            return False
        u = ca.vertcat(*self.u)
        exprs = [e for es in self._expressions(name) for e in es]
        exprs += [a for ext in self.externals if any(ca.depends_on(ca.SX(e), ext.symbol) for e in exprs)
                  for a in ext.args]
        return any(ca.depends_on(ca.SX(e), u) for e in exprs)

    def _expressions(self, name: str) -> list[list[Any]]:
        return {"f": [self.f], "y": [self.y], "z": [self.z, self.z_margin],
                "transition": [self.transition_x, self.transition_q], "rest_mode": [self.rest_q],
                "x0": [self.x0, self.q0], "settle": [self.settle_x or self.x],
                "jacobian": [self.f, self.y]}[name]

    @property
    def functions(self) -> dict[str, Any]:
        """The model as CasADi ``Function`` s, by the names of :data:`FUNCTION_SIGNATURES`."""
        return {name: self.function(name) for name in FUNCTION_SIGNATURES}

    def sparsity(self) -> dict[str, list[list[int]]]:
        """Structural dependencies: for each Jacobian block, the column indices each row depends on.

        ``A``: derivatives on states, ``B``: derivatives on inputs, ``C``: outputs on states,
        ``D``: outputs on inputs (an FMU's ``ModelStructure`` is written from these).
        """
        jac = self.function("jacobian")
        out = {}
        for k, name in enumerate(("A", "B", "C", "D")):
            sp = jac.sparsity_out(k)
            rows = [[] for _ in range(sp.size1())]
            for r, c in zip(*sp.get_triplet()):
                rows[r].append(c)
            out[name] = [sorted(r) for r in rows]
        return out

    def quadratures(self) -> list[int]:
        """The states that only accumulate (a work integral): nothing reads them but the outputs, no
        event resets them, and no other derivative, indicator or mode depends on them.  An integrator
        may compute them by quadrature of its solution rather than carry them in its error control.  Not a
        conserved state (:attr:`pamsim.modeling.variables.Var.conserved`: an isothermal volume's air mass,
        which nothing reads), which must be integrated by the rule of those it exchanges with."""
        import casadi as ca

        def reads(exprs, sym):
            return any(ca.depends_on(ca.SX(e), sym) for e in exprs)

        out = []
        for i, xi in enumerate(self.x):
            others = [e for j, e in enumerate(self.f) if j != i] + [self.f[i]]
            others += self.z + self.z_margin + self.transition_q + self.rest_q + self.q0
            others += [e for j, e in enumerate(self.transition_x) if j != i]
            others += [e for j, e in enumerate(self.settle_x) if j != i]
            others += [a for ext in self.externals for a in ext.args]
            own = [self.transition_x[i], *(self.settle_x[i:i + 1] or [xi])]
            if not self.states[i].conserved and not reads(others, xi) and all(ca.is_equal(ca.SX(e), xi) for e in own):
                out.append(i)
        return out

    # ------------------------------------------------------------------ generated code
    def python_source(self, names=None) -> str:
        """Python source of every function, or of those in ``names`` (:mod:`pamsim.modeling.pygen`):
        byte-identical for one model."""
        from .pygen import module_source
        return module_source(self, names)

    def compile_python(self):
        """The generated Python functions, compiled (:class:`pamsim.modeling.pygen.GeneratedModel`)."""
        if "python" not in self._cache:
            from .pygen import GeneratedModel
            self._cache["python"] = GeneratedModel(self)
        return self._cache["python"]

    def c_sources(self, prefix: str | None = None) -> dict[str, str]:
        """C sources of every function (:mod:`pamsim.modeling.cgen`): ``{file name: text}``."""
        from .cgen import c_sources
        return c_sources(self, prefix or self.name)
