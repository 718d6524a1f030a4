"""The generalized Prandtl-Ishlinskii operator as an element of the muscle's force balance (``[hysteresis] model =
"pi"``, docs/hysteresis.md): against the Maxwell-slip elements it equals without an envelope, and against the
standalone operator (:mod:`pamsim.hysteresis.play`) driven by the run's own contraction with one."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from pamsim.backends import simulate
from pamsim.hysteresis.play import play
from pamsim.scenario import Scenario, load_scenario

from conftest import SCENARIOS, run_main

THRESHOLDS_M = [2e-4, 1e-3, 4e-3]
WEIGHTS_N_PER_M = [3750.0, 750.0, 250.0]


def _loops(hysteresis: dict, friction: str = "load_dependent", rate_Hz: float = 100.0) -> Scenario:
    spec = copy.deepcopy(dict(load_scenario(SCENARIOS / "hysteresis_loops.toml").spec))
    spec["hysteresis"] = hysteresis
    spec["model"]["friction"] = friction
    spec["simulation"]["sample_rate_Hz"] = rate_Hz
    return Scenario.from_dict(spec, "pi_loops", SCENARIOS, "pi_loops")


@pytest.mark.parametrize("backend", ["python", "native"])
def test_the_classical_operator_is_maxwell_slip_with_its_weights_as_stiffnesses(backend):
    """Without an envelope, play j of threshold r_j and weight w_j is an elasto-slide element of stiffness w_j
    and slip force w_j r_j: the Maxwell-slip elements at the constant 2.5 N level with shares w_j r_j / 2.5
    and slip displacements r_j.  The two runs are the same run."""
    pi = simulate(_loops({"model": "pi", "thresholds_m": THRESHOLDS_M, "weights_N_per_m": WEIGHTS_N_PER_M}), backend)
    shares = [w * r / 2.5 for w, r in zip(WEIGHTS_N_PER_M, THRESHOLDS_M)]
    ms = simulate(_loops({"model": "maxwell_slip", "slip_displacement_m": THRESHOLDS_M, "share": shares},
                         friction="constant"), backend)
    np.testing.assert_allclose(pi.x_m, ms.x_m, rtol=0, atol=1e-12)
    np.testing.assert_allclose(pi.signals["hysteresis.F_N"], ms.signals["hysteresis.F_N"], rtol=0, atol=1e-9)
    assert np.ptp(pi.x_m) > 0.04  # the loops do move the load


@pytest.fixture(scope="module")
def enveloped():
    hysteresis = {"model": "pi", "thresholds_m": THRESHOLDS_M, "weights_N_per_m": WEIGHTS_N_PER_M,
                  "envelope_scale_m": 0.02}
    sc = _loops(hysteresis, rate_Hz=1000.0)
    return {b: simulate(sc, b) for b in ("python", "native")}


def test_with_an_envelope_the_force_is_the_operator_along_the_run(enveloped):
    """The standalone plays, driven by g(x) = s tanh(x / s) of the run's sampled contraction from their relaxed
    state, give ``-sum w_j (g - P_rj[g])``: the element's force within 2e-3 N (of 2.5 N; the samples cut
    the turns between them by less than that at 1 kHz).  Without the envelope's slope the gap is newtons."""
    res = enveloped["python"]
    s = 0.02
    r, w = np.array(THRESHOLDS_M), np.array(WEIGHTS_N_PER_M)
    g = s * np.tanh(res.x_m / s)
    expected = -((g[:, None] - play(g, r, np.full(r.size, g[0]))) @ w)
    assert np.max(np.abs(res.signals["hysteresis.F_N"] - expected)) < 2e-3
    classical = -((res.x_m[:, None] - play(res.x_m, r, np.full(r.size, res.x_m[0]))) @ w)
    assert np.max(np.abs(res.signals["hysteresis.F_N"] - classical)) > 0.5
    # The saturated stops pull sum w_j r_j = 2.5 N.
    assert np.max(np.abs(res.signals["hysteresis.F_N"])) == pytest.approx(float(w @ r), rel=1e-9)


def test_native_runs_the_enveloped_operator_as_python_does(enveloped):
    assert np.max(np.abs(enveloped["python"].x_m - enveloped["native"].x_m)) < 1e-6


BAD = [
    ("hysteresis.thresholds_m[2]", {"thresholds_m": [2e-4, 1e-3, 1e-3]}),
    ("hysteresis.thresholds_m[0]", {"thresholds_m": [0.0, 1e-3, 4e-3]}),
    ("hysteresis.weights_N_per_m[1]", {"weights_N_per_m": [3750.0, -1.0, 250.0]}),
    ("hysteresis.weights_N_per_m", {"weights_N_per_m": [3750.0, 750.0]}),
    ("hysteresis.envelope_scale_m", {"envelope_scale_m": 0.0}),
    ("hysteresis.thresholds_m", {"thresholds_m": []}),
    ("hysteresis.share", {"share": [0.5]}),
]


@pytest.mark.parametrize("key,change", BAD, ids=[b[0] for b in BAD])
def test_bad_pi_tables_exit_2_naming_the_key(tmp_path, key, change):
    text = (SCENARIOS / "hysteresis_loops.toml").read_text()
    head = text[:text.index("[hysteresis]")]
    tail = text[text.index("[simulation]"):]
    table = {"model": "pi", "thresholds_m": THRESHOLDS_M, "weights_N_per_m": WEIGHTS_N_PER_M, **change}
    body = "\n".join(f"{k} = {v!r}".replace("'", '"') for k, v in table.items())
    path = tmp_path / "bad.toml"
    path.write_text(f"{head}[hysteresis]\n{body}\n\n{tail}")
    done = run_main("run", path, "-o", tmp_path / "out")
    assert done.returncode == 2, done.stderr
    assert key in done.stderr
    assert "Traceback" not in done.stderr
