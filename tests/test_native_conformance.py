"""Conformance of the C core with the Python elements, point by point.

10,000 random states, inputs, parameter sets, element choices and modes are
evaluated by the C core (one call of ``pam_native_evaluate``) and by the Python
elements and model they mirror.  Every checked quantity agrees to 1e-12
relative to its own size, or, where a sum cancels (a force or flow near zero),
to 1e-12 of the size of its largest term (``_size_of_terms``).  The valve flow
and the pressure rate are held to 1e-12 of the choked flow: near a pressure
ratio of 1 the laminar branch scales with ``1 - p_down / p_up``, which turns
one rounding of the ratio (Python's branch-free min and max against C's fmin
and fmax) into a larger relative error of a small flow.  The
trajectory comparisons (``test_native.py``, ``test_fmu.py``) stay as
end-to-end checks; this suite is the main guard of Python-C consistency.
"""

from __future__ import annotations

import numpy as np
import pytest

from pamsim.core_table import C_CHOICES, EVENT_V_TOL_M_S, EVENT_X_TOL_M, SCENARIO_KEYS
from pamsim.elements.chamber import MuscleChamber
from pamsim.elements.damping import DAMPING_MODELS
from pamsim.elements.friction import FRICTION_MODELS
from pamsim.elements.load import HangingLoad
from pamsim.elements.pressure_source import PrescribedPressure, ValveChamberSource
from pamsim.elements.static_force import STATIC_FORCE_MODELS
from pamsim.elements.stops import EndStops
from pamsim.elements.valve import Iso6358Orifice, ProportionalValve33
from pamsim.model import FitRange, Mode, MuscleModel
from pamsim.native import library as native
from pamsim.parameters import get_parameter_set
from pamsim.signals import Constant
from pamsim.assemblies import one_muscle_assembly
from pamsim.modeling.pygen import compiled_by_mode
from pamsim.simulator import SolverOptions

N_POINTS = 10_000
RTOL = 1e-12
SEED = 20121203  # fixed: the same points on every run



def _random_parameters(rng, n):
    """Parameter sets around the paper's: every coefficient within +-30 % (signs kept), the gas and valve
    constants across their plausible ranges, each inside the range its Parameter accepts."""
    base = get_parameter_set("shadow_6x300_acra2012")
    params = {name: base[name] * rng.uniform(0.7, 1.3, n) for name in base}
    params["valve_b"] = rng.uniform(0.0, 0.6, n)
    params["valve_laminar_ratio"] = rng.uniform(0.95, 0.9999, n)
    params["polytropic_index"] = rng.choice([1.0, 1.2, 1.4], n)
    angle = "theta0_deg" if "theta0_deg" in base else "braid_angle_rest_deg"  # renamed on another branch
    params[angle] = rng.uniform(10.0, 40.0, n)
    params["stop_restitution"] = rng.uniform(0.0, 1.0, n)
    return params


def _points():
    rng = np.random.default_rng(SEED)
    n = N_POINTS
    params = _random_parameters(rng, n)
    choice = {key: rng.integers(0, len(C_CHOICES[key]), n) for key in SCENARIO_KEYS}
    mode = rng.choice([int(m) for m in Mode], n)
    x = rng.uniform(0.0, 1.0, n)  # as a fraction of the braid-lock contraction, on the stop in a stop mode
    x[mode == Mode.STOP_LOW] = 0.0
    x[mode == Mode.STOP_HIGH] = 1.0
    v = rng.uniform(-0.5, 0.5, n) * (np.abs(mode) == 1)  # a held load is at rest
    p_abs = rng.uniform(0.3e5, 5.5e5, n)
    inputs = {"valve_command": rng.choice([-1.0, 0.0, 1.0, 0.5], n) * rng.choice([1.0, rng.uniform()], n),
              "supply_pressure_gauge_Pa": rng.uniform(0.0, 4.5e5, n),
              "prescribed_pressure_gauge_Pa": rng.uniform(-0.5e5, 4.5e5, n),
              "load_mass_kg": rng.uniform(0.1, 8.0, n),  # heavy loads at low pressure: negative friction levels
              "external_force_N": rng.uniform(-10.0, 10.0, n)}
    temperature = rng.uniform(250.0, 350.0, n)
    return params, choice, mode, np.column_stack([x, v, p_abs, temperature]), inputs


class _AlwaysFirst(dict):
    """Choice index 0 (the first, the default) for every key: the valve source."""

    def __missing__(self, key):
        return [0] * N_POINTS


_VALVE_CHOICE = _AlwaysFirst()


