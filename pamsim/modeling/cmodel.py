"""The C model a generic engine runs: an assembly's functions generated once per mode, with the counts
and tables the engine sizes itself from.

The engine (``fmu/src/pam_engine.c``) integrates a hybrid ODE one mode at a time.  For each mode of the
assembly's hybrid component this module flattens the assembly with that mode fixed (no mode logic
left in the code the integrator runs) and has CasADi generate, as C:

=============  ==========================  =====================================================
function       arguments                   results
=============  ==========================  =====================================================
``f``          xd, u, p                    derivatives of the integrated states xd
``jac``        xd, u, p                    their Jacobian by xd, dense, column-major (stiff steps)
``fq``         xd, u, p                    derivatives of the quadrature states (work integrals)
``z``          xd, u, p                    event indicators plus their margins, > 0 inside the mode
``tr``         xd, u, p, e                 integrated states and mode after an event (e: fired flags)
``rest``       xd, u, p                    the mode decided afresh from the forces at rest
``settle``     xd, u, p, tol               the states settled within the tolerance ``tol``
``y``          x, u, p                     the outputs (x: every state, quadratures included)
=============  ==========================  =====================================================

and, once, ``x0(u, p) -> (x, q0)``.  With ``jacobians``, also the exact directional derivatives an FMU's
``getDirectionalDerivative`` returns, in CasADi's forward mode (the code is about the size of the model's,
where dense Jacobians by every parameter were ten times that and took 30 s to compile): per mode
``dir(x, u, p, dx, du, dp)``, the derivatives of every state then the outputs along the seed
``(dx, du, dp)``, and once ``dx0(u, p, du, dp)``, the initial states along ``(du, dp)``.  The integrated states are those that are not quadratures
(:meth:`pamsim.modeling.flat.FlatModel.quadratures`): the engine computes the quadratures from its
dense output, outside its error control.  A mode is *held* when the hybrid component's own states do
not move in it (their derivatives are structurally zero); the engine caps its steps only while
moving, and settles and checks a held mode's indicators along long steps.

``PM_*`` macros and ``pm_*`` wrappers (mode index first) are what the engine sees; the text depends
only on the assembly's structure: generating it twice gives the same bytes.
"""

from __future__ import annotations

import os
import tempfile

from .lifting import lifted

FUNCTIONS = ("f", "jac", "fq", "z", "tr", "rest", "settle", "y")
"""The per-mode functions, in the order they are generated."""


def _c_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _array(ctype: str, name: str, values) -> str:
    body = ", ".join(values) or "0"
    return f"static const {ctype} {name}[] = {{{body}}};"


