"""The package list in pyproject.toml must name every subpackage, or a wheel would lack it."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_pyproject_lists_every_subpackage():
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(conf["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "pamsim").rglob("__init__.py")}
    assert found <= listed, f"add to [tool.setuptools] packages: {sorted(found - listed)}"
    assert conf["package-dir"]["pamsim.fmu.csrc"] == "fmu"
    assert (ROOT / "fmu" / "src" / "pam_gcore.c").is_file()


def test_license_file_matches_pyproject_and_ships():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT"
    # license-files puts LICENSE into the sdist and the wheel's .dist-info/licenses/.
    assert project["license-files"] == ["LICENSE"]
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License\n")
    assert "Copyright (c) 2026 the pamsim authors" in text


def test_no_two_files_differ_only_by_case():
    """A checkout on a case-insensitive file system (macOS, Windows) would keep only one of them."""
    import subprocess
    from collections import defaultdict

    names = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split("\n")
    by_folded = defaultdict(set)
    for name in filter(None, names):
        parts = name.split("/")
        for k in range(1, len(parts) + 1):  # folders too: docs/A and Docs/B collide as folders
            by_folded["/".join(parts[:k]).casefold()].add("/".join(parts[:k]))
    clashes = sorted(sorted(group) for group in by_folded.values() if len(group) > 1)
    assert not clashes, f"paths that differ only by case: {clashes}"
