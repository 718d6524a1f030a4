"""pamsim.export: the scenario's model as CasADi functions, and the worked trajectory optimisation."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.export import casadi_model
from pamsim.model import Mode

ROOT = Path(__file__).resolve().parents[1]


def test_casadi_model_is_the_scenarios_model():
    sc = pamsim.load_scenario(ROOT / "scenarios" / "acra2012_fig4.toml")
    model = sc.build_model()
    cm = casadi_model(sc)
    np.testing.assert_array_equal(cm.x0, model.initial_state(0.0))
    assert cm.mode0 == Mode.STOP_LOW and cm.inputs == ("valve_command", "supply_pressure_gauge_Pa", "external_force_N")
    rng = np.random.default_rng(29)
    for mode in (Mode.SLIP_UP, Mode.SLIP_DOWN):
        f = cm.rhs(mode.label)
        for _ in range(50):
            y = np.array(model.initial_state(rng.uniform(0.0, 0.07)))
            y[1], y[2] = rng.uniform(-0.3, 0.3), rng.uniform(1.2e5, 4.5e5)
            u = (rng.uniform(-1.0, 1.0), rng.uniform(0.0, 4e5))
            want = model.slip_rhs(y, float(mode), u, 0.0)
            np.testing.assert_allclose(np.array(f(y, [*u, 0.0])).ravel(), want, rtol=1e-12, atol=1e-12)
    A, B, C, D = (np.array(m) for m in cm.functions["jacobian"](cm.x0, [1.0, 3.6e5, 0.0], cm.parameter_values,
                                                                  [float(Mode.SLIP_UP)]))
    assert A.shape == (8, 8) and B.shape == (8, 3) and C.shape[1] == 8 and D.shape[1] == 3
    assert A[0, 1] == 1.0  # dx/dt = v


def test_trajectory_optimisation_example_moves_the_load_to_40_mm(monkeypatch):
    monkeypatch.chdir(ROOT / "examples")  # the examples run from their folder
    spec = importlib.util.spec_from_file_location("trajectory_optimisation",
                                                  ROOT / "examples" / "trajectory_optimisation.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    stats, u_opt, result = example.optimise()
    assert stats["success"], stats["return_status"]
    assert np.all((u_opt >= -1e-9) & (u_opt <= 1 + 1e-9))
    # The optimiser sees the load sliding up; on the hybrid model friction stops it a little early or late.
    assert result.x_m[-1] == pytest.approx(0.040, abs=1.5e-3)
    assert result.final_mode.label == "stick"
