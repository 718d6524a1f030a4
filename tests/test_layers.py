"""pamsim's import architecture: the import-linter contract in pyproject.toml holds, it still says
what this file expects, and no module or subpackage imports another that imports it back, even
from inside a function (which import-linter's layers would let pass between siblings)."""

from __future__ import annotations

import ast
import subprocess
import sys
import tomllib
from pathlib import Path

import pamsim

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = Path(pamsim.__file__).resolve().parent

# The layers, top to bottom, as the contract must state them: changing the architecture is a
# change here and in pyproject.toml, on purpose.
EXPECTED_LAYERS = [
    "__main__",
    "cli",
    "api | hysteresis",
    "sweep | identification | control | atlas | export | envs | coupling",
    "backends | joints | muscle_alone",
    "native",
    "fmu",
    "scenario",
    "scenario_components",
    "simulator | muscle_setup | signal_tables | static",
    "result | parameters",
    "model | muscles | assemblies",
    "components",
    "elements",
    "static_models | parameter_schema | signals | plotting | atlas_plots | oscillation | paperdata | data",
    "core_table | table_checks | atomic | references | figure_style",
    "modeling",  # the component machinery knows no physics: anything may build on it
    "constants | errors | gc_control | stepping",
]


def _contracts() -> dict[str, dict]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    assert config["root_package"] == "pamsim"
    return {c["id"]: c for c in config["contracts"]}


def test_the_contract_states_the_expected_layers():
    layers = _contracts()["layers"]
    assert layers["type"] == "layers" and layers["containers"] == ["pamsim"]
    assert layers["exhaustive"] is True  # a new module fails lint-imports until it is given a layer
    assert layers["layers"] == EXPECTED_LAYERS


def test_lint_imports_keeps_every_contract():
    # The console script's own entry point (lint-imports = importlinter.cli:lint_imports_command), run
    # by this interpreter, so that it is the one the test environment installed.
    run = subprocess.run([sys.executable, "-c", "from importlinter.cli import lint_imports_command; "
                          "lint_imports_command()", "--no-cache", "--no-logo"],
                         cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert f"{len(_contracts())} kept, 0 broken" in run.stdout, run.stdout


# ---------------------------------------------------------------- import cycles
def modules(package: Path) -> dict[str, tuple[Path, bool]]:
    """``{dotted name: (file, is a package)}`` of every module below ``package`` (a folder)."""
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        out[".".join(parts[:-1] if is_package else parts)] = (path, is_package)
    return out


def import_graph(package: Path) -> dict[str, dict[str, int]]:
    """``{module: {imported module of the package: line}}`` from every import statement, at any depth
    (inside functions and ``if TYPE_CHECKING:`` too).  ``from a import b`` imports ``a.b`` when that is
    a module, else ``a``; a name that is not a module is taken as its nearest enclosing module."""
    mods = modules(package)
    top = package.name

    def nearest(name: str) -> str:
        while name and name not in mods:
            name = name.rpartition(".")[0]
        return name

    graph: dict[str, dict[str, int]] = {m: {} for m in mods}
    for mod, (path, is_package) in mods.items():
        here = mod if is_package else mod.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = here.split(".")
                    base = ".".join(parts[:len(parts) - node.level + 1] + ([node.module] if node.module else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names]
            else:
                continue
            for target in targets:
                if target == top or target.startswith(top + "."):
                    target = nearest(target)
                    if target != mod:
                        graph[mod].setdefault(target, node.lineno)
    return graph


def subpackage_graph(graph: dict[str, dict[str, int]]) -> dict[str, set[str]]:
    """The graph between the package's direct children (``pamsim.sweep``, ``pamsim.api``, ...)."""
    def child(name: str) -> str:
        return ".".join(name.split(".")[:2])

    out: dict[str, set[str]] = {}
    for a, targets in graph.items():
        out.setdefault(child(a), set()).update(child(b) for b in targets if child(b) != child(a))
    return out


def cycles(graph) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found = []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def _describe(graph, component) -> str:
    return "; ".join(f"{a} -> {b} (line {line})" for a in component for b, line in graph[a].items()
                     if b in component)


def test_no_module_imports_one_that_imports_it_back():
    graph = import_graph(PACKAGE)
    assert not cycles(graph), [_describe(graph, c) for c in cycles(graph)]


def test_no_subpackage_imports_one_that_imports_it_back():
    graph = subpackage_graph(import_graph(PACKAGE))
    assert not cycles(graph), cycles(graph)


def test_the_cycle_finder_sees_a_circle_closed_inside_a_function(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from .sub import b\n")
    (pkg / "sub" / "b.py").write_text("def f():\n    from .. import a\n")
    (pkg / "c.py").write_text("from . import a\n")
    graph = import_graph(pkg)
    assert cycles(graph) == [["pkg.a", "pkg.sub.b"]]
    assert cycles(subpackage_graph(graph)) == [["pkg.a", "pkg.sub"]]
