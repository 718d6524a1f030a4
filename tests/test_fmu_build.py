"""The FMU rebuilt by fmpy from its shipped sources, built and run from the command line, and the
docs' FMU pages (variable table, import snippets run as written).

Split from ``test_fmu.py`` (the slowest of these tests call cmake, the CLI or fresh interpreters) so
that the two files run on different test workers.
"""

from __future__ import annotations

import re
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from conftest import SCENARIOS, run_cli, run_main
from pamsim.fmu.runner import run_cs
from test_fmu import MAX_DIFF_M, _diff, _require_ecospy


@pytest.mark.parametrize("version", [2, 3])
def test_fmu_without_binaries_rebuilds_with_fmpy_compile(fmus, paper_results, tmp_path, version):
    import shutil

    if not shutil.which("cmake"):
        pytest.skip("fmpy compile needs cmake (the test extra installs it from PyPI)")
    stripped = tmp_path / f"stripped{version}.fmu"
    with zipfile.ZipFile(fmus[version]) as src, zipfile.ZipFile(stripped, "w") as dst:
        for item in src.infolist():
            if not item.filename.startswith("binaries/"):
                dst.writestr(item, src.read(item))
    proc = subprocess.run([sys.executable, "-m", "fmpy", "compile", str(stripped)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert any(n.startswith("binaries/") and n.endswith(".so") for n in zipfile.ZipFile(stripped).namelist())
    if shutil.which("nm"):  # the rebuilt binary, compiled without -fvisibility=hidden, exports only FMI functions
        with zipfile.ZipFile(stripped) as zf:
            so = next(n for n in zf.namelist() if n.endswith(".so"))
            (tmp_path / "rebuilt.so").write_bytes(zf.read(so))
        nm = subprocess.run(["nm", "-D", "--defined-only", str(tmp_path / "rebuilt.so")], capture_output=True,
                            text=True, check=True).stdout.split()
        assert not [s for s in nm if s.startswith(("pam_", "fmu_"))]
    sc, ref = paper_results["acra2012_fig5"]
    rebuilt = run_cs(sc, version, fmu_path=stripped)
    original = run_cs(sc, version, fmu_path=fmus[version])
    assert np.max(np.abs(rebuilt["contraction_m"] - original["contraction_m"])) <= 1e-9
    assert np.max(_diff(rebuilt, ref)) <= MAX_DIFF_M


# ------------------------------------------------------------------ command line


def test_cli_build_and_run_with_fmu_backends(tmp_path):
    out = run_main("fmu", "build", "-o", tmp_path / "m.fmu", "--fmi", "3")
    assert out.returncode == 0 and (tmp_path / "m.fmu").is_file(), out.stderr
    bad = run_cli("fmu", "build", "--fmi", "4")  # the one real subprocess here: exit code and line as a user sees them
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "must be 2 or 3" in bad.stderr
    scenario = SCENARIOS / "acra2012_fig6b.toml"
    csvs = {}
    for backend in ("python", "fmu-cs", "fmu-me"):
        r = run_main("run", scenario, "-o", tmp_path / backend, "--backend", backend, "--no-plot")
        assert r.returncode == 0, r.stderr
        with open(tmp_path / backend / "acra2012_fig6b.csv") as fh:
            header = fh.readline()
        csvs[backend] = (header, np.loadtxt(tmp_path / backend / "acra2012_fig6b.csv", delimiter=",", skiprows=1))
    for backend in ("fmu-cs", "fmu-me"):
        assert csvs[backend][0] == csvs["python"][0]
        assert np.max(np.abs(csvs[backend][1][:, 1] - csvs["python"][1][:, 1])) <= MAX_DIFF_M


# ------------------------------------------------------------------ docs

DOCS = SCENARIOS.parent / "docs" / "fmu.md"


def test_docs_variable_table_is_the_generated_one():
    from pamsim.fmu.generate import markdown_table

    text = DOCS.read_text()
    start = text.index("<!-- BEGIN GENERATED VARIABLE TABLE -->\n") + len("<!-- BEGIN GENERATED VARIABLE TABLE -->\n")
    end = text.index("<!-- END GENERATED VARIABLE TABLE -->")
    assert text[start:end] == markdown_table()


def test_docs_import_snippets_run_and_match_python(fmus, paper_results, tmp_path):
    import shutil

    pytest.importorskip("libcosimpy", reason="libcosimpy (test extra) is not installed")
    _require_ecospy()

    for v in (2, 3):
        shutil.copy(fmus[v], tmp_path / f"pamsim_muscle_fmi{v}.fmu")
    blocks = re.findall(r"```python\n(.*?)```", DOCS.read_text(), flags=re.S)
    blocks = [b for b in blocks if "fig4.fmu" not in b]  # a scenario's FMU: tests/test_fmu_presets.py
    assert len(blocks) == 3  # fmpy, libcosim, Ecos
    expected = f"{paper_results['acra2012_fig4'][1].x_m[-1] * 1e3:.2f}"
    printed = []
    for code in blocks:
        r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr[-2000:]
        printed += re.findall(r"final contraction (\S+) mm", r.stdout)
    assert len(printed) == 5  # fmpy ME and CS, libcosim, Ecos FMI 2.0 and 3.0
    assert set(printed) == {expected}