def _model(p, choice, inputs, k) -> MuscleModel:
    """The Python model of point ``k``, composed from its elements as ``Scenario.build_model`` does."""
    options = {"friction_negative_level": C_CHOICES["friction_negative_level"][choice["friction_negative_level"][k]]}
    if C_CHOICES["source"][choice["source"][k]] == "valve":
        source = ValveChamberSource(ProportionalValve33(Iso6358Orifice.from_parameters(p)),
                                    MuscleChamber.from_parameters(p),
                                    Constant(float(inputs["supply_pressure_gauge_Pa"][k])),
                                    Constant(float(inputs["valve_command"][k])), p["T_supply_K"], p["p_atm_Pa"])
    else:
        source = PrescribedPressure(Constant(float(inputs["prescribed_pressure_gauge_Pa"][k])))
    return MuscleModel(
        static_force=STATIC_FORCE_MODELS[C_CHOICES["static_force"][choice["static_force"][k]]](p, options),
        friction=FRICTION_MODELS[C_CHOICES["friction"][choice["friction"][k]]](p, options),
        damping=DAMPING_MODELS[C_CHOICES["damping"][choice["damping"][k]]](p, options),
        load=HangingLoad(float(inputs["load_mass_kg"][k]), p["g_m_s2"], Constant(float(inputs["external_force_N"][k]))),
        stops=EndStops.from_parameters(p),
        source=source,
        fit_range=FitRange(p["fit_x_min_m"], p["fit_x_max_m"], p["fit_p_max_Pa"]))


def _generated(model, opts):
    """The Python code generated from the model's components (indicators and rest decisions by mode),
    its parameter values and its inputs at t = 0."""
    assembly = one_muscle_assembly(model, 0.0, None, opts.stick_margin_N, opts.release_margin_N)
    code = compiled_by_mode(assembly, "load", ("z", "rest_mode"))
    return code, assembly.parameter_values(), [*model.source.inputs(0.0), model.load.external_N(0.0)]


def _c_indicators_from_python(generated, mode, y):
    """The C indicators (positive inside the mode, shifted by the shared tolerances) from the
    components' indicators and the margins they give an integrator like the C core's."""
    code, P, u = generated
    z, margin = code[Mode(mode)].z(list(y), u, P, ())
    return z[0] + margin[0], z[1] + margin[1]


@pytest.fixture(scope="module")
def evaluated():
    params, choice, mode, raw_states, inputs = _points()
    n = len(mode)
    reals = np.tile(native.REAL_DEFAULTS, (n, 1))
    for name, values in {**params, **inputs}.items():
        reals[:, native.REAL_INDEX[name]] = values
    opts = SolverOptions()
    reals[:, native.REAL_INDEX["stick_margin_N"]] = opts.stick_margin_N
    reals[:, native.REAL_INDEX["release_margin_N"]] = opts.release_margin_N
    ints = np.tile(native.INT_DEFAULTS, (n, 1))
    for key, column in (("friction", "friction_model"), ("damping", "damping_model"), ("source", "pressure_source"),
                        ("friction_negative_level", "friction_negative_level")):
        ints[:, native.INT_INDEX[column]] = choice[key]
    py = {name: np.empty(n) for name in native.QUANTITIES}
    states = np.empty((n, 4))
    dp_terms = np.zeros(n)  # the size of the two terms of the chamber's pressure rate
    for k in range(n):
        p = {name: float(values[k]) for name, values in params.items()}
        model = _model(p, choice, inputs, k)
        fraction, v, p_abs, temperature = raw_states[k]
        x = fraction * model.stops.x_high_m
        valve = isinstance(model.source, ValveChamberSource)
        chamber = MuscleChamber.from_parameters(p)
        volume = chamber.volume_m3(x)
        air = chamber.air_mass_kg(p_abs, volume, temperature)  # a gas temperature of 250-350 K
        states[k] = (x, v, p_abs, air)
        y = np.array([x, v, *((p_abs, air) if valve else ()), 0.0, 0.0, 0.0, 0.0])
        source_inputs = model.source.inputs(0.0)
        p_gauge = float(model.source.pressure_gauge_Pa(y[2:2 + model.n_source], source_inputs))
        py["pressure_gauge_Pa"][k] = p_gauge
        py["static_force_N"][k] = model.static_force.force_N(x, p_gauge)
        py["coulomb_level_N"][k] = model.friction.level_N(x, p_gauge, model.load.mass_kg)
        py["damping_force_N"][k] = model.damping.force_N(v)
        # The valve and chamber at every point, also where the model's source is prescribed.
        valve_source = model.source if valve else _model(p, _VALVE_CHOICE, inputs, k).source
        py["pressure_rate_Pa_s"][k], py["valve_flow_kg_s"][k] = valve_source.derivatives(
            [p_abs, air], x, v, valve_source.inputs(0.0))
        T_in = max(p["T_supply_K"], temperature)
        choked = p["valve_C_m3_per_s_Pa"] * p["rho0_kg_m3"] * 6.5e5 * np.sqrt(p["T0_K"] / 250.0)
        dp_terms[k] = p["polytropic_index"] * (p["R_J_per_kg_K"] * T_in * choked
                                               + p_abs * abs(chamber.dvolume_dx_m2(x) * v)) / volume
        dy = model.rhs(0.0, y, Mode(int(mode[k])))
        py["rhs_x"][k], py["rhs_v"][k] = dy[0], dy[1]
        py["rhs_p"][k], py["rhs_m"][k] = (dy[2], dy[3]) if valve else (0.0, 0.0)
        generated = _generated(model, opts)
        py["indicator_1"][k], py["indicator_2"][k] = _c_indicators_from_python(generated, int(mode[k]), y)
        py["net_force_N"][k], py["level_at_rest_N"][k] = model.rest_forces(0.0, y)
        where = Mode.STICK if Mode(int(mode[k])).is_slip else Mode(int(mode[k]))
        code, P, u = generated
        py["rest_mode"][k] = int(code[where].rest_mode(list(y), u, P, ())[0][0])
        py["volume_m3"][k] = volume
        py["upper_stop_m"][k] = model.stops.x_high_m
    c = native.evaluate(reals, ints, states, mode)
    return {"python": py, "c": c, "mode": mode, "choice": choice, "params": params, "states": states,
            "dp_terms": dp_terms}


