"""The component layer's cost, against the commit before it, measured in the same run.

    python benchmarks/bench_components.py [--baseline DIR] [--repeat N] [--rounds K]

``DIR`` is a checkout of the commit to compare with (``git worktree add DIR COMMIT``); without it
only this checkout is measured.  Each measurement runs in a fresh process with ``PYTHONPATH`` set to
the checkout, so both import their own pamsim from the same environment; the checkouts alternate
K times and each figure is the best of its K measurements.

Rows:

- fig4 on the Python backend: ``pamsim.simulate`` of the paper's Figure 4 scenario, the median of N
  calls after 3 warm-up calls (the first call of a process also generates the model's code);
- the 66 paper cases on the Python backend, serial: best of N;
- the first fig4 call of a process: with an empty code cache (generation included), then in a
  second process that finds the first one's code on disk (``pamsim.modeling.code_cache``);
- ``pamsim --help``: a fresh process, best of N;
- fig4 on the native backend (median of 20 N calls after 3 warm-up calls) and the 66 paper cases in
  one native batch (best of 4 N; the same scenario objects each time, then, as a sweep runs them,
  objects made anew before each batch, with ``with_changes({})``), at the scenario's ``rtol`` in both checkouts (a checkout whose
  native backend scales it by ``solver.native_rtol_factor`` runs these rows at factor 1, so that the
  ratio compares the code, not the tolerance); the first native fig4 call of a process with empty
  caches (this checkout generates the model's C and compiles the engine, the baseline compiles its C
  core), then in a second process that finds the library on disk;
- the same two native rows at this checkout's default factor, if it has one, with their cost against
  factor 1 (the price of the default tolerance, not of the code);
- this checkout only: flattening and generating the one-muscle model's Python (every function and
  the five per-mode sets), generating its C and compiling it with the system's C compiler, and one
  right-hand-side evaluation of the generated Python against the composed model's elements.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]

MEASURE = r"""
import json, statistics, sys, time
t0 = time.perf_counter()
import pamsim
from pamsim.paperdata import acra2012_steady_state
sc = pamsim.load_scenario(sys.argv[1] + "/scenarios/acra2012_fig4.toml")
t1 = time.perf_counter()
pamsim.simulate(sc)
first = time.perf_counter() - t1
for _ in range(3):
    pamsim.simulate(sc)
runs = []
for _ in range(int(sys.argv[2]) * 10):
    t = time.perf_counter(); pamsim.simulate(sc); runs.append(time.perf_counter() - t)
cases = [sc.with_changes({"load": {"weight_N": float(r["weight_N"])},
                          "pressure": {"supply_gauge_bar": float(r["pressure_stable_bar"])}})
         for r in acra2012_steady_state()]
grid = []
for _ in range(int(sys.argv[2])):
    t = time.perf_counter()
    for c in cases:
        pamsim.simulate(c)
    grid.append(time.perf_counter() - t)
import dataclasses
from pamsim.native import simulate_batch
from pamsim.simulator import SolverOptions
# Like for like: the native backend at the scenario's rtol in both checkouts (a checkout that scales it
# by solver.native_rtol_factor runs at factor 1 here; its default is measured on its own below).
scaled = "native_rtol_factor" in {f.name for f in dataclasses.fields(SolverOptions)}
at_rtol = {"solver": {"native_rtol_factor": 1.0}}
def like(s): return s.with_changes(at_rtol) if scaled else s
def native_times(fig, batch_cases):
    for _ in range(3):
        pamsim.simulate(fig, backend="native")
    one = []
    for _ in range(int(sys.argv[2]) * 20):
        t = time.perf_counter(); pamsim.simulate(fig, backend="native"); one.append(time.perf_counter() - t)
    many = []
    for _ in range(int(sys.argv[2]) * 4):
        t = time.perf_counter(); simulate_batch(batch_cases); many.append(time.perf_counter() - t)
    new = []  # as a sweep runs them: scenario objects never run before (a checkout may keep a scenario's inputs)
    for _ in range(int(sys.argv[2]) * 4):
        anew = [c.with_changes({}) for c in batch_cases]
        t = time.perf_counter(); simulate_batch(anew); new.append(time.perf_counter() - t)
    return statistics.median(one), min(many), min(new)
