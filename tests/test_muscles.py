"""Muscle files: loading, provenance, and one clear line per mistake (in-process)."""

from __future__ import annotations

import math

import pytest

import pamsim
from pamsim.muscles import MuscleError, load_muscle, muscle_from_dict, shipped_names
from pamsim.muscles.schema import FILE_INPUTS, KNOWN, LOCK_DEG, SUFFIX_UNITS, unit_of
from pamsim.parameters import get_parameter_set
from pamsim.static_models import REGISTRY


def test_shadow_file_holds_every_value_of_the_built_in_set():
    m = pamsim.load_muscle("shadow_6x300_acra2012")
    old = get_parameter_set("shadow_6x300_acra2012")
    renamed = {"D0_m": ("r0_m", 0.5), "braid_angle_rest_deg": ("theta0_deg", 1.0)}
    for key, value in old.items():
        new_key, factor = renamed.get(key, (key, 1.0))
        assert m.parameters[new_key] == pytest.approx(value * factor, rel=1e-15), key
        assert m.parameters.entries[new_key].unit == old.entries[key].unit
    assert m.default_static_force == "acra2012_polynomial"


@pytest.mark.parametrize("name", shipped_names())
def test_every_shipped_muscle_loads_with_provenance_for_every_value(name):
    m = load_muscle(name)
    assert m.name == name and m.citation and m.description
    for key, p in m.parameters.entries.items():
        assert p.source.strip(), key
        assert p.unit == unit_of(key)
        assert p.violation(p.value) is None


def test_unit_suffixes_are_read_from_the_name():
    assert unit_of("L0_m") == "m" and unit_of("fibre_area_m2") == "m^2" and unit_of("theta0_deg") == "deg"
    assert unit_of("K1_N_per_bar_m2") == "N/(bar m^2)" and unit_of("n_fibres") == "1" and unit_of("g_m_s2") == "m/s^2"
    # The suffix table is ordered so that no suffix hides a longer one listed after it.
    suffixes = [s for s, _ in SUFFIX_UNITS]
    for i, s in enumerate(suffixes):
        assert not any(t.endswith(s) for t in suffixes[i + 1:]), s


def test_every_model_parameter_is_a_known_name():
    for spec in REGISTRY.values():
        for key in (*spec.parameters, *spec.optional):
            assert key in KNOWN or key in FILE_INPUTS, (spec.name, key)


BASE = {
    "name": "t", "description": "test muscle", "citation": "none", "default_static_force": "gaylord",
    "parameters": {
        "L0_m": {"value": 0.1, "source": "test"},
        "r0_m": {"value": 0.005, "source": "test"},
        "theta0_deg": {"value": 30.0, "source": "test"},
        "wall_thickness_m": {"value": 0.001, "source": "test"},
    },
}


def _with(path, value):
    import copy
    d = copy.deepcopy(BASE)
    node = d
    for k in path[:-1]:
        node = node[k]
    if value is _DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


_DELETE = object()

BAD = [  # (path to change, new value, text the one-line message must contain)
    (("colour",), "red", "colour = 'red': unknown key"),
    # The parameter named, not its table dumped.
    (("parameters", "L0_mm"), {"value": 1.0, "source": "x"}, "dir/bad.toml: parameters.L0_mm: unknown parameter (did you mean 'L0_m'?)"),
    (("parameters", "L0_m", "value"), "0.1", "parameters.L0_m.value = '0.1': must be a number, not a string"),
    (("parameters", "L0_m", "value"), True, "parameters.L0_m.value = true: must be a number, not a boolean"),
    (("parameters", "L0_m", "value"), _DELETE, "dir/bad.toml: missing key parameters.L0_m.value: required, a number"),
    (("parameters", "L0_m", "value"), math.inf, "parameters.L0_m.value = inf: must be a finite number"),
    (("parameters", "L0_m", "value"), -0.1, "parameters.L0_m = -0.1: must be > 0"),
    (("parameters", "L0_m", "source"), _DELETE, "missing key parameters.L0_m.source: required"),
    (("parameters", "L0_m", "unit"), "mm", "parameters.L0_m.unit = 'mm': does not match"),
    (("parameters", "L0_m", "colour"), 1, "parameters.L0_m.colour = 1: unknown key"),
    (("parameters", "theta0_deg", "value"), 54.7357, "parameters.theta0_deg = 54.7357: at or beyond the braid locking angle"),
    (("parameters", "theta0_deg", "value"), 95.0, "parameters.theta0_deg = 95.0: must lie in (0, 90)"),
    (("parameters", "wall_thickness_m", "value"), 0.006, "parameters.r0_m = 0.005: braid radius must exceed the bladder wall thickness"),
    (("parameters", "alpha_radial_deg"), {"value": 60.0, "source": "x"}, "parameters.alpha_radial_deg = 60.0: give either theta0_deg"),
    (("parameters", "ri0_m"), {"value": 0.0035, "source": "x"}, "parameters.wall_thickness_m = 0.001: inconsistent with r0_m - ri0_m"),
    (("default_static_force",), "gaylrod", "default_static_force = 'gaylrod': unknown static model (did you mean 'gaylord'?)"),
    (("citation",), _DELETE, "missing key citation: required"),
    (("rated_pressure_gauge_Pa",), -1.0, "rated_pressure_gauge_Pa = -1.0: must be > 0"),
    (("gaps",), "none", "gaps = 'none': must be a list of strings"),
    (("data",), {"file": "nope.csv"}, "data.file = 'nope.csv': no such file"),
]


