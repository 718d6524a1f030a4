"""Sphinx configuration of pamsim's documentation (docs/about_docs.md says what each choice is for).

Build, from the repository's root, offline and with warnings as errors:

    python -m sphinx -W --keep-going -b html docs docs/_build/html
"""

from __future__ import annotations

import inspect
import sys
from pathlib import Path

import pamsim

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))  # gallery_images, the scraper of the figure files examples write

project = "pamsim"
author = "the pamsim authors"
copyright = "2026, the pamsim authors"  # as LICENSE
release = version = pamsim.__version__

extensions = [
    "myst_parser",              # the markdown chapters
    "sphinx.ext.autodoc",       # the API reference, from the docstrings
    "sphinx.ext.autosummary",   # one page per module, generated at build time
    "numpydoc",                 # docstring sections (Parameters, Returns, ...)
    "sphinx_gallery.gen_gallery",  # examples/, executed, with their figures
    "sphinxarg.ext",            # the CLI reference, from pamsim.cli.build_parser
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "atlas/*/atlas_table.md",  # shown by atlas.md, under titles
                    "**/.ipynb_checkpoints", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.md5", "auto_examples/*.codeobj.json"]
templates_path = ["_templates"]

# --- markdown (the narrative chapters are the docs/*.md files, unchanged) -------------------------
myst_enable_extensions = ["colon_fence"]
myst_heading_anchors = 3  # links to a section by its title's slug, e.g. model.md#7-chamber

# --- API reference ----------------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {
    "members": True,
    "undoc-members": True,        # a public name without a docstring is listed all the same
    "ignore-module-all": True,    # document what a module defines, never what it re-exports
    "show-inheritance": True,
    "member-order": "bysource",
}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True
autodoc_member_order = "bysource"
toc_object_entries = False  # objects stay out of the navigation tree (each module page has its summary table)
numpydoc_show_class_members = False  # autodoc lists the members; numpydoc would list them twice
numpydoc_xref_param_type = False


def _top_level_names() -> list[tuple[str, str, str]]:
    """``pamsim.NAME`` (imported on first use) with the role and the full name it is documented under."""
    out = []
    for name in pamsim.__all__:
        obj = getattr(pamsim, name)
        if inspect.ismodule(obj):
            out.append((name, "mod", obj.__name__))
        else:
            role = "class" if inspect.isclass(obj) else "func"
            out.append((name, role, f"{obj.__module__}.{obj.__qualname__}"))
    return out


autosummary_context = {"top_level_names": _top_level_names()}

# --- examples gallery -------------------------------------------------------------------------------


sphinx_gallery_conf = {
    "examples_dirs": ["../examples"],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r".*\.py$",      # run every example, not only plot_*.py
    "image_scrapers": ("gallery_images", "matplotlib"),  # _ext/gallery_images.py
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "show_memory": False,
    "capture_repr": (),                  # a bare expression shows nothing, as when the script runs
    "reference_url": {},                 # no links to other projects' docs: the build stays offline
}

# --- HTML ---------------------------------------------------------------------------------------------
smartquotes = False  # "--format" stays two hyphens in the CLI reference, and quotes stay straight in prose
html_theme = "furo"
html_title = f"pamsim {release}"
html_static_path: list[str] = []