t = time.perf_counter()
pamsim.simulate(like(sc), backend="native")
native_first = time.perf_counter() - t
native, batch, batch_new = native_times(like(sc), [like(c) for c in cases])
default = native_times(sc, cases) if scaled else (None, None, None)
print(json.dumps({"pamsim_file": pamsim.__file__, "fig4_s": statistics.median(runs), "grid_s": min(grid), "first_s": first,
                  "import_s": t1 - t0, "native_fig4_s": native, "native_grid_s": batch, "native_grid_new_s": batch_new,
                  "native_first_s": native_first, "native_default_fig4_s": default[0],
                  "native_default_grid_s": default[1]}))
"""


def measure(checkout: Path, repeat: int) -> dict:
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as native_cache:
        # Cache folders of its own: the first process generates the model's code and compiles the native
        # library, the second finds both.
        env = {**os.environ, "PYTHONPATH": str(checkout), "PAMSIM_CODE_CACHE": cache,
               "PAMSIM_NATIVE_CACHE": native_cache}
        # cwd is the checkout: ``python -c`` and ``-m`` put the working directory ahead of PYTHONPATH, so
        # run from another checkout they would import that one's pamsim.
        runs = [json.loads(subprocess.run([sys.executable, "-c", MEASURE, str(checkout), str(repeat)], env=env, cwd=checkout,
                                          check=True, capture_output=True, text=True).stdout.strip().splitlines()[-1])
                for _ in range(2)]
    data = runs[0]
    if Path(data["pamsim_file"]).resolve().parents[1] != checkout.resolve():
        raise SystemExit(f"measuring {checkout} imported {data['pamsim_file']}")
    data["first_cached_s"] = runs[1]["first_s"]
    data["native_first_cached_s"] = runs[1]["native_first_s"]
    helps = []
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pamsim", "--help"], env=env, cwd=checkout, check=True, capture_output=True)
        helps.append(time.perf_counter() - t)
    data["help_s"] = min(helps)
    return data


GENERATE = r"""
import json, os, shutil, subprocess, sys, tempfile, time
import numpy as np
t0 = time.perf_counter()
import casadi
import pamsim
from pamsim.assemblies import scenario_assembly
from pamsim.model import Mode
from pamsim.modeling.pygen import compiled_by_mode
sc = pamsim.load_scenario(sys.argv[1] + "/scenarios/acra2012_fig4.toml")
t1 = time.perf_counter()
assembly = scenario_assembly(sc)
flat = assembly.flatten()
t2 = time.perf_counter()
g = flat.compile_python()
t3 = time.perf_counter()
by_mode = compiled_by_mode(assembly, "load", ("f", "y", "z", "transition", "rest_mode", "x0"))
t4 = time.perf_counter()
sources = flat.c_sources()
t5 = time.perf_counter()
cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
compile_s = float("nan")
if cc:
    with tempfile.TemporaryDirectory() as tmp:
        for name, text in sources.items():
            open(os.path.join(tmp, name), "w").write(text)
        t = time.perf_counter()
        subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", os.path.join(tmp, "m.so"),
                        os.path.join(tmp, "one_muscle.c"), "-lm"], check=True)
        compile_s = time.perf_counter() - t
t6 = time.perf_counter()
compiled_by_mode(assembly, "load", ("f", "y", "z", "transition", "rest_mode", "x0"))
cached = time.perf_counter() - t6
model = sc.build_model()
y = np.array(model.initial_state(0.01)); y[1] = 0.01; y[2] += 2e5
u = [*model.source.inputs(2.0), 0.0]
P = assembly.parameter_values()
f = by_mode[Mode.SLIP_UP].f
n = 20000
yl = y.tolist()
t = time.perf_counter()
for _ in range(n):
    f(yl, u, P, ())
gen_us = (time.perf_counter() - t) / n * 1e6
t = time.perf_counter()
for _ in range(n):
    model.rhs(2.0, y, Mode.SLIP_UP)
