"""Muscle files are read and validated once per version: an edited file is read again."""

import os
from pathlib import Path

from pamsim.muscles import load_muscle

SHADOW = Path(__file__).resolve().parents[1] / "pamsim" / "muscles" / "shadow_6x300_acra2012.toml"


def test_an_edited_muscle_file_is_read_again(tmp_path):
    path = tmp_path / "m.toml"
    # The data file reference is dropped: it names a file next to the shipped muscle.
    path.write_text("\n".join(l for l in SHADOW.read_text().splitlines() if not l.startswith(("[data]", "file ="))))
    first = load_muscle(path)
    assert load_muscle(path) is first  # the same version: the cached, immutable Muscle
    text = path.read_text()
    assert 'description = "' in text
    path.write_text(text.replace('description = "', 'description = "edited: ', 1))
    st = os.stat(path)
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))  # a new version even within one clock tick
    second = load_muscle(path)
    assert second is not first
    assert second.description.startswith("edited: ")
