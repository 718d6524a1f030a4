"""The paper's cases with a tube and the thermal chamber: a sweep carries its base scenario's pneumatic line,
and ``benchmarks/fidelity_pneumatics.py`` reruns the cases through it (docs/validation.md, section 6)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import pamsim
from pamsim.elements.chamber import MuscleChamber
from pamsim.errors import InputError
from pamsim.parameters import get_parameter_set
from pamsim.sweep import load_sweep, settled_time_s

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
SCRIPT = ROOT / "benchmarks" / "fidelity_pneumatics.py"
FRICTION = "load_dependent"
CASES = (22, 41, 53, 62)
"""Four of the 66: 1.63 bar / 22.74 N (its friction level clamped, still ringing at 8 s), 2.83, 3.63 and
3.99 bar with 22.74 and 42.74 N (lifted, overshooting, stuck)."""


@pytest.fixture(scope="module")
def fidelity():
    spec = importlib.util.spec_from_file_location("fidelity_pneumatics", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks its module up there
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        del sys.modules[spec.name]


def _line_sweep(tmp_path: Path) -> Path:
    sweep = tmp_path / "line.toml"
    sweep.write_text(f'base_scenario = "{SCENARIOS / "supply_chain.toml"}"\n'
                     'friction_models = ["load_dependent"]\n'
                     '[[case]]\npressure_bar = 3.6\nweight_N = 22.74\n'
                     '[[case]]\npressure_bar = 2.4\nweight_N = 12.74\n')
    return sweep


def test_a_sweep_runs_its_base_scenarios_pneumatic_line(tmp_path):
    """A base scenario with a supply line (supply, feed hose, reservoir, tube) is swept, not refused: every
    case keeps the line, its row is the case's own run, and the settling times are that run's."""
    spec = load_sweep(_line_sweep(tmp_path))
    result = pamsim.sweep(spec)
    for case, row in zip(spec.cases, result.rows):
        scenario = spec.case_scenario(case, FRICTION)
        assert [a.component.name for a in scenario.added_components] == ["supply", "feed", "reservoir", "tube"]
        run = pamsim.simulate(scenario)
        assert "tube.p_gauge_Pa" in run.signals
        assert row["failure"] == ""
        assert row["final_contraction_m"] == run.x_m[-1]
        # the supply line's regulator takes the case's pressure: the muscle ends at it
        assert abs(run.p_gauge_Pa[-1] - case.pressure_bar * 1e5) < 1.0
        assert row["settled_time_s"] == settled_time_s(run.t_s, run.p_gauge_Pa)
        assert row["contraction_settled_time_s"] == settled_time_s(run.t_s, run.x_m)


def test_a_sweep_still_refuses_a_component_that_acts_on_the_load(tmp_path):
    """A spring on the load changes the static equilibrium the sweep computes from the rig: refused, named,
    when it comes with a pneumatic line too (only the spring is named)."""
    base = tmp_path / "line_and_spring.toml"
    base.write_text((SCENARIOS / "supply_chain.toml").read_text()
                    + '\n[[component]]\nname = "spring"\ntype = "linear_spring"\nk_N_per_m = 300.0\n'
                      'x_free_m = 0.0\n[component.connect]\nflange = "load.flange"\n')
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(f'base_scenario = "{base}"\n[[case]]\npressure_bar = 3.6\nweight_N = 22.74\n')
    with pytest.raises(InputError, match=r"static analysis takes the rig and its pneumatic line alone, not the components added to it \('spring'\);"):
        load_sweep(sweep)


def _runs(fidelity, config, cases=CASES):
    spec = fidelity.grid(FRICTION, config)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # LSODA's convergence notes on the stiff tube
        return [pamsim.simulate(spec.case_scenario(spec.cases[i], FRICTION)) for i in cases]


def test_a_negligible_tube_gives_todays_cases(fidelity):
    """A tube of 2 mm x 3 mm bore (14 mm^3, 1.5e-3 of the muscle's volume at rest; its laminar drop under
    the valve's choked flow below 10 Pa) reproduces today's rig case by case, on the script's path.

    Tolerance, from the gas: the tube's only first-order effect is its volume V_t at the valve's side, which
    the valve fills with the muscle, so the pressure follows today's trace slowed by at most V_t / V_0
    (V_0 the muscle's smallest volume, at rest); over the fill (the pressure's settling time after the valve
    opens) the trajectory lags by at most dt = t_fill V_t / V_0, which moves the contraction by at most
    max|v| dt.  The difference must also be first order in V_t: twice the bore's length, twice the
    largest difference (within 10 %).  And a real tube (0.25 m x 2.5 mm) exceeds the bound: the check can
    fail."""
    tiny = fidelity.Config(2e-3, 3e-3)
    today_rows, _ = fidelity.rerun(FRICTION, fidelity.Config(), "python", CASES)
    tiny_rows, _ = fidelity.rerun(FRICTION, tiny, "python", CASES)
    today, small, double = (_runs(fidelity, c) for c in (fidelity.Config(), tiny, fidelity.Config(4e-3, 3e-3)))
    V_t = np.pi * 3e-3 ** 2 / 4 * 2e-3
    V_0 = MuscleChamber.from_parameters(get_parameter_set("shadow_6x300_acra2012")).volume_m3(0.0)
    assert 8.5e-6 < V_0 < 1e-5  # the braid at rest, 8.5 cm^3 (docs/pneumatics.md), and the dead volume
    valve_open_s = 1.0  # acra2012_fig4.toml, the grid's base
    bounds = []
    for row, tiny_row, ref, run, run2 in zip(today_rows, tiny_rows, today, small, double):
        t_fill = row["settled_time_s"] - valve_open_s
        bound = np.max(np.abs(ref.v_m_s)) * t_fill * V_t / V_0 + 1e-6
        bounds.append(bound)
        assert abs(tiny_row["final_contraction_m"] - row["final_contraction_m"]) <= bound
        assert np.max(np.abs(run.x_m - ref.x_m)) <= bound
        assert tiny_row["at_rest"] == row["at_rest"]
        ratio = np.max(np.abs(run2.x_m - ref.x_m)) / np.max(np.abs(run.x_m - ref.x_m))
        assert 1.8 < ratio < 2.2
    real = _runs(fidelity, fidelity.Config(0.25, 2.5e-3))
    assert any(np.max(np.abs(r.x_m - ref.x_m)) > b for r, ref, b in zip(real, today, bounds))


def test_the_thermal_chamber_tends_to_the_isothermal_one_as_h_grows(fidelity):
    """One case (3.63 bar, 22.74 N): with the wall's heat transfer h growing by decades the thermal run's
    pressure and contraction approach the isothermal run's as 1/h (the gas lags its wall by its heating
    rate times m c_v / (h A)): a factor 8-12 per decade from 1e3 to 1e5 W/(m^2 K).  The isothermal law at the
    supply's temperature is today's chamber (polytropic with the muscle's index 1), to rounding."""
    case = (53,)
    iso, = _runs(fidelity, fidelity.Config(law="isothermal"), case)
    today, = _runs(fidelity, fidelity.Config(), case)
    assert np.max(np.abs(iso.x_m - today.x_m)) < 1e-9
    p_gaps, x_gaps = [], []
    for h in (1e3, 1e4, 1e5):
        run, = _runs(fidelity, fidelity.Config(law="thermal", h_W_per_m2_K=h), case)
        p_gaps.append(np.max(np.abs(run.p_gauge_Pa - iso.p_gauge_Pa)))
        x_gaps.append(np.max(np.abs(run.x_m - iso.x_m)))
    for gaps in (p_gaps, x_gaps):
        assert all(8 < a / b < 12 for a, b in zip(gaps, gaps[1:])), gaps
    assert p_gaps[-1] < 3e-4 * 3.634e5


def test_native_and_python_give_the_same_rerun(fidelity):
    """The 0.5 m tube and the thermal chamber on three cases: the native backend's rows are the python
    backend's within 1 um of final contraction (the backends' bound on the shipped supply line,
    docs/pneumatics.md), the same rest flags and settling times within a sample (1 ms)."""
    config = fidelity.Config(0.5, 2.5e-3, "thermal")
    py, _ = fidelity.rerun(FRICTION, config, "python", CASES[:3])
    native, _ = fidelity.rerun(FRICTION, config, "native", CASES[:3])
    for a, b in zip(py, native):
        assert abs(a["final_contraction_m"] - b["final_contraction_m"]) < 1e-6
        assert a["at_rest"] == b["at_rest"]
        assert abs(a["settled_time_s"] - b["settled_time_s"]) <= 1e-3 + 1e-12
        assert abs(a["contraction_settled_time_s"] - b["contraction_settled_time_s"]) <= 1e-3 + 1e-12


@pytest.mark.parametrize("args, named", [
    (["--lengths-m", "-1"], "--lengths-m: '-1'"),
    (["--lengths-m", "0.5,abc"], "--lengths-m: '0.5,abc'"),
    (["--diameter-mm", "0"], "--diameter-mm: '0'"),
    (["--h-W-per-m2-K", "-5"], "--h-W-per-m2-K: '-5'"),
    (["--T-wall-K", "nan"], "--T-wall-K: 'nan'"),
    (["--backend", "fmu-cs"], "--backend: invalid choice: 'fmu-cs'"),
    (["--friction", "sticky"], "--friction: invalid choice: 'sticky'"),
])
def test_bad_arguments_exit_2_with_one_line(fidelity, capsys, args, named):
    with pytest.raises(SystemExit) as exc:
        fidelity.main(args)
    assert exc.value.code == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and named in err, err


def test_the_script_exits_2_as_a_process():
    done = subprocess.run([sys.executable, str(SCRIPT), "--lengths-m", "0"], capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stdout == ""
    assert done.stderr == "fidelity_pneumatics.py: error: argument --lengths-m: '0': every length must be a " \
                          "finite number > 0\n"


def test_a_frequency_study_that_replaces_the_lines_valve_is_refused(tmp_path):
    """``[frequency.pressure]`` prescribes the muscle's pressure: the line's supply then has no set pressure to
    read; refused before anything runs, exit 2, nothing written."""
    from conftest import run_main

    sweep = _line_sweep(tmp_path)
    sweep.write_text(sweep.read_text() + '[frequency]\npressure_bar = 3.6\nweight_N = [12.74]\n'
                     '[frequency.pressure]\nsource = "prescribed"\n'
                     'prescribed = { kind = "step", time_s = 1.0, final_gauge_bar = 3.6 }\n')
    done = run_main("sweep", sweep, "-o", tmp_path / "out")
    assert done.returncode == 2
    assert "[frequency.pressure]" in done.stderr and "supply.p_set_gauge_Pa" in done.stderr
    assert done.stderr.count("\n") == 1
    assert not (tmp_path / "out").exists()


def _row(error_mm, within=True, at_rest=True, settled=1.5, x_settled=1.2, ringing_mm=0.0, step=1.2, weight=12.74):
    return {"within_capability": within, "measured_contraction_m": 0.03, "error_m": error_mm * 1e-3,
            "settled_time_s": settled, "contraction_settled_time_s": x_settled, "at_rest": at_rest,
            "last_second_peak_to_peak_m": ringing_mm * 1e-3, "pressure_step_bar": step, "weight_N": weight,
            "final_contraction_m": 0.03 + error_mm * 1e-3}


def test_the_summary_of_a_configuration_by_hand(fidelity):
    """Four cases, three within capability (errors 3, -4 and 0 mm): RMS sqrt(25/3) = 2.887 mm, largest 4 mm,
    mean -1/3 mm; the settling medians over the stuck ones (1.2 and 1.4 s -> 1.3 s, less the valve's 1 s)
    and the ringing one (3.0 s) apart; the case outside capability counts only for rest and ringing."""
    rows = [_row(3.0, x_settled=1.2), _row(-4.0, at_rest=False, x_settled=3.0, ringing_mm=0.5, settled=1.3),
            _row(0.0, x_settled=1.4, step=3.6, weight=22.74, settled=1.1),
            _row(9.0, within=False, at_rest=False, ringing_mm=0.1)]
    today = [dict(r, final_contraction_m=r["final_contraction_m"] + d * 1e-3) for r, d in zip(rows, (1, -2, 0, 0))]
    s = fidelity.summarise(rows, 1.0, today)
    assert s["n_within"] == 3
    assert s["rms_mm"] == pytest.approx(np.sqrt(25 / 3))
    assert s["max_mm"] == pytest.approx(4.0)
    assert s["mean_mm"] == pytest.approx(-1 / 3)
    assert s["pressure_settling_s"] == pytest.approx(0.3)
    assert s["stuck_settling_s"] == pytest.approx(0.3)
    assert s["ringing_settling_s"] == pytest.approx(2.0)
    assert s["figure4_settling_s"] == pytest.approx(0.4)
    assert (s["at_rest"], s["n_cases"]) == (2, 4)
    assert s["ringing_mm"] == pytest.approx(0.3)
    assert s["largest_change_mm"] == pytest.approx(2.0)