class CModel:
    """The per-mode CasADi functions of an assembly and the facts the engine needs about them.

    ``component`` names the hybrid component whose modes the code is generated for (at most one
    hybrid component is supported; a model without one has a single mode, value 0).
    """

    def __init__(self, assembly, component: str | None = None, jacobians: bool = False, extra: tuple = ()):
        """``extra``: further CasADi Functions (named ``pm_<name>_fn``, one result) generated with the model,
        each called from C as ``pm_<name>(arg0, ..., out)``."""
        import casadi as ca

        full = self.full = _runnable(assembly.flatten(), component)
        hybrid = [name for name, _ in full.modes]
        self.component = hybrid[0] if hybrid else None
        self.mode_values = [int(m) for m in full.modes[0][1]] if hybrid else [0]
        self.quadratures = full.quadratures()
        self.dynamic = [i for i in range(len(full.states)) if i not in self.quadratures]
        self.jacobians = jacobians
        self.functions: list = []
        self.held: list[bool] = []
        self.quad_zero: list[bool] = []
        for k, value in enumerate(self.mode_values):
            self._add_mode(ca, assembly.flatten({self.component: value}) if self.component else full, k)
        col = lambda es: ca.vertcat(*es) if es else ca.SX(0, 1)  # noqa: E731
        self.functions.append(_dense(ca, "pm_x0_fn", [col(full.u), col(full.p)], [full.x0, full.q0], full.externals))
        if jacobians:
            self.functions.append(_forward(ca, "pm_dx0_fn", [full.u, full.p], full.x0, full.externals))
        self.extra = tuple(extra)
        self.functions += list(self.extra)

    def _add_mode(self, ca, m, k: int) -> None:
        """Mode ``k``'s functions (flat model ``m``, the mode fixed), and whether it is held and its
        quadratures stand still."""
        own = [i for i, v in enumerate(m.states) if self.component and v.name.startswith(self.component + ".")]
        self.functions += self._mode_functions(ca, m, k)
        if self.jacobians:
            self.functions.append(_forward(ca, f"pm_dir{k}", [m.x, m.u, m.p], m.f + m.y, m.externals))
        self.held.append(bool(own) and all(ca.SX(m.f[i]).is_zero() for i in own))
        self.quad_zero.append(all(ca.SX(m.f[i]).is_zero() for i in self.quadratures))

    def _mode_functions(self, ca, m, k: int) -> list:
        col = lambda es: ca.vertcat(*es) if es else ca.SX(0, 1)  # noqa: E731
        xd = col([m.x[i] for i in self.dynamic])
        x, u, p, e, tol = col(m.x), col(m.u), col(m.p), col(m.e), m._tol()
        pick = lambda es, idx: [es[i] for i in idx]  # noqa: E731
        z = [a + b for a, b in zip(m.z, m.z_margin)]
        ext = m.externals
        return [
            _dense(ca, f"pm_f{k}", [xd, u, p], [pick(m.f, self.dynamic)], ext),
            lifted(ca, f"pm_jac{k}", [xd, u, p], pick(m.f, self.dynamic), ext, jacobian_by=0),
            _dense(ca, f"pm_fq{k}", [xd, u, p], [pick(m.f, self.quadratures)], ext),
            _dense(ca, f"pm_z{k}", [xd, u, p], [z], ext),
            _dense(ca, f"pm_tr{k}", [xd, u, p, e], [pick(m.transition_x, self.dynamic), m.transition_q], ext),
            _dense(ca, f"pm_rest{k}", [xd, u, p], [m.rest_q], ext),
            _dense(ca, f"pm_settle{k}", [xd, u, p, tol], [pick(m.settle_x, self.dynamic)], ext),
            _dense(ca, f"pm_y{k}", [x, u, p], [m.y], ext),
        ]

    @property
    def counts(self) -> dict[str, int]:
        """``nx`` integrated states, ``nq`` quadratures, ``nu`` inputs, ``np`` parameters, ``ny`` outputs, ``nz`` indicators, ``nmodes`` modes."""
        f = self.full
        return {"nx": len(self.dynamic), "nq": len(self.quadratures), "nu": len(f.u), "np": len(f.p),
                "ny": len(f.y), "nz": len(f.z), "nmodes": len(self.mode_values)}

    def sources(self) -> dict[str, str]:
        """``{"pam_model.c": text}``: the CasADi functions and the engine's view of them."""
        import casadi as ca

        gen = ca.CodeGenerator("pam_model_fns.c", {"with_header": False, "with_export": False, "prefix": "pm_"})
        for fn in self.functions:
            gen.add(fn)
        with tempfile.TemporaryDirectory() as tmp:
            gen.generate(tmp + os.sep)
            with open(os.path.join(tmp, "pam_model_fns.c"), encoding="utf-8") as fh:
                body = fh.read()
        return {"pam_model.c": "\n".join([self._header(), body, self._glue()])}

    def _header(self) -> str:
        f, c = self.full, self.counts
        lines = [f"/* Generated by pamsim.modeling.cmodel from the assembly {f.name!r}.  Do not edit. */",
                 "#ifndef PAM_MODEL_C", "#define PAM_MODEL_C", ""]
        for key, n in c.items():
            lines.append(f"#define PM_{key.upper()} {n}")
        lines.append(f"#define PM_NS {len(f.states)} /* every state: integrated and quadratures */")
        sizes = [max(1, *(getattr(fn, f"sz_{what}")() for fn in self.functions)) for what in ("arg", "res", "iw", "w")]
        lines += [f"#define PM_SZ_ARG {sizes[0]}", f"#define PM_SZ_RES {sizes[1]}", f"#define PM_SZ_IW {sizes[2]}",
                  f"#define PM_SZ_W {sizes[3]}", ""]
        lines.append(_array("int", "PM_DYNAMIC", [str(i) for i in self.dynamic]) + " /* their places among all states */")
        lines.append(_array("int", "PM_QUADRATURE", [str(i) for i in self.quadratures]))
        lines.append(_array("double", "PM_NOMINAL", [repr(float(f.states[i].nominal)) for i in self.dynamic]))
        lines.append(_array("int", "PM_MODE_VALUE", [str(v) for v in self.mode_values]))
        lines.append(_array("int", "PM_MODE_HELD", [str(int(h)) for h in self.held]))
        lines.append(_array("int", "PM_MODE_QUAD_ZERO", [str(int(h)) for h in self.quad_zero]))
        for kind in ("states", "inputs", "outputs", "parameters"):
            lines.append(_array("char *const", f"PM_{kind.upper()}_NAMES", [_c_string(v.name) for v in getattr(f, kind)]))
        lines += ["", "#endif", ""]
        return "\n".join(lines)

    def _glue(self) -> str:
        modes = range(len(self.mode_values))
        lines = ["/* ---- the engine's view: mode index first, dense vectors ---- */", "",
                 "static int pm_mode_index(double value) {", "    switch ((int)value) {"]
        lines += [f"    case {v}: return {k};" for k, v in enumerate(self.mode_values)]
        lines += ["    default: return -1;", "    }", "}", ""]
        calls = {"f": ("xd", "u", "p"), "jac": ("xd", "u", "p"), "fq": ("xd", "u", "p"), "z": ("xd", "u", "p"), "rest": ("xd", "u", "p"),
                 "settle": ("xd", "u", "p", "&tol"), "y": ("x", "u", "p")}
        for name, args in calls.items():
            params = ", ".join(f"const double *{a}" if not a.startswith("&") else f"double {a[1:]}" for a in args)
            lines.append(f"static void pm_{name}(int k, {params}, double *out) {{")
            lines.append("    const double *arg[PM_SZ_ARG]; double *res[PM_SZ_RES]; long long iw[PM_SZ_IW]; "
                         "double w[PM_SZ_W];")
            lines.append("    " + " ".join(f"arg[{i}] = {a};" for i, a in enumerate(args)) + " res[0] = out;")
            lines.append("    switch (k) {")
            lines += [f"    case {k}: pm_{name}{k}(arg, res, iw, w, 0); break;" for k in modes]
            lines += ["    default: break;", "    }", "}", ""]
        lines += ["static void pm_tr(int k, const double *xd, const double *u, const double *p, const double *e, "
                  "double *xd_next, double *q_next) {",
                  "    const double *arg[PM_SZ_ARG]; double *res[PM_SZ_RES]; long long iw[PM_SZ_IW]; double w[PM_SZ_W];",
                  "    arg[0] = xd; arg[1] = u; arg[2] = p; arg[3] = e; res[0] = xd_next; res[1] = q_next;",
                  "    switch (k) {"]
        lines += [f"    case {k}: pm_tr{k}(arg, res, iw, w, 0); break;" for k in modes]
        lines += ["    default: break;", "    }", "}", "",
                  "static void pm_x0(const double *u, const double *p, double *x, double *q0) {",
                  "    const double *arg[PM_SZ_ARG]; double *res[PM_SZ_RES]; long long iw[PM_SZ_IW]; double w[PM_SZ_W];",
                  "    arg[0] = u; arg[1] = p; res[0] = x; res[1] = q0;",
                  "    pm_x0_fn(arg, res, iw, w, 0);", "}", ""]
        if self.jacobians:
            lines += ["static void pm_dir(int k, const double *x, const double *u, const double *p, const double *dx, "
                      "const double *du, const double *dp, double *out) {",
                      "    const double *arg[PM_SZ_ARG]; double *res[PM_SZ_RES]; long long iw[PM_SZ_IW]; "
                      "double w[PM_SZ_W];",
                      "    arg[0] = x; arg[1] = u; arg[2] = p; arg[3] = dx; arg[4] = du; arg[5] = dp; res[0] = out;",
                      "    switch (k) {"]
            lines += [f"    case {k}: pm_dir{k}(arg, res, iw, w, 0); break;" for k in modes]
            lines += ["    default: break;", "    }", "}", "",
                      "static void pm_dx0(const double *u, const double *p, const double *du, const double *dp, "
                      "double *out) {",
                      "    const double *arg[PM_SZ_ARG]; double *res[PM_SZ_RES]; long long iw[PM_SZ_IW]; "
                      "double w[PM_SZ_W];", "    arg[0] = u; arg[1] = p; arg[2] = du; arg[3] = dp; res[0] = out;",
                      "    pm_dx0_fn(arg, res, iw, w, 0);", "}", ""]
        for fn in self.extra:
            n = fn.n_in()
            params = ", ".join(f"const double *a{i}" for i in range(n))
            lines += [f"static void {fn.name()[:-3]}({params}, double *out) {{",
                      "    const double *arg[PM_SZ_ARG]; double *res[PM_SZ_RES]; long long iw[PM_SZ_IW]; double w[PM_SZ_W];",
                      "    " + " ".join(f"arg[{i}] = a{i};" for i in range(n)) + " res[0] = out;",
                      f"    {fn.name()}(arg, res, iw, w, 0);", "}", ""]
        return "\n".join(lines)


