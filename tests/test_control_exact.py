"""The linearisation's exact Jacobians (CasADi's derivatives of the components' expressions) against a
second implementation (Richardson-extrapolated central differences of the composed model's
right-hand side, ``pamsim.control.linear.jacobians``), against hand values, at the valve's kink and
at a flow reversal, and the fall-back for a model with no symbolic form."""

from __future__ import annotations

import numpy as np
import pytest

import pamsim
from conftest import SCENARIOS
from pamsim.control import FrictionTreatment, MusclePlant, linearize
from pamsim.control.exact import exact_jacobians
from pamsim.control.linear import jacobians
from pamsim.control.operating_point import held_equilibrium, open_valve_equilibrium, trajectory_point

FIG4 = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml")
MODEL = FIG4.build_model()
SUPPLY = FIG4.final_pressure_gauge_Pa
POINTS = {
    "held 30 mm": held_equilibrium(MODEL, 0.030, SUPPLY),
    "valve open, chamber at supply": open_valve_equilibrium(MODEL, SUPPLY),
    "filling, sliding up at 1.1 s": trajectory_point(FIG4, 1.1),
}
TREATMENTS = [FrictionTreatment("dropped"), FrictionTreatment("regularised", 1e-3),
              FrictionTreatment("sliding", 1e-3, 1.0)]


@pytest.mark.parametrize("point", list(POINTS))
@pytest.mark.parametrize("friction", TREATMENTS, ids=lambda f: f.kind)
@pytest.mark.parametrize("valve_slope", ["mean", "fill", "vent"])
def test_exact_jacobians_agree_with_central_differences(point, friction, valve_slope):
    """Every entry to 1e-6 of itself (the differences' own error: measured 4e-7 at most), or of 1e-9
    of its block's largest entry where it is nearly zero; an exact zero (the tendon force's
    independence of the external force, m a + W - F_ext) against the differences' rounding, 1e-8."""
    op = POINTS[point]
    exact = exact_jacobians(MODEL, op.states, op.inputs, friction, valve_slope)
    diff = jacobians(MusclePlant(MODEL), op, friction, valve_slope)
    for name, e, d in zip("ABCD", exact, diff):
        floor = 1e-9 * max(np.max(np.abs(d)), np.max(np.abs(e))) + np.where(e == 0.0, 1e-8, 0.0)
        assert np.all(np.abs(e - d) <= 1e-6 * np.abs(d) + floor), (name, e, d)


def test_hand_values():
    """dx/dt = v, dv/dt per unit external force = 1/m, the tendon force does not depend on the external
    force (m a + W - F_ext), and the contraction output is the state: exactly."""
    op = POINTS["filling, sliding up at 1.1 s"]
    A, B, C, D = exact_jacobians(MODEL, op.states, op.inputs, FrictionTreatment("sliding"), "mean")
    assert A[0].tolist() == [0.0, 1.0, 0.0, 0.0]
    assert B[1, 2] == pytest.approx(1.0 / MODEL.load.mass_kg, rel=1e-15)
    assert D[2, 2] == 0.0 and C[0].tolist() == [1.0, 0.0, 0.0, 0.0]


def test_the_valve_kink_gives_fill_vent_and_their_mean():
    op = POINTS["held 30 mm"]
    assert op.inputs[0] == 0.0
    cols = {s: exact_jacobians(MODEL, op.states, op.inputs, FrictionTreatment("dropped"), s)[1][:, 0]
            for s in ("fill", "vent", "mean")}
    assert cols["fill"][3] > 0 and cols["vent"][3] > 0 and cols["fill"][3] != cols["vent"][3]
    np.testing.assert_allclose(cols["mean"], 0.5 * (cols["fill"] + cols["vent"]), rtol=1e-15)


def test_a_flow_reversal_takes_the_two_sided_slope():
    """Valve open, chamber exactly at supply: the flow reverses there; its pressure derivative at the
    point itself would be a branch's convention (zero), and the pressure pole must not vanish."""
    op = POINTS["valve open, chamber at supply"]
    A = exact_jacobians(MODEL, op.states, op.inputs, FrictionTreatment("dropped"), "mean")[0]
    assert A[2, 2] < -100.0  # the laminar branch's pole, about -204 1/s


def test_linearize_says_which_jacobians_it_took():
    assert linearize(MODEL, POINTS["held 30 mm"]).jacobian_method == "exact"
    survey = pamsim.Scenario.from_dict({
        "model": {"muscle": "mpam_survey_45mm", "static_force": "mpam_two_phase"},
        "parameters": {"E_nylon_Pa": 3e9},  # nylon 6: 2-4 GPa; the survey gives none
        "load": {"weight_N": 0.05}, "pressure": {"source": "valve", "supply_gauge_bar": 5.0, "valve_open_time_s": 0.1},
        "simulation": {"duration_s": 1.0}})
    model = survey.build_model()  # an implicit static model: tabulated, called on floats
    op = open_valve_equilibrium(model, survey.final_pressure_gauge_Pa)
    assert linearize(model, op).jacobian_method == "central differences"
