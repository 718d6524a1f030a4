"""Every public definition of the pamsim package has a docstring: the API reference is made of them.

A public definition is a module of the package, or a class or function defined at a module's top level,
or a method, property or class defined in such a class, whose name (and whose module's name) does not
start with an underscore: what the API reference documents (``docs/api.rst``).  A method without a
docstring of its own counts as documented when it overrides a method that has one, as the reference
then shows that docstring.

The definitions that had no docstring when this check came in are listed in ``docstring_allowlist.txt``
beside this file.  The list only shrinks: a public definition without a docstring that is not on it
fails, and so does an entry that now has a docstring or no longer exists.

``python tests/test_docstrings.py`` prints the counts; ``--missing`` lists the undocumented names.
"""

from __future__ import annotations

import ast
import importlib
import sys
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "pamsim"
ALLOWLIST = Path(__file__).with_name("docstring_allowlist.txt")


def module_names() -> list[tuple[str, Path]]:
    """(dotted name, file) of every public module of the package."""
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        if any(part.startswith("_") for part in parts):
            continue  # private modules, and __main__
        out.append((".".join(parts), path))
    return out


def _definitions(body, prefix: str):
    """(qualified name, node) of the public classes and functions in ``body``, and in the classes among them.

    Definitions under a module- or class-level ``if`` or ``try`` count (they are still attributes)."""
    for node in body:
        if isinstance(node, (ast.If, ast.Try)):
            for block in (node.body, getattr(node, "orelse", []), getattr(node, "finalbody", []),
                          *(h.body for h in getattr(node, "handlers", []))):
                yield from _definitions(block, prefix)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) \
                and not node.name.startswith("_"):
            name = f"{prefix}.{node.name}"
            yield name, node
            if isinstance(node, ast.ClassDef):
                yield from _definitions(node.body, name)


@cache
def _module(name: str):
    return importlib.import_module(name)


def _inherits_a_docstring(module: str, qualname: str) -> bool:
    """Whether the method ``qualname`` of ``module`` overrides one with a docstring (autodoc shows that one)."""
    *owner_path, attr = qualname.split(".")
    owner = _module(module)
    for part in owner_path:
        owner = getattr(owner, part, None)
        if owner is None:
            return False
    if not isinstance(owner, type):
        return False
    for base in owner.__mro__[1:]:
        if base.__module__ == "builtins":
            continue
        found = base.__dict__.get(attr)
        if found is None:
            continue
        found = getattr(found, "__func__", found)  # classmethod, staticmethod
        return bool((getattr(found, "__doc__", None) or "").strip())
    return False


def public_definitions() -> dict[str, bool]:
    """{qualified name: has a docstring} over the public definitions of the package."""
    out: dict[str, bool] = {}
    for module, path in module_names():
        tree = ast.parse(path.read_text(), filename=str(path))
        out[module] = bool(ast.get_docstring(tree))
        classes = {module}
        for name, node in _definitions(tree.body, module):
            # A property's setter, or a definition repeated under if/else: documented if any of them is.
            out[name] = out.get(name, False) or bool(ast.get_docstring(node))
            if isinstance(node, ast.ClassDef):
                classes.add(name)
        for name, documented in list(out.items()):
            owner = name.rpartition(".")[0]
            if not documented and owner in classes and owner != module and name.startswith(module + "."):
                out[name] = _inherits_a_docstring(module, name[len(module) + 1:])
    return out


def undocumented() -> set[str]:
    return {name for name, documented in public_definitions().items() if not documented}


def allowlist() -> list[str]:
    lines = ALLOWLIST.read_text().splitlines()
    return [ln.strip() for ln in lines if ln.strip() and not ln.startswith("#")]


def test_no_public_definition_without_a_docstring_beyond_the_allowlist():
    new = sorted(undocumented() - set(allowlist()))
    assert not new, ("public definitions without a docstring (write one; the allow-list "
                     f"{ALLOWLIST.name} only shrinks): {new}")


def test_the_allowlist_only_holds_undocumented_definitions():
    listed = allowlist()
    assert listed == sorted(set(listed)), f"{ALLOWLIST.name}: keep it sorted, each name once"
    stale = sorted(set(listed) - undocumented())
    assert not stale, f"documented now, or gone: remove them from {ALLOWLIST.name}: {stale}"


def test_the_check_sees_the_kinds_of_definitions_it_claims_to():
    defs = public_definitions()
    assert defs["pamsim.api"] and defs["pamsim.api.run"] and defs["pamsim.api.ScenarioRun.summary"]
    assert "pamsim.api.ScenarioRun.failures" in defs  # a property
    assert not any(".__" in name or "._" in name for name in defs)
    assert "pamsim.__main__" not in defs


def main(argv: list[str]) -> None:
    defs = public_definitions()
    missing = sorted(name for name, documented in defs.items() if not documented)
    print(f"{len(defs)} public definitions, {len(defs) - len(missing)} with a docstring, {len(missing)} without")
    if "--missing" in argv:
        print("\n".join(missing))


if __name__ == "__main__":
    main(sys.argv[1:])
