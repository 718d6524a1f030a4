"""The modelling layer on its own: wiring checks, the generated Python against CasADi's own
evaluation, the generated C against the generated Python, and reproducible generation."""

from __future__ import annotations

import ctypes
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pamsim.assemblies import one_muscle_assembly
from pamsim.modeling import (PNEUMATIC, TRANSLATIONAL, Assembly, AssemblyError, Component, Equations, Port, Symbols,
                             Var)
from pamsim.modeling.pygen import function_source
from pamsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]


# ---------------------------------------------------------------- small components for wiring tests
class Body(Component):
    parameters = (Var("m_kg", "kg"),)
    ports = (Port("flange", TRANSLATIONAL, "node"),)
    states = (Var("x_m", "m"), Var("v_m_s", "m/s"))
    outputs = (Var("x_m", "m"),)

    def equations(self, s: Symbols) -> Equations:
        return Equations(der={"x_m": s.x["v_m_s"], "v_m_s": s.port["flange"]["F_N"] / s.p["m_kg"]},
                         outputs={"x_m": s.x["x_m"]}, port={"flange": {"x_m": s.x["x_m"], "v_m_s": s.x["v_m_s"]}})


class Spring(Component):
    parameters = (Var("k_N_per_m", "N/m"),)
    ports = (Port("flange", TRANSLATIONAL, "branch"),)

    def equations(self, s: Symbols) -> Equations:
        return Equations(port={"flange": {"F_N": -s.p["k_N_per_m"] * s.port["flange"]["x_m"]}})


class Gain(Component):
    """y = k u: two of them in a ring make an algebraic loop."""

    parameters = (Var("k", "1"),)
    inputs = (Var("u_N", "N"),)
    outputs = (Var("y_N", "N"),)

    def equations(self, s: Symbols) -> Equations:
        return Equations(outputs={"y_N": s.p["k"] * s.u["u_N"]})


class Volume(Component):
    ports = (Port("port", PNEUMATIC, "node"),)

    def equations(self, s: Symbols) -> Equations:
        return Equations(port={"port": {"p_abs_Pa": 1e5, "T_K": 293.15}})


class FloatForce(Component):
    """A force computed on floats from an input: the model reads the input only through it."""

    inputs = (Var("u_N", "N"),)
    ports = (Port("flange", TRANSLATIONAL, "branch"),)

    def equations(self, s: Symbols) -> Equations:
        return Equations(port={"flange": {"F_N": s.external("F", lambda u: 2.0 * u, s.u["u_N"])}})


def test_a_model_reads_the_inputs_an_external_function_reads():
    flat = Assembly([Body("body", {"m_kg": 2.0}), FloatForce("push")], [("body.flange", "push.flange")],
                    {"u_N": "push.u_N"}).flatten()
    assert flat.depends_on_inputs("f")  # only through the external function's argument
    (xdot,) = flat.compile_python().f([0.0, 0.0], [3.0], flat.parameter_values, [])
    assert xdot == [0.0, 3.0]  # 2 u / m


def _oscillator(k=4.0, m=1.0):
    return Assembly([Body("body", {"m_kg": m}), Spring("spring", {"k_N_per_m": k})],
                    [("body.flange", "spring.flange")], name="oscillator")


def test_flat_model_of_a_spring_mass_is_the_harmonic_oscillator():
    flat = _oscillator(k=4.0, m=0.25).flatten()
    g = flat.compile_python()
    assert [v.name for v in flat.states] == ["body.x_m", "body.v_m_s"]
    (xdot,) = g.f([0.3, -1.5], [], flat.parameter_values, [])
    assert xdot == [-1.5, -4.0 * 0.3 / 0.25]
    A, B, C, D = g.jacobian([0.3, -1.5], [], flat.parameter_values, [])
    np.testing.assert_array_equal(A, [[0.0, 1.0], [-16.0, 0.0]])  # omega^2 = k / m = 16
    assert B.shape == (2, 0) and C.tolist() == [[1.0, 0.0]] and D.shape == (1, 0)
    assert flat.sparsity()["A"] == [[1], [0]]


