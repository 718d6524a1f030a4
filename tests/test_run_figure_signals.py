"""The run figure's pneumatic signals: a PWM or spool valve's panel, the line components' pressures, no
friction line where hysteresis elements replace the friction, and the hysteresis fit's figures saying what
they fit at a hanging load.  Checked on the matplotlib objects against the run's own signals."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import pamsim
from pamsim import plotting
from pamsim.constants import PA_PER_BAR
from pamsim.hysteresis.loop_data import LoopData
from pamsim.hysteresis.plots import plot_loop, plot_residuals
from pamsim.hysteresis.synthetic import contraction_path
from pamsim.plotting import result_figure

from conftest import SCENARIOS


def _short(name: str, duration_s: float):
    """The scenario ``name`` cut to ``duration_s``."""
    return pamsim.load_scenario(SCENARIOS / f"{name}.toml").with_changes({"simulation": {"duration_s": duration_s}})


def _lines(ax) -> dict:
    """The labelled lines of ``ax`` by label."""
    return {line.get_label(): line for line in ax.get_lines() if not line.get_label().startswith("_")}


def _valve_axes(fig):
    """The valve panel: the axes whose y label is the valve's (the panel under the pressure)."""
    ax = fig.axes[2]
    assert ax.get_ylabel().split("\n")[0].endswith("[-]"), ax.get_ylabel()
    return ax


@pytest.fixture(scope="module")
def pwm_3_2():
    """The 3/2 valve under 50 Hz PWM, over its first five periods (the PWM starts at 0.5 s)."""
    return pamsim.simulate(_short("pwm_3_2", 0.6))


def test_a_pwm_valves_command_gets_a_small_panel_under_the_pressure(pwm_3_2):
    res = pwm_3_2
    fig = result_figure(res)
    assert len(fig.axes) == 4
    assert "pressure" in fig.axes[1].get_ylabel() and "force" in fig.axes[-1].get_ylabel()
    ax = _valve_axes(fig)
    (label, line), = _lines(ax).items()
    assert "PWM 50 Hz, duty 0.5" in label
    assert np.array_equal(line.get_xdata(), res.t_s)
    assert np.array_equal(line.get_ydata(), res.signals["valve_command"])
    assert set(np.unique(res.signals["valve_command"])) >= {-1.0, 1.0}  # it does switch in the window
    assert ax.get_position().height < 0.6 * fig.axes[1].get_position().height


def test_a_valve_pairs_panel_draws_each_valves_opening():
    res = pamsim.simulate(_short("pwm_onoff", 0.6))
    lines = _lines(_valve_axes(result_figure(res)))
    assert list(lines) == ["inlet (PWM 50 Hz, duty 0.5)", "exhaust (PWM 50 Hz, duty 0.5, inverted)"]
    assert np.array_equal(lines["inlet (PWM 50 Hz, duty 0.5)"].get_ydata(), res.signals["valve_command"])
    assert np.array_equal(lines["exhaust (PWM 50 Hz, duty 0.5, inverted)"].get_ydata(), res.signals["exhaust_command"])


def test_the_averaged_pwm_valves_panel_draws_its_duty():
    res = pamsim.simulate(_short("pwm_3_2", 0.6).with_pwm_averaged())
    ax = _valve_axes(result_figure(res))
    (label, line), = _lines(ax).items()
    assert "duty" in ax.get_ylabel() and "duty" in label
    assert np.array_equal(line.get_ydata(), res.signals["valve_command"])
    assert np.max(line.get_ydata()) == 0.5


def test_a_spool_valves_command_and_position_and_its_tubes_pressure_are_drawn():
    run = pamsim.run(_short("proportional_valve", 0.7))
    res = run.result
    fig = result_figure(res)
    assert len(fig.axes) == 4
    ax = _valve_axes(fig)
    assert "spool" in ax.get_ylabel()
    lines = _lines(ax)
    assert list(lines) == ["command", "position"]
    assert np.array_equal(lines["command"].get_ydata(), res.signals["valve_command"])
    assert np.array_equal(lines["position"].get_ydata(), res.signals["spool_position"])
    assert np.ptp(res.signals["spool_position"]) > 0.5  # the controller moves it in the window
    pressures = _lines(fig.axes[1])
    assert list(pressures) == ["muscle", "supply", "tube"]
    assert np.array_equal(pressures["tube"].get_ydata(), res.signals["tube.p_gauge_Pa"] / PA_PER_BAR)
    # The run's own figure is the closed loop's: it draws the tube and the spool too.
    loop_fig = run.figure()
    pressures = _lines(loop_fig.axes[1])
    assert list(pressures) == ["chamber", "holding pressure (feedforward)", "tube"]
    assert np.array_equal(pressures["tube"].get_ydata(), res.signals["tube.p_gauge_Pa"] / 1e5)
    valve = _lines(loop_fig.axes[2])
    assert list(valve) == ["command", "spool position"]
    assert np.array_equal(valve["spool position"].get_ydata(), res.signals["spool_position"])


