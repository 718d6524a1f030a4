"""CITATION.cff: valid CFF 1.2.0 fields, pamsim's version and license, and every paper of pamsim.references."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest
import yaml

import pamsim
from pamsim.references import _UNNAMED, _UNTITLED, REFERENCES

ROOT = Path(__file__).resolve().parents[1]
UNNAMED_AUTHOR = [{"name": "not named in the source text"}]
UNTITLED = "title not in the text pamsim was built from"


@pytest.fixture(scope="module")
def cff() -> dict:
    return yaml.safe_load((ROOT / "CITATION.cff").read_text())


def test_software_fields(cff):
    assert cff["cff-version"] == "1.2.0"
    assert cff["type"] == "software"
    assert cff["title"] == "pamsim" and cff["message"] and cff["authors"]
    assert cff["version"] == pamsim.__version__
    assert cff["license"] == tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"]


def _by_label(cff) -> dict[str, dict]:
    out = {}
    for ref in cff["references"]:
        out[re.match(r'pamsim label "([^"]+)"', ref["notes"]).group(1)] = ref
    return out


def _authors(ref: dict) -> str:
    names = [a.get("name") or f"{a['given-names']} {a['family-names']}" for a in ref["authors"]]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _venue(ref: dict) -> str:
    if "journal" in ref:
        return f"{ref['journal']} {ref['volume']}({ref['issue']})"
    if "conference" in ref:
        return ref["conference"]["name"]
    return ref["notes"]


@pytest.mark.parametrize("key", sorted(REFERENCES))
def test_every_reference_is_cited_as_pamsim_states_it(cff, key):
    r = REFERENCES[key]
    refs = _by_label(cff)
    assert r.short in refs, f"CITATION.cff has no reference labelled {r.short!r}"
    ref = refs[r.short]
    assert ref["year"] == r.year
    assert ref.get("doi", "") == r.doi
    if r.authors == _UNNAMED:
        assert ref["authors"] == UNNAMED_AUTHOR  # never guessed
    else:
        assert _authors(ref) == r.authors
    if r.title.startswith(_UNTITLED):
        assert ref["title"] == UNTITLED
        quoted = r.title.removeprefix(_UNTITLED).split("'")[1]
        assert ref["abstract"] == quoted
    else:
        assert ref["title"] == r.title
    assert r.venue in _venue(ref)


def test_no_reference_beyond_pamsim_references(cff):
    assert sorted(_by_label(cff)) == sorted(r.short for r in REFERENCES.values())
