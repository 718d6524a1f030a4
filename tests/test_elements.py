"""Each model element against hand calculations from its defining equation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pamsim.elements.chamber import MuscleChamber
from pamsim.elements.damping import LinearDamping, NoDamping, PaperDamping
from pamsim.elements.friction import ConstantCoulomb, LoadDependentCoulomb
from pamsim.elements.static_force import Acra2012Polynomial
from pamsim.elements.stops import EndStops
from pamsim.elements.valve import Iso6358Orifice, ProportionalValve33
from pamsim.paperdata import acra2012_steady_state
from pamsim.parameters import get_parameter_set
from pamsim.signals import FirstOrderLag, Ramp, Step

P = get_parameter_set("shadow_6x300_acra2012")

# The six training tests of the paper (sec. 3.2): (stable pressure, weight) -> Table 1/2 data.
TRAINING = [(12.74, 2.8), (22.74, 2.0), (22.74, 3.6), (32.74, 3.6), (42.74, 4.0), (52.74, 4.0)]


@pytest.mark.parametrize("weight_N, step_bar", TRAINING)
def test_static_force_returns_the_hung_weight_at_training_tests(weight_N, step_bar):
    data = acra2012_steady_state()
    row = data[(data["weight_N"] == weight_N) & (data["pressure_step_bar"] == step_bar)][0]
    F = Acra2012Polynomial.from_parameters(P).force_N(row["contraction_stable_mm"] * 1e-3,
                                                      row["pressure_stable_bar"] * 1e5)
    assert abs(F - weight_N) <= 0.02


def test_static_force_hand_value_and_units():
    # eq. (11) at x = 50 mm, 3 bar, computed term by term.
    x, Pb = 0.05, 3.0
    hand = (-476.95 * x * x - 188.39 * x + 23.90) * Pb + 2562.4 * x * x - 245.48 * x - 11.56
    assert Acra2012Polynomial.from_parameters(P).force_N(x, Pb * 1e5) == pytest.approx(hand, rel=1e-12)


def test_load_dependent_friction_eq7_and_clamp():
    fr = LoadDependentCoulomb.from_parameters(P)
    x, Pb, m = 0.04, 3.6, 12.74 / 9.81
    hand = (Pb - m) * (228.93 * x * x - 90.43 * x + 6.87)
    assert fr.level_N(x, Pb * 1e5, m) == pytest.approx(hand, rel=1e-12)
    # 2.0 bar with 22.74 N: P - m = -0.318 < 0 -> clamped to zero, or its magnitude with "abs".
    m2 = 22.74 / 9.81
    assert fr.level_N(x, 2.0e5, m2) == 0.0
    fr_abs = LoadDependentCoulomb.from_parameters(P, {"friction_negative_level": "abs"})
    assert fr_abs.level_N(x, 2.0e5, m2) == pytest.approx(abs((2.0 - m2) * (228.93 * x * x - 90.43 * x + 6.87)))
    # Works on arrays too (used to rebuild the force breakdown of a trace).
    arr = fr.level_N(np.array([x, x]), np.array([3.6e5, 2.0e5]), m2)
    assert arr[1] == 0.0 and arr[0] > 0.0
    with pytest.raises(ValueError):
        LoadDependentCoulomb.from_parameters(P, {"friction_negative_level": "signed"})


def test_friction_polynomial_stays_positive_below_102_mm():
    fr = LoadDependentCoulomb.from_parameters(P)
    x = np.linspace(0.0, 0.1, 200)
    assert np.all(fr.level_N(x, 5e5, 0.0) > 0.0)


def test_constant_friction():
    assert ConstantCoulomb.from_parameters(P).level_N(0.03, 1e5, 2.0) == 2.5


@pytest.mark.parametrize("damping", [PaperDamping.from_parameters(P), LinearDamping.from_parameters(P), NoDamping()])
def test_damping_is_zero_at_rest_and_odd(damping):
    assert damping.force_N(0.0) == 0.0
    assert damping.force_N(0.3) == pytest.approx(-damping.force_N(-0.3))


def test_paper_damping_reading():
    d = PaperDamping.from_parameters(P)
    v = 0.5
    assert d.force_N(v) == pytest.approx(-1.01 * v + 0.80 * v * abs(v))
    # D1 < 0: this reading adds energy below |v| = -D1/D2 = 1.2625 m/s (MODEL_NOTES sec. 3).
    assert d.force_N(1.0) < 0.0 < d.force_N(1.5)


ORIFICE = Iso6358Orifice.from_parameters(P)
CHOKED = 1e-9 * 1.185  # C rho0


def test_valve_choked_flow():
    flow = ORIFICE.mass_flow_kg_s(5e5, 1e5, 293.15, 293.15)
    assert flow == pytest.approx(CHOKED * 5e5, rel=1e-12)
    # sqrt(T0/T) temperature correction.
    assert ORIFICE.mass_flow_kg_s(5e5, 1e5, 4 * 293.15, 293.15) == pytest.approx(CHOKED * 5e5 / 2, rel=1e-12)


def test_valve_subsonic_and_laminar_branch():
    b = 0.3
    r = 0.6
    hand = CHOKED * 5e5 * math.sqrt(1 - ((r - b) / (1 - b)) ** 2)
    assert ORIFICE.mass_flow_kg_s(5e5, r * 5e5, 293.15, 293.15) == pytest.approx(hand, rel=1e-12)
    # Continuous at the laminar ratio, linear above it, zero at ratio 1.
    r_lam = 0.999
    at = ORIFICE.mass_flow_kg_s(5e5, r_lam * 5e5, 293.15, 293.15)
    assert at == pytest.approx(CHOKED * 5e5 * math.sqrt(1 - ((r_lam - b) / (1 - b)) ** 2), rel=1e-9)
    mid = ORIFICE.mass_flow_kg_s(5e5, 0.9995 * 5e5, 293.15, 293.15)
    assert mid == pytest.approx(at / 2, rel=1e-6)
    assert ORIFICE.mass_flow_kg_s(5e5, 5e5, 293.15, 293.15) == 0.0


def test_valve_reverses_with_the_pressure_difference():
    assert ORIFICE.mass_flow_kg_s(2e5, 4e5, 293.15, 293.15) == pytest.approx(
        -ORIFICE.mass_flow_kg_s(4e5, 2e5, 293.15, 293.15))


def test_proportional_valve_command_scaling():
    valve = ProportionalValve33(ORIFICE)
    args = (2e5, 293.15, 5e5, 293.15, 1.01325e5)
    full = valve.inflow_kg_s(1.0, *args)
    assert full == pytest.approx(ORIFICE.mass_flow_kg_s(5e5, 2e5, 293.15, 293.15))
    assert valve.inflow_kg_s(0.5, *args) == pytest.approx(full / 2)
    assert valve.inflow_kg_s(0.0, *args) == 0.0
    vent = valve.inflow_kg_s(-1.0, *args)
    assert vent == pytest.approx(-ORIFICE.mass_flow_kg_s(2e5, 1.01325e5, 293.15, 293.15))
    assert vent < 0.0


def test_chamber_volume_is_the_cylinder_at_rest_and_grows_with_contraction():
    ch = MuscleChamber.from_parameters(P)
    cylinder = math.pi * 0.006 ** 2 / 4 * 0.3
    assert ch.volume_m3(0.0) - P["dead_volume_m3"] == pytest.approx(cylinder, rel=1e-12)
    assert 2.8 < (ch.volume_m3(0.075) - P["dead_volume_m3"]) / cylinder < 3.6  # "roughly three times"
    h = 1e-6
    fd = (ch.volume_m3(0.03 + h) - ch.volume_m3(0.03 - h)) / (2 * h)
    assert ch.dvolume_dx_m2(0.03) == pytest.approx(fd, rel=1e-7)


def test_closed_isothermal_chamber_keeps_pV_constant():
    ch = MuscleChamber.from_parameters(P)
    p, V, dV = 3e5, ch.volume_m3(0.02), 1e-6
    assert ch.pressure_rate_Pa_s(p, V, dV, 0.0, 293.15) == pytest.approx(-p * dV / V)


def test_upper_stop_is_the_braid_lock_angle():
    stops = EndStops.from_parameters(P)
    ch = MuscleChamber.from_parameters(P)
    L = 0.3 - stops.x_high_m
    assert math.degrees(math.acos(L / ch.thread_length_m)) == pytest.approx(54.7356, abs=1e-3)
    assert stops.x_low_m == 0.0
    assert stops.restitution == 0.0  # inelastic by default


def test_signals():
    s = Step(1.0, 0.0, 2.0)
    assert s(0.999) == 0.0 and s(1.0) == 2.0
    assert list(s(np.array([0.0, 2.0]))) == [0.0, 2.0]
    r = Ramp(1.0, 3.0, 0.0, 4.0)
    assert r(2.0) == pytest.approx(2.0) and r(5.0) == 4.0
    lag = FirstOrderLag(1.0, 0.0, 1.0, 0.5)
    assert lag(1.5) == pytest.approx(1 - math.exp(-1)) and lag(0.5) == 0.0
    assert lag(np.array([1.5]))[0] == pytest.approx(1 - math.exp(-1))


def test_signal_breakpoints_and_final_values():
    assert Step(1.0, 0.0, 2.0).breakpoints == (1.0,) and Step(1.0, 0.0, 2.0).final_value == 2.0
    assert Ramp(0.5, 1.5, 0.0, 3.0).breakpoints == (0.5, 1.5) and Ramp(0.5, 1.5, 0.0, 3.0).final_value == 3.0
    assert FirstOrderLag(1.0, 0.0, 4.0, 0.1).final_value == 4.0


@pytest.mark.parametrize("registry, protocol", [
    ("pamsim.elements.static_force:STATIC_FORCE_MODELS", "StaticForce"),
    ("pamsim.elements.friction:FRICTION_MODELS", "Friction"),
    ("pamsim.elements.damping:DAMPING_MODELS", "Damping"),
])
def test_every_registry_entry_builds_from_params_and_options_into_its_protocol(registry, protocol):
    """One builder shape for every registry: ``builder(params, options)``, no special case per entry."""
    import importlib

    from pamsim.elements import contracts

    module, name = registry.split(":")
    entries = getattr(importlib.import_module(module), name)
    proto = getattr(contracts, protocol)
    for key, builder in entries.items():
        params = _params_giving(key) if protocol == "StaticForce" else P
        if params is None:  # a model no shipped muscle gives the parameters of (its file names its own)
            continue
        element = builder(params, {"friction_negative_level": "abs"})
        assert isinstance(element, proto), key
        assert element.name == key


def _params_giving(model: str):
    """The dynamics parameters of the first shipped muscle (the Shadow muscle first) that gives
    every parameter ``model`` needs, or None."""
    from pamsim.muscles import shipped_names
    from pamsim.static_models import REGISTRY

    for name in ["shadow_6x300_acra2012", *shipped_names()]:
        params = get_parameter_set(name)
        if not REGISTRY[model].missing(params):
            return params
    return None


def test_the_negative_level_option_reaches_the_friction_through_the_registry():
    from pamsim.elements.friction import FRICTION_MODELS

    x, p, m = 0.02, 1.0e5, 3.0  # P - m = 1 - 3 bar < 0: clamped to zero, or its magnitude
    raw = (1.0 - P["phi_bar_per_kg"] * m) * (P["N2_N_per_bar_m2"] * x * x + P["N1_N_per_bar_m"] * x + P["N0_N_per_bar"])
    assert raw < 0
    assert FRICTION_MODELS["load_dependent"](P, {"friction_negative_level": "clamp"}).level_N(x, p, m) == 0.0
    assert FRICTION_MODELS["load_dependent"](P, {"friction_negative_level": "abs"}).level_N(x, p, m) == pytest.approx(-raw)
