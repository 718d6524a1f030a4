"""Every example runs, from its folder as the gallery runs it, and writes a figure there.

Each runs in a copy of ``examples/`` beside the repository's ``scenarios/``, so that the figures it
writes stay out of the source tree.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))

pytestmark = pytest.mark.docs


def test_there_are_examples():
    assert any(p.name == "plot_quickstart.py" for p in EXAMPLES)


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_and_writes_a_figure(example, tmp_path):
    folder = tmp_path / "examples"
    folder.mkdir()
    shutil.copy2(example, folder / example.name)
    (tmp_path / "scenarios").symlink_to(ROOT / "scenarios")
    (tmp_path / "pamsim").symlink_to(ROOT / "pamsim")  # scenarios that read ../pamsim/data
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run([sys.executable, example.name], cwd=folder, env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]
    figures = [p.name for p in folder.iterdir() if p.suffix in (".png", ".svg")]
    assert figures, f"{example.name} wrote no figure (the gallery shows the PNG or SVG files an example writes)"
