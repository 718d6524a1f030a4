"""The documentation builds as the README says, offline, with warnings as errors, and has what it claims.

The build runs on a copy of the sources in a temporary folder (the build writes generated pages into its
source folder), with every proxy pointing at a closed port, so that anything fetched from the network
fails the build.  It runs every example (sphinx-gallery), so this test also checks the gallery.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from test_docstrings import module_names

ROOT = Path(__file__).resolve().parents[1]
GENERATED = ("_build", "api", "auto_examples", "sg_execution_times.rst")  # what a build writes into docs/
NO_NETWORK = "http://127.0.0.1:9"  # the discard port: nothing listens, a connection is refused at once

pytestmark = pytest.mark.docs


@pytest.fixture(scope="module")
def html(tmp_path_factory) -> Path:
    src = tmp_path_factory.mktemp("docs_src")
    shutil.copy2(ROOT / "README.md", src / "README.md")
    shutil.copytree(ROOT / "docs", src / "docs", ignore=lambda folder, names: [
        n for n in names if Path(folder).resolve() == (ROOT / "docs").resolve() and n in GENERATED])
    shutil.copytree(ROOT / "examples", src / "examples",
                    ignore=shutil.ignore_patterns("*.png", "*.svg", "*.pdf", "__pycache__"))
    shutil.copytree(ROOT / "scenarios", src / "scenarios")
    (src / "pamsim").symlink_to(ROOT / "pamsim")  # scenarios/acra2012_grid.toml reads ../pamsim/data
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONHASHSEED": "0"}
    for var in ("http_proxy", "https_proxy", "HTTP_PROXY", "HTTPS_PROXY", "all_proxy", "ALL_PROXY"):
        env[var] = NO_NETWORK
    env.pop("no_proxy", None)
    env.pop("NO_PROXY", None)
    out = src / "docs" / "_build" / "html"
    # The README's command, from the copy's root.
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "docs", str(out)]
    proc = subprocess.run(cmd, cwd=src, env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, f"sphinx-build failed:\n{proc.stderr[-6000:]}\n{proc.stdout[-2000:]}"
    return out


def test_every_public_module_has_a_page_in_the_api_reference(html):
    missing = [name for name, _ in module_names() if not (html / "api" / f"{name}.html").is_file()]
    assert not missing, missing


def test_the_api_reference_documents_what_the_modules_define(html):
    page = (html / "api" / "pamsim.api.html").read_text()
    assert 'id="pamsim.api.run"' in page and 'id="pamsim.api.ScenarioRun"' in page
    # The names ``import pamsim`` gives link to where they are documented.
    top = (html / "api" / "pamsim.html").read_text()
    assert 'href="pamsim.backends.html#pamsim.backends.simulate"' in top
    assert 'href="pamsim.result.html#pamsim.result.Result"' in top


def _subcommands(parser, prefix=()):
    """(command words, parser) of every subcommand of ``parser``, nested ones (``fit static``) included."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield (*prefix, name), sub
                yield from _subcommands(sub, (*prefix, name))


def test_the_cli_reference_has_every_subcommand_and_option(html):
    import argparse

    from pamsim.cli import build_parser

    page = (html / "cli.html").read_text()
    text = " ".join(re.sub(r"<[^>]+>", "", page).split())
    commands = list(_subcommands(build_parser()))
    assert len(commands) >= 11
    for words, parser in commands:
        assert f"pamsim {' '.join(words)} " in text, words  # its usage line
        for action in parser._actions:
            if isinstance(action, argparse._HelpAction):
                continue  # -h/--help: the reference leaves it out
            for flag in action.option_strings:
                assert flag in page, (words, flag)


def test_the_chapters_and_the_readme_are_in_the_site(html):
    index = (html / "index.html").read_text()
    assert "Quick start" in index
    for chapter in sorted((ROOT / "docs").glob("*.md")):
        assert (html / f"{chapter.stem}.html").is_file(), chapter.name


def test_every_example_has_a_page_with_its_figure(html):
    for example in sorted((ROOT / "examples").glob("*.py")):
        page = (html / "auto_examples" / f"{example.stem}.html").read_text()
        assert re.search(rf'<img [^>]*src="[^"]*sphx_glr_{example.stem}_001\.(png|svg)"', page), example.name