@pytest.mark.parametrize("path, value, message", BAD, ids=[".".join(b[0]) for b in BAD])
def test_bad_muscle_file_names_file_key_and_value(path, value, message):
    with pytest.raises(MuscleError) as err:
        muscle_from_dict(_with(path, value), "dir/bad.toml")
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith("dir/bad.toml: ")
    assert message in text


def test_radial_plane_angle_is_converted_at_the_edge():
    d = _with(("parameters", "theta0_deg"), _DELETE)
    d["parameters"]["alpha_radial_deg"] = {"value": 61.8, "source": "Kothera Table 1"}
    m = muscle_from_dict(d, "x.toml")
    assert m.parameters["theta0_deg"] == pytest.approx(28.2, abs=1e-12)
    assert "alpha_radial_deg" not in m.parameters
    assert "converted" in m.parameters.entries["theta0_deg"].source


def test_inner_radius_and_wall_thickness_complete_each_other():
    m = muscle_from_dict(BASE, "x.toml")
    assert m.parameters["ri0_m"] == pytest.approx(0.004, rel=1e-12)
    assert m.parameters.entries["ri0_m"].source.startswith("derived")


def test_unknown_name_and_missing_path(tmp_path):
    with pytest.raises(MuscleError, match=r"muscle = 'shadow_6x300': unknown muscle \(did you mean 'shadow_6x300_acra2012'\?\)"):
        load_muscle("shadow_6x300")
    with pytest.raises(MuscleError, match="no such muscle file"):
        load_muscle(tmp_path / "none.toml")
    bad = tmp_path / "broken.toml"
    bad.write_text("name = \n")
    with pytest.raises(MuscleError, match=r"broken.toml: invalid TOML"):
        load_muscle(str(bad))


def test_a_path_loads_and_is_the_origin(tmp_path):
    f = tmp_path / "mine.toml"
    f.write_text('name = "mine"\ndescription = "d"\ncitation = "c"\ndefault_static_force = "gaylord"\n'
                 '[parameters.L0_m]\nvalue = 0.2\nsource = "measured"\n'
                 '[parameters.r0_m]\nvalue = 0.01\nsource = "measured"\n'
                 '[parameters.theta0_deg]\nvalue = 25\nsource = "measured"\n')
    m = load_muscle(str(f))
    assert m.origin == f and m.parameters["L0_m"] == 0.2
    assert "gaylord" in m.applicable_models() and "chou_hannaford" not in m.applicable_models()


def test_known_bounds_agree_with_the_built_in_parameter_set():
    """Until the built-in set is read from its muscle file, the two tables of bounds must not drift apart."""
    old = get_parameter_set("shadow_6x300_acra2012")
    for key, p in old.entries.items():
        if key in ("D0_m", "braid_angle_rest_deg"):  # renamed in the muscle file (r0_m, theta0_deg)
            continue
        if key == "theta0_deg":  # the dynamics bound it by the locking angle: they model contracting muscles
            assert (p.lower, p.upper, p.upper_open) == (KNOWN[key].lower, LOCK_DEG, True)
            continue
        k = KNOWN[key]
        assert (k.lower, k.upper, k.lower_open, k.upper_open) == (p.lower, p.upper, p.lower_open, p.upper_open), key
