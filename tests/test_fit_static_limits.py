"""``pamsim fit static`` on the README's own example muscle: geometry stays physical, the fitted
muscle file loads back, and the result claims no more than the data show."""

from __future__ import annotations

import re
import tomllib

import numpy as np
import pytest

import pamsim
from pamsim.parameter_schema import LOCK_DEG

from conftest import ROOT
from conftest import run_main as pamsim_cli

README_MUSCLE = re.search(r"`my_muscle.toml`:\n\n```toml\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)

THIN_WALL_TESTS = """# seven tests of the README muscle, loads beyond what a 1 mm wall allows: the fit drives the wall to zero
pressure_bar,contraction_mm,weight_N
2.12,19.7,70.6
3.66,32.2,86.3
4.37,22.6,112.2
3.39,52.4,10.5
2.97,26.7,97.4
3.93,27.0,110.7
3.72,38.3,60.4
"""


@pytest.fixture
def readme_muscle(tmp_path):
    path = tmp_path / "my_muscle.toml"
    path.write_text(README_MUSCLE)
    return path


def check_fitted_muscle_loads(out):
    """Every fit output loads back as a muscle, with only independent values written."""
    muscle = pamsim.muscles.load_muscle(out / "muscle.toml")
    written = tomllib.loads((out / "muscle.toml").read_text())["parameters"]
    assert not [k for k, v in written.items() if v["source"].startswith("derived")]
    return muscle


def test_readme_muscle_fit_keeps_its_geometry_physical(tmp_path, readme_muscle):
    data = tmp_path / "static.csv"
    data.write_text(THIN_WALL_TESTS)
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", readme_muscle, "-o", out)
    assert proc.returncode == 0, proc.stderr
    muscle = check_fitted_muscle_loads(out)
    v = muscle.parameters
    assert 0.0 < v["wall_thickness_m"] < v["r0_m"] < v["L0_m"]
    assert 0.0 < v["theta0_deg"] < LOCK_DEG


@pytest.mark.parametrize("free", ["r0_m,theta0_deg", "ri0_m,theta0_deg", "r0_m,wall_thickness_m,theta0_deg"])
def test_fitted_muscle_with_wall_loads_back(tmp_path, readme_muscle, free):
    # Tests the starting muscle itself would give: the fit moves the radii a little.
    muscle = pamsim.load_muscle(readme_muscle)
    force = muscle.static_force().force_N
    p_bar = np.repeat([2.0, 3.0, 4.0], 3)
    w = np.tile([10.0, 30.0, 60.0], 3)
    x = np.array([muscle.static_force().free_contraction_m(pi * 1e5, wi) for pi, wi in zip(p_bar, w)])
    assert np.all(np.abs(force(x, p_bar * 1e5) - w) < 1e-6)
    rows = "\n".join(f"{a:g},{b * 1e3 + 0.3 * (-1) ** i:.3f},{c:g}" for i, (a, b, c) in enumerate(zip(p_bar, x, w)))
    data = tmp_path / "static.csv"
    data.write_text("pressure_bar,contraction_mm,weight_N\n" + rows + "\n")
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", readme_muscle, "--free", free, "-o", out)
    assert proc.returncode == 0, proc.stderr
    fitted = check_fitted_muscle_loads(out).parameters
    assert fitted["r0_m"] - fitted["ri0_m"] == pytest.approx(fitted["wall_thickness_m"], rel=1e-9)


def test_freeing_both_wall_values_is_refused(tmp_path, readme_muscle):
    data = tmp_path / "static.csv"
    data.write_text(THIN_WALL_TESTS)
    out = tmp_path / "fit"
    proc = pamsim_cli("fit", "static", data, "--muscle", readme_muscle, "--free", "ri0_m,wall_thickness_m", "-o", out)
    assert proc.returncode == 2 and "at most one of ri0_m and wall_thickness_m" in proc.stderr
    assert proc.stderr.count("\n") == 1 and not out.exists()