@pytest.mark.parametrize("build, message", [
    (lambda: Assembly([Body("a", {"m_kg": 1}), Body("a", {"m_kg": 2})]), "component name 'a' is given twice"),
    (lambda: Assembly([Body("body", {"m_kg": 1}), Spring("spring", {"k_N_per_m": 1})]).flatten(),
     "ports body.flange (translational node), spring.flange (translational branch) are not connected"),
    (lambda: Assembly([Body("body", {"m_kg": 1}), Volume("tank")], [("body.flange", "tank.port")]).flatten(),
     "cannot connect port body.flange (translational) to port tank.port (pneumatic)"),
    (lambda: Assembly([Body("b1", {"m_kg": 1}), Body("b2", {"m_kg": 1})], [("b1.flange", "b2.flange")]).flatten(),
     "form a net with 2 nodes"),
    (lambda: Assembly([Body("body", {"m_kg": 1}), Spring("spring", {"k_N_per_m": 1}), Gain("gain", {"k": 1.0})],
                      [("body.flange", "spring.flange"), ("body.x_m", "gain.u_N")]).flatten(),
     "cannot connect body.x_m [m] to gain.u_N [N]: the units differ"),
    (lambda: Assembly([Body("body", {"m_kg": 1}), Spring("spring", {"k_N_per_m": 1}), Gain("gain", {"k": 1.0})],
                      [("body.flange", "spring.flange")]).flatten(),
     "input gain.u_N [N] is not connected"),
    (lambda: Assembly([Gain("g1", {"k": 0.5}), Gain("g2", {"k": 0.5})],
                      [("g1.y_N", "g2.u_N"), ("g2.y_N", "g1.u_N")]).flatten(),
     "algebraic loop: g1.u_N -> g2.u_N -> g1.u_N"),
    (lambda: Assembly([Gain("g1", {"k": 0.5})], [("g1.y_N", "nothing.u_N")], {"u": "g1.u_N"}).flatten(),
     "no component 'nothing'"),
    (lambda: Spring("spring", {"k": 1.0}), "unknown parameters ['k']; missing parameters ['k_N_per_m']"),
])
def test_wiring_mistakes_are_refused_naming_component_and_port(build, message):
    with pytest.raises((AssemblyError, ValueError)) as err:
        build()
    assert message in str(err.value)


class Clash(Component):
    """A port and an output of one name."""

    ports = (Port("y_N", TRANSLATIONAL, "branch"),)
    outputs = (Var("y_N", "N"),)


class GainOwnInputs(Gain):
    """A gain that may declare its inputs per instance."""

    def __init__(self, name, values, inputs=None):
        if inputs is not None:
            self.inputs = inputs
        super().__init__(name, values)


def test_a_name_given_to_two_ports_inputs_or_outputs_is_refused_every_time():
    """The check is kept per class once a class passes it: a class that fails fails at every instance,
    and an instance that declares its own clashing names fails after instances of its class passed."""
    for _ in range(2):
        with pytest.raises(ValueError, match=r"\['y_N'\] name more than one port, input or output"):
            Clash("clash")
    GainOwnInputs("fine", {"k": 1.0})
    GainOwnInputs("fine again", {"k": 1.0})
    with pytest.raises(ValueError, match=r"component 'own' \(GainOwnInputs\): \['y_N'\] name more than one"):
        GainOwnInputs("own", {"k": 1.0}, inputs=(Var("y_N", "N"),))


def _arguments(flat, name, x, u, P, q, rng):
    """The arguments of generated function ``name``: states, inputs, parameters, modes and (for a jump)
    random flags of the indicators that crossed."""
    from pamsim.modeling.signatures import FUNCTION_SIGNATURES

    values = {"x": x, "u": u, "p": P, "q": [q], "e": rng.integers(0, 2, len(flat.e)).astype(float)}
    return [values[a] for a in FUNCTION_SIGNATURES[name][0]]


def _random_points(flat, rng, n):
    x = rng.uniform(-1.0, 1.0, (n, len(flat.states))) * [v.nominal for v in flat.states]
    u = rng.uniform(-1.0, 1.0, (n, len(flat.inputs)))
    return x, u