def test_each_line_components_pressure_is_drawn_in_bar_gauge_under_its_name():
    res = pamsim.simulate(_short("supply_chain", 0.8))
    fig = result_figure(res)
    assert len(fig.axes) == 3  # the valve's command is a step: no valve panel
    lines = _lines(fig.axes[1])
    # The regulator is named "supply", as the rig's supply line is already labelled.
    assert list(lines) == ["muscle", "supply", "supply (component)", "feed", "reservoir", "tube"]
    for name in ("feed", "reservoir", "tube"):
        assert np.array_equal(lines[name].get_ydata(), res.signals[f"{name}.p_gauge_Pa"] / PA_PER_BAR), name
    assert np.array_equal(lines["supply (component)"].get_ydata(), res.signals["supply.p_gauge_Pa"] / PA_PER_BAR)
    styles = [(line.get_linestyle(), line.get_marker()) for line in lines.values()]
    assert len(set(styles)) == len(styles)  # told apart in grey too


def test_only_a_components_own_gauge_pressure_is_a_line_pressure():
    """``NAME.p_gauge_Pa`` of each component, not the muscle's own column, another quantity of the component
    (``tube.outlet_p_gauge_Pa``) or its absolute pressure."""
    signals = {"vessel.p_abs_Pa": np.array([150e3, 250e3]), "tube.p_gauge_Pa": np.array([1.0, 2.0]),
               "tube.p_abs_Pa": np.zeros(2), "tube.outlet_p_gauge_Pa": np.zeros(2), "p_gauge_Pa": np.zeros(2)}
    found = plotting.line_pressures(SimpleNamespace(signals=signals))
    assert list(found) == ["tube"]
    assert np.array_equal(found["tube"], signals["tube.p_gauge_Pa"])


EXPECTED_PLAIN = {  # counted on the figures before the valve panel and the line pressures were added
    "acra2012_fig4": [["acra2012_fig4"], ["muscle", "supply"],
                      ["static", "gravity", "friction", "damping", "stop contact", "_child5"]],
    "thermal_drift": [["thermal_drift"], ["muscle", "supply"], ["gas", "wall"],
                      ["static", "gravity", "friction", "damping", "stop contact", "_child5"]],
}


@pytest.mark.parametrize("name", EXPECTED_PLAIN)
def test_a_run_without_these_signals_draws_the_figure_it_drew_before(name):
    res = pamsim.simulate(pamsim.load_scenario(SCENARIOS / f"{name}.toml"))
    fig = result_figure(res)
    assert [[line.get_label() for line in ax.get_lines()] for ax in fig.axes] == EXPECTED_PLAIN[name]
    assert list(fig.get_size_inches()) == [9.0, 11.0 if name == "thermal_drift" else 9.0]


def test_hysteresis_elements_replace_the_friction_line():
    """The elements replace the Coulomb friction: its level is zero, and F_friction_N is nonzero only where the
    load sticks, where it holds a residual of micronewtons; the figure leaves it out."""
    res = pamsim.simulate(_short("hysteresis_loops", 2.0))
    friction = res.signals["F_friction_N"]
    assert np.any(friction != 0.0) and np.max(np.abs(friction)) < 1e-3
    assert np.all(friction[res.mode != 0] == 0.0) and np.all(res.signals["F_coulomb_level_N"] == 0.0)
    forces = _lines(result_figure(res).axes[2])
    assert "friction" not in forces and "hysteresis" in forces and "static" in forces


def _fake_fit(hanging: bool):
    """A fit's figure inputs without fitting: a loop (at a hanging load: with its friction law's level) and
    one model's fitted force."""
    t, x = contraction_path()
    pull = 2.0 * np.sign(np.gradient(x)) + 100.0 * x
    level = np.full(x.size, 3.0) if hanging else None
    data = LoopData(t, np.full(x.size, 3e5), x, pull, "<test>", level_N=level)
    model = SimpleNamespace(label="maxwell_slip N=1", force_N=pull * 0.9, residual_N=pull * 0.1, rms_N=0.1)
    return SimpleNamespace(data=data, models={"maxwell_slip": model}, chosen=model)


@pytest.mark.parametrize("hanging, quantity", [(True, "W - F_static"), (False, "force")])
def test_the_fit_figures_say_what_they_fit(hanging, quantity):
    fit = _fake_fit(hanging)
    assert plot_loop(fit).axes[0].get_ylabel() == f"{quantity} [N]"
    residual = "residual [N]" if quantity == "force" else f"residual of {quantity} [N]"
    assert [ax.get_ylabel() for ax in plot_residuals(fit).axes] == [residual] * 2