def _runnable(full, component: str | None):
    """``full``, a flat model the C engine can run: no Python-only functions (an external function must
    have a CasADi form, :mod:`pamsim.modeling.lifting`), at most one hybrid component (``component``, if
    given).  Else :class:`NotImplementedError`, saying why."""
    lacking = [ext.name for ext in full.externals if ext.casadi is None]
    if lacking:
        raise NotImplementedError(f"{full.name}: no C for the external functions {', '.join(lacking)} "
                                  "(Python-only physics)")
    hybrid = [name for name, _ in full.modes]
    if len(hybrid) > 1 or (component is not None and hybrid != [component]):
        raise NotImplementedError(f"{full.name}: the C engine runs models with at most one hybrid component "
                                  f"(this one has {', '.join(hybrid) or 'none'})")
    return full


def _forward(ca, name: str, wrt: list, exprs: list, externals=()):
    """A CasADi Function of ``wrt`` (lists of symbols) and one seed per list, giving the derivative of
    ``exprs`` along the seed (forward mode: the Jacobian times the seed)."""
    col = lambda es: ca.vertcat(*es) if es else ca.SX(0, 1)  # noqa: E731
    return lifted(ca, name, [col(list(w)) for w in wrt], list(exprs), externals, forward=True)


def _dense(ca, name: str, args: list, outs: list, externals=()):
    """A CasADi Function whose every result entry is written (the C of a sparse result skips its zeros)."""
    col = lambda es: ca.vertcat(*es) if es else ca.SX(0, 1)  # noqa: E731
    return lifted(ca, name, args, [col(list(o)) if isinstance(o, list) else o for o in outs], externals)