def test_generated_python_reproduces_casadi_bit_for_bit_on_every_operation():
    """Every operation CasADi can emit that the printer knows, at values where C and Python differ
    (negative roots, division by zero, overflow), against CasADi's own evaluation."""
    import casadi as ca

    a, b = ca.SX.sym("a"), ca.SX.sym("b")
    exprs = [a + b, a - b, a * b, a / b, -a, ca.exp(a), ca.log(a), a ** b, a ** 3, ca.sqrt(a), a * a, 2 * a,
             ca.sin(a), ca.cos(a), ca.tan(a), ca.asin(a), ca.acos(a), ca.atan(a), a < b, a <= b, a == b, a != b,
             ca.logic_not(a), ca.logic_and(a, b), ca.logic_or(a, b), ca.floor(a), ca.ceil(a), ca.fmod(a, b),
             ca.fabs(a), ca.sign(a), ca.copysign(a, b), ca.if_else(a > 0, b, 2 * b), ca.erf(a), ca.fmin(a, b),
             ca.fmax(a, b), 1 / a, ca.sinh(a), ca.cosh(a), ca.tanh(a), ca.asinh(a), ca.acosh(a), ca.atanh(a),
             ca.atan2(a, b), ca.log1p(a), ca.expm1(a), ca.hypot(a, b), ca.remainder(a, b), a ** -1, a ** 3.5,
             b ** a]
    fn = ca.Function("ops", [ca.vertcat(a, b)], [ca.vertcat(*exprs)], ["ab"], ["out"])
    ns: dict = {}
    from pamsim.modeling.pygen import RUNTIME
    exec(RUNTIME + "\n" + function_source(fn, "ops"), ns)
    for pair in [(0.7, 1.3), (-0.7, 1.3), (2.5, -0.5), (0.0, 0.0), (-3.0, 0.0), (800.0, 2.0), (1e-3, 1e3), (1.0, -1.0),
                 (-1.0, 2.0), (3.0, 0.5), (float("inf"), 2.0), (float("-inf"), -3.0), (-0.0, 3.0),
                 (-1e308, 2.5), (1e308, 3.0), (float("nan"), 1.0)]:
        want = np.array(fn(pair)).ravel()
        (got,) = ns["ops"](list(pair))
        np.testing.assert_allclose(got, want, rtol=4e-16, atol=0, equal_nan=True, err_msg=str(pair))


@pytest.fixture(scope="module")
def fig4_flat():
    sc = load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    return one_muscle_assembly(sc.build_model()).flatten()


def test_generated_python_equals_casadi_on_the_muscle_model(fig4_flat):
    flat = fig4_flat
    g = flat.compile_python()
    rng = np.random.default_rng(3)
    X, U = _random_points(flat, rng, 200)
    X[:, 2] = 1e5 + np.abs(X[:, 2]) * 4  # a positive absolute pressure and air mass
    X[:, 3] = np.abs(X[:, 3]) + 1e-6
    P = flat.parameter_values
    for x, u in zip(X, U):
        for q in (-1.0, 0.0, 1.0, 2.0, 3.0):
            for name in ("f", "y", "z", "transition", "rest_mode", "jacobian"):
                args = _arguments(flat, name, x, u, P, q, rng)
                want = [np.array(r).ravel(order="F") for r in flat.function(name).call(args)]
                got = getattr(g, "_jacobian" if name == "jacobian" else name)(*[list(a) for a in args])
                for w, h in zip(want, got):
                    np.testing.assert_allclose(h, w, rtol=1e-15, atol=0, equal_nan=True)


def _cc() -> str | None:
    return os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")


@pytest.mark.skipif(_cc() is None, reason="no C compiler (cc, gcc or $CC) on this machine")
def test_generated_c_equals_generated_python(fig4_flat, tmp_path):
    """The C of CasADi's code generator, compiled, against the generated Python at random points."""
    flat = fig4_flat
    for name, text in flat.c_sources().items():
        (tmp_path / name).write_text(text)
    lib_path = tmp_path / "libone_muscle.so"
    subprocess.run([_cc(), "-O2", "-shared", "-fPIC", "-o", str(lib_path), str(tmp_path / "one_muscle.c"), "-lm"],
                   check=True, capture_output=True)
    lib = ctypes.CDLL(str(lib_path))
    g = flat.compile_python()
    dbl_p = ctypes.POINTER(ctypes.c_double)
    rng = np.random.default_rng(5)
    X, U = _random_points(flat, rng, 100)
    X[:, 2] = 1e5 + np.abs(X[:, 2]) * 4
    X[:, 3] = np.abs(X[:, 3]) + 1e-6
    P = np.array(flat.parameter_values)
    for name in ("f", "y", "z", "transition", "rest_mode"):
        fn = flat.function(name)
        c_fn = getattr(lib, f"one_muscle_{name}")
        n_w = fn.sz_w()
        work = (ctypes.c_double * max(n_w, 1))()
        iw = (ctypes.c_longlong * max(fn.sz_iw(), 1))()
        outs = [np.zeros(fn.nnz_out(i)) for i in range(fn.n_out())]
        res = (dbl_p * fn.sz_res())(*[o.ctypes.data_as(dbl_p) for o in outs])
        for x, u in zip(X, U):
            for q in (-1.0, 0.0, 1.0, 2.0, 3.0):
                ins = [np.ascontiguousarray(a, dtype=float) for a in _arguments(flat, name, x, u, P, q, rng)]
                arg = (dbl_p * fn.sz_arg())(*[a.ctypes.data_as(dbl_p) for a in ins])
                assert c_fn(arg, res, iw, work, 0) == 0
                got = getattr(g, name)(*[list(a) for a in ins])
                for i, o in enumerate(outs):
                    dense = np.zeros(fn.numel_out(i))
                    dense[fn.sparsity_out(i).find()] = o
                    np.testing.assert_allclose(dense, got[i], rtol=1e-13, atol=0, equal_nan=True,
                                               err_msg=f"{name} at q = {q}")


