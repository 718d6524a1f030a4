"""force_map: a measured F(x, p) table, interpolated smoothly; bad tables give one clear line."""

from __future__ import annotations

import numpy as np
import pytest

from pamsim.muscles import load_muscle, muscle_from_dict
from pamsim.static_models import StaticModelDomainError, get
from pamsim.static_models.force_map import ForceMapError, read_force_map

SHADOW = load_muscle("shadow_6x300_acra2012")


def write_table(path, xs, ps, F, shuffle=True):
    rows = [(x, p, F(x, p)) for x in xs for p in ps]
    if shuffle:
        rows = [rows[i] for i in np.random.default_rng(1).permutation(len(rows))]
    path.write_text("# test table\ncontraction_m,pressure_gauge_Pa,force_N\n"
                    + "".join(f"{float(x)!r},{float(p)!r},{float(f)!r}\n" for x, p, f in rows))
    return path


def test_table_of_the_polynomial_is_reproduced_between_its_nodes(tmp_path):
    """The ACRA polynomial is quadratic in x and linear in p: a bicubic spline holds it exactly."""
    poly = SHADOW.static_force("acra2012_polynomial")
    xs, ps = np.linspace(0.0, 0.075, 9), np.linspace(0.4e5, 4.0e5, 5)
    f = write_table(tmp_path / "poly.csv", xs, ps, poly.force_N)
    model = get("force_map").build({"force_map_file": f})
    x = np.linspace(0.0, 0.075, 101)
    p = np.linspace(0.4e5, 4.0e5, 37)[:, None]
    assert np.max(np.abs(model.force_N(x, p) - poly.force_N(x, p))) < 1e-9
    assert model.force_N(0.0301, 3.3e5) == pytest.approx(poly.force_N(0.0301, 3.3e5), abs=1e-9)
    assert isinstance(model.force_N(0.03, 3e5), float)
    assert model.domain.x_max_m == 0.075 and model.domain.p_min_Pa == 0.4e5
    with pytest.raises(StaticModelDomainError, match="outside"):
        model.evaluate_N(0.08, 3e5)


def test_table_of_a_nonpolynomial_model_converges_with_the_grid(tmp_path):
    chou = load_muscle("mpam_survey_45mm").static_force("chou_hannaford")
    x = np.linspace(0.0, 0.02, 97)
    errors = []
    for n in (6, 12, 24):
        f = write_table(tmp_path / f"c{n}.csv", np.linspace(0.0, 0.02, n), np.linspace(0.0, 8e5, 4), chou.force_N)
        m = get("force_map").build({"force_map_file": f})
        errors.append(np.max(np.abs(m.force_N(x, 6e5) - chou.force_N(x, 6e5))))
    assert errors[0] > errors[1] > errors[2] and errors[2] < 1e-4 * chou.blocked_force_N(6e5)


def test_muscle_file_names_its_force_map(tmp_path):
    write_table(tmp_path / "mine.csv", [0.0, 0.01, 0.02], [0.0, 5e5], lambda x, p: p * 1e-5 - 100 * x)
    m = muscle_from_dict({"name": "m", "description": "d", "citation": "c", "default_static_force": "force_map",
                          "force_map": "mine.csv", "parameters": {}}, tmp_path / "m.toml")
    assert m.applicable_models() == ["force_map"]
    assert m.static_force().force_N(0.01, 2.5e5) == pytest.approx(1.5, abs=1e-12)


BAD = [
    ("contraction,pressure_gauge_Pa,force_N\n0,0,1\n", "missing column(s) contraction_m"),
    ("contraction_m,pressure_gauge_Pa,force_N\n0,0,a\n", "row 2: force_N = 'a': not a number"),
    ("contraction_m,pressure_gauge_Pa,force_N\n0,0,nan\n", "row 2: force_N = 'nan': must be finite"),
    ("contraction_m,pressure_gauge_Pa,force_N\n0,0,1\n0,0,2\n", "row 3: (contraction_m, pressure_gauge_Pa) = (0.0, 0.0): duplicate point"),
    ("contraction_m,pressure_gauge_Pa,force_N\n0,0,1\n0,1,2\n", "grid = 1 x 2: needs at least two"),
    ("contraction_m,pressure_gauge_Pa,force_N\n0,0,1\n0,1,2\n1,0,1\n", "(1, 1): missing point"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_bad_force_map_names_file_and_value(tmp_path, text, message):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(ForceMapError) as err:
        read_force_map(f)
    assert str(err.value).startswith(f"{f}: ") and message in str(err.value) and "\n" not in str(err.value)
