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


def test_schulte_is_left_out_for_its_elastic_term_at_rest():
    """Survey eq. (15): the bracket of the elastic term, l0 sin(theta) - (cos^2/sin)((b/N) sin(theta) - 2 pi r0),
    is l0 sin(theta0) at rest, since (b/N) sin(theta0) = 2 pi r0: a pull with no pressure and no strain.
    P_u only enters the friction term, which no static map keeps."""
    import math

    from pamsim.muscles import load_muscle
    from pamsim.static_models.geometry import Braid

    g = Braid.from_parameters(load_muscle("kothera2009_5a").parameters)
    s0, c0 = math.sin(g.theta0), math.cos(g.theta0)
    bracket = g.L0 * s0 - c0 ** 2 / s0 * ((g.b / g.N) * s0 - 2 * math.pi * g.r0)
    assert bracket == pytest.approx(g.L0 * s0, rel=1e-12) and bracket > 0
    text = (ROOT / "docs" / "static_models.md").read_text()
    row = next(ln for ln in text.splitlines() if ln.startswith("| S-09 |"))
    assert "needs a law for the free-tube pressure" not in row and "nonzero at rest" in row
    listed = next(ln for ln in text.splitlines() if ln.startswith("- Schulte (S-09)"))
    assert "under-specified" not in listed