GENERATE = """
import hashlib, sys
from pamsim.assemblies import one_muscle_assembly
from pamsim.scenario import load_scenario
flat = one_muscle_assembly(load_scenario(sys.argv[1]).build_model()).flatten()
texts = [flat.python_source()] + [t for _, t in sorted(flat.c_sources().items())]
print(hashlib.sha256("".join(texts).encode()).hexdigest())
"""


def test_generation_is_byte_identical_across_processes():
    path = str(ROOT / "scenarios" / "acra2012_fig4.toml")
    digests = {subprocess.run([sys.executable, "-c", GENERATE, path], capture_output=True, text=True,
                              check=True).stdout.strip() for _ in range(2)}
    assert len(digests) == 1 and len(digests.pop()) == 64


def test_flat_model_counts_and_names(fig4_flat):
    flat = fig4_flat
    assert flat.counts == {"states": 8, "inputs": 3, "outputs": 20, "parameters": 42, "modes": 1, "indicators": 2}
    assert [v.name for v in flat.inputs] == ["valve_command", "supply_pressure_gauge_Pa", "external_force_N"]
    assert flat.index("states", "chamber.p_abs_Pa") == 2
    with pytest.raises(KeyError, match="has no state 'chamber.T_K'"):
        flat.index("states", "chamber.T_K")
    assert math.isclose(flat.parameter_values[flat.index("parameters", "load.mass_kg")], 22.74 / 9.81, rel_tol=1e-3)


RUN_FIG4 = """
import sys
import pamsim
r = pamsim.simulate(sys.argv[1])
print(repr(float(r.x_m[-1])), "casadi" in sys.modules)
"""


def test_generated_code_is_kept_on_disk_for_the_next_process(tmp_path):
    """A second process runs the model from the first one's code, without CasADi; a damaged entry is
    generated again; a key that another process could not reproduce is not stored."""
    from pamsim.modeling import code_cache

    env = {**os.environ, code_cache.CACHE_ENV: str(tmp_path / "cache")}
    path = str(ROOT / "scenarios" / "acra2012_fig4.toml")

    def run():
        out = subprocess.run([sys.executable, "-c", RUN_FIG4, path], env=env, capture_output=True, text=True,
                             check=True).stdout.split()
        return float(out[0]), out[1] == "True"

    first, loaded_first = run()
    entries = sorted((tmp_path / "cache").glob("*.json"))
    assert entries and loaded_first
    second, loaded_second = run()
    assert second == first and not loaded_second
    for entry in entries:
        entry.write_text("{ damaged")
    third, loaded_third = run()
    assert third == first and loaded_third
    assert code_cache.entry_name(("model", object())) is None
    assert code_cache.entry_name(("model", (1.0, "a", None))) is not None


def test_an_assemblys_parameter_values_are_the_flat_models_and_a_fresh_list_each_time():
    """The vector is kept after the first call: equal to the flattened model's, and a caller that changes the
    list it was given does not change the next caller's."""
    from pamsim.assemblies import scenario_assembly
    from pamsim.scenario import load_scenario

    assembly = scenario_assembly(load_scenario(Path(__file__).resolve().parents[1] / "scenarios" / "acra2012_fig4.toml"))
    first = assembly.parameter_values()
    assert first == list(assembly.flatten().parameter_values)
    first[0] = -1.0
    again = assembly.parameter_values()
    assert again == list(assembly.flatten().parameter_values) and again is not first