old_us = (time.perf_counter() - t) / n * 1e6
print(json.dumps({"import_casadi_pamsim_s": t1 - t0, "flatten_s": t2 - t1, "python_all_s": t3 - t2,
                  "python_modes_s": t4 - t3, "c_sources_s": t5 - t4, "c_compile_s": compile_s,
                  "cached_s": cached, "rhs_generated_us": gen_us, "rhs_elements_us": old_us,
                  "instructions": {k: fn.n_instructions() for k, fn in flat.functions.items()}}))
"""


def _best(values):
    """The smallest of the measurements, or None where the checkout has no such row."""
    values = [v for v in values if v is not None]
    return min(values) if values else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", type=Path, help="a checkout of the commit to compare with")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3, help="alternations of the two checkouts")
    args = ap.parse_args(argv)
    # The two checkouts alternate, and each figure is the best of the rounds: a change of the machine's
    # load during the run favours neither.
    nows, befores = [], []
    for _ in range(args.rounds):
        nows.append(measure(HERE, args.repeat))
        if args.baseline:
            befores.append(measure(args.baseline, args.repeat))
    now = {k: _best(m[k] for m in nows) for k in nows[0]}
    before = {k: _best(m[k] for m in befores) for k in befores[0]} if befores else None
    print(f"{'measure':34s} {'this checkout':>14s}" + (f" {'baseline':>10s} {'ratio':>6s}" if before else ""))
    rows = (("fig4, python backend [ms]", "fig4_s", 1e3), ("66 paper cases, python [s]", "grid_s", 1.0),
            ("first fig4 call of a process [s]", "first_s", 1.0),
            ("  the same, code kept on disk [s]", "first_cached_s", 1.0), ("import pamsim [s]", "import_s", 1.0),
            ("pamsim --help [s]", "help_s", 1.0), ("fig4, native backend [ms]", "native_fig4_s", 1e3),
            ("66 paper cases, native batch [ms]", "native_grid_s", 1e3),
            ("  the same, new scenario objects [ms]", "native_grid_new_s", 1e3),
            ("first native fig4 of a process [s]", "native_first_s", 1.0),
            ("  the same, library kept on disk [s]", "native_first_cached_s", 1.0))
    for label, key, scale in rows:
        line = f"{label:34s} {now[key] * scale:14.3f}"
        if before:
            line += f" {before[key] * scale:10.3f} {now[key] / before[key]:6.2f}"
        print(line)
    if now["native_default_fig4_s"] is not None:
        print("(the native rows run at the scenario's rtol; at this checkout's default, rtol times "
              "solver.native_rtol_factor:)")
        for label, key, like in (("fig4, native default [ms]", "native_default_fig4_s", "native_fig4_s"),
                                 ("66 paper cases, native default [ms]", "native_default_grid_s", "native_grid_s")):
            print(f"{label:34s} {now[key] * 1e3:14.3f}   {now[key] / now[like]:.2f} x factor 1")
    with tempfile.TemporaryDirectory() as cache:  # an empty code cache: everything is generated
        env = {**os.environ, "PYTHONPATH": str(HERE), "PAMSIM_CODE_CACHE": cache}
        gen = json.loads(subprocess.run([sys.executable, "-c", GENERATE, str(HERE)], check=True, capture_output=True,
                                        text=True, env=env).stdout.splitlines()[-1])
    print()
    print("one-muscle model, this checkout (a fresh process, an empty code cache):")
    print(f"  import casadi and pamsim             {gen['import_casadi_pamsim_s']:.3f} s")
    print(f"  flatten the assembly                 {gen['flatten_s']:.3f} s")
    print(f"  generate + compile its Python        {gen['python_all_s']:.3f} s (every function)")
    print(f"  the five per-mode sets               {gen['python_modes_s']:.3f} s")
    print(f"  generate its C                       {gen['c_sources_s']:.3f} s")
    print(f"  compile its C (cc -O2)               {gen['c_compile_s']:.3f} s")
    print(f"  per-mode sets again (cached)         {gen['cached_s'] * 1e3:.3f} ms")
    print(f"  right-hand side, generated Python    {gen['rhs_generated_us']:.2f} us")
    print(f"  right-hand side, composed elements   {gen['rhs_elements_us']:.2f} us "
          f"(ratio {gen['rhs_generated_us'] / gen['rhs_elements_us']:.2f})")
    print(f"  operations per function              {gen['instructions']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
