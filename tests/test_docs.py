"""The docs cite papers properly and point only at what a reader of the repository can follow."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from pamsim.references import REFERENCES

ROOT = Path(__file__).resolve().parents[1]
DOCS = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]


def test_every_reference_is_listed_in_full_in_the_model_docs():
    text = (ROOT / "docs" / "model.md").read_text()
    for key, ref in REFERENCES.items():
        assert f"| {ref.short} | {ref.full()} |" in text, key


@pytest.mark.parametrize("path", DOCS, ids=lambda p: p.name)
def test_docs_name_no_source_files_issues_or_outside_paths(path):
    text = path.read_text()
    bad = {
        "a paper's text file": re.search(r"\b\w+_(?:pm|mckibben|survey|festo_pam)\.txt\b|acra2012_dynamic_force_model", text),
        "a path outside the repository": re.search(r"\.\./shared|shared/design|shared/papers", text),
        "an issue": re.search(r"\bissues?\b|#\d+\b", text, re.IGNORECASE),
        "the design card": re.search(r"design card", text, re.IGNORECASE),
    }
    found = {what: m.group(0) for what, m in bad.items() if m}
    assert not found, found


def test_parameter_provenance_uses_the_short_labels_not_file_keys():
    from pamsim.muscles import shipped_names
    from pamsim.parameters import get_parameter_set

    for pset in map(get_parameter_set, shipped_names()):
        for name, entry in pset.entries.items():
            assert "acra2012_dynamic" not in entry.source and ".txt" not in entry.source, name