def _size_of_terms(e, name):
    """The size of the largest term summed into a quantity: the scale of its rounding error."""
    py, params, (x, v, p_abs, air) = e["python"], e["params"], e["states"].T
    p_bar = np.abs(py["pressure_gauge_Pa"]) / 1e5
    if name == "static_force_N":
        return ((np.abs(params["K1_N_per_bar_m2"]) * x + np.abs(params["K2_N_per_bar_m"])) * x
                + np.abs(params["C1_N_per_bar"])) * p_bar + (np.abs(params["S1_N_per_m2"]) * x
                                                              + np.abs(params["S2_N_per_m"])) * x + np.abs(params["S3_N"])
    if name in ("net_force_N", "level_at_rest_N", "rhs_v", "indicator_1", "indicator_2"):
        forces = (_size_of_terms(e, "static_force_N") + np.abs(py["coulomb_level_N"]) + np.abs(py["damping_force_N"])
                  + 8.0 * params["g_m_s2"] + 10.0)  # loads up to 8 kg, external forces up to 10 N
        if name == "rhs_v":
            return forces / 0.1  # an acceleration: divided by a mass of at least 0.1 kg
        if name.startswith("indicator"):  # sliding: a speed or a distance to a stop
            return np.where(np.abs(e["mode"]) == 1, np.abs(v) + py["upper_stop_m"], forces)
        return forces
    if name in ("valve_flow_kg_s", "rhs_m"):
        # the flow is a product (no cancellation) but its laminar branch scales 1 - p_down/p_up:
        # the choked flow from the higher of the two pressures bounds its rounding
        return params["valve_C_m3_per_s_Pa"] * params["rho0_kg_m3"] * 6.5e5 * np.sqrt(params["T0_K"] / 250.0)
    if name in ("pressure_rate_Pa_s", "rhs_p"):
        return e["dp_terms"]
    if name in ("coulomb_level_N",):
        return (p_bar + params["phi_bar_per_kg"] * 8.0) * (np.abs(params["N2_N_per_bar_m2"]) * x * x
                                                          + np.abs(params["N1_N_per_bar_m"]) * x
                                                          + np.abs(params["N0_N_per_bar"]))
    return np.abs(py[name])


QUANTITY_SCALES = ("static_force_N", "coulomb_level_N", "damping_force_N", "valve_flow_kg_s", "pressure_rate_Pa_s",
                   "rhs_x", "rhs_v", "rhs_p", "rhs_m", "indicator_1", "indicator_2", "net_force_N",
                   "level_at_rest_N", "volume_m3", "upper_stop_m", "pressure_gauge_Pa")


def test_points_cover_every_mode_and_element_choice(evaluated):
    for m in Mode:
        assert np.count_nonzero(evaluated["mode"] == int(m)) > 1000
    for key in SCENARIO_KEYS:
        for i in range(len(C_CHOICES[key])):
            assert np.count_nonzero(evaluated["choice"][key] == i) > N_POINTS // (2 * len(C_CHOICES[key]))
    level = evaluated["python"]["coulomb_level_N"]
    assert np.count_nonzero(level == 0.0) > 100  # the clamp of a negative load-dependent level is exercised


@pytest.mark.parametrize("name", QUANTITY_SCALES)
def test_c_core_matches_python_elements(evaluated, name):
    py, c = evaluated["python"][name], evaluated["c"][name]
    ok = np.isfinite(py)
    assert np.count_nonzero(ok) == N_POINTS
    scale = np.maximum(np.abs(py), _size_of_terms(evaluated, name))[ok]
    err = np.abs(c[ok] - py[ok])
    worst = int(np.argmax(err / np.where(scale > 0, scale, 1.0)))
    assert np.all(err <= RTOL * scale), (name, float(c[ok][worst]), float(py[ok][worst]), float(err[worst]))


def test_rest_mode_decisions_agree(evaluated):
    py, c = evaluated["python"]["rest_mode"], evaluated["c"]["rest_mode"]
    assert np.array_equal(py, c)
    assert len(np.unique(c)) == 5  # slip both ways, stuck, and held on either stop
