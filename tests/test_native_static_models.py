"""Library static models on the native backend: one written in symbols runs as generated C on the
engine, a tabulated one as its spline table's B-spline on the engine; either way its trajectories
follow the Python backend's (which evaluates the same model or table) to within the integrators'
errors."""

from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.errors import InputError

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


@pytest.mark.parametrize("changes", [
    {},  # acra2012_fig4_chou_hannaford: the Shadow muscle with Chou and Hannaford's model
    {"model": {"static_force": "gaylord"}},
    {"model": {"static_force": "tondu_lopez"}},
])
def test_native_table_run_follows_the_python_model(changes):
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4_chou_hannaford.toml")
    if changes:
        sc = sc.with_changes(changes)
    nat, py = pamsim.simulate(sc, backend="native"), pamsim.simulate(sc)
    assert nat.final_mode == py.final_mode
    # These models are written in symbols: the engine runs them exactly, and the two integrators differ by
    # micrometres over the run (measured: at most 2.7 um).  Bound: 10 um.
    assert np.max(np.abs(nat.x_m - py.x_m)) < 1e-5
    assert nat.energy_balance()["relative"] < 1e-4


def test_kothera_muscle_with_its_energy_model():
    """A muscle whose parameters the C core does not have (wall thickness, bladder modulus) runs: they
    are the static force component's parameters on the engine."""
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes(
        {"model": {"muscle": "kothera2009_5a", "static_force": "kothera_energy"},
         "simulation": {"duration_s": 2.0}})
    nat, py = pamsim.simulate(sc, backend="native"), pamsim.simulate(sc)
    assert np.max(np.abs(nat.x_m - py.x_m)) < 1e-5  # measured 0.2 um


def test_a_kept_negative_force_is_refused():
    sc = pamsim.load_scenario(SCENARIOS / "acra2012_fig4.toml").with_changes(
        {"model": {"static_force_negative": "keep"}})
    with pytest.raises(InputError, match="static_force_negative = 'keep'"):
        pamsim.simulate(sc, backend="native")
