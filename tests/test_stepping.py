"""The segment loop against ``scipy.integrate.solve_ivp``, a second implementation of the same rule: the
same steps, events and samples, number for number."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pamsim.stepping import integrate_segment


def oscillator(t, y):
    """A lightly damped oscillator under a force that ramps up: its level crossings are events."""
    return np.array([y[1], -40.0 * y[0] - 0.3 * y[1] + 2.0 * t])


def below(level: float):
    def g(t, y):
        return y[0] - level
    g.terminal, g.direction = True, -1.0
    return g


def speed_zero(t, y):
    return y[1]


speed_zero.terminal, speed_zero.direction = True, 0.0

Y0 = np.array([0.2, 0.0])


@pytest.mark.parametrize("method", ["LSODA", "RK45", "DOP853", "BDF", "Radau"])
@pytest.mark.parametrize("events", [[], [below(-0.1)], [below(-0.5), below(-0.1), speed_zero]],
                         ids=["no event", "one event", "three events"])
def test_a_segment_takes_solve_ivps_steps_events_and_samples(method, events):
    t_end = 3.0
    ref = solve_ivp(oscillator, (0.0, t_end), Y0, method=method, dense_output=True, events=events or None,
                    rtol=1e-7, atol=1e-9, max_step=0.05)
    # a 1 kHz grid with the step ends added: a sample on a boundary is read from the step solve_ivp reads it from
    samples = np.unique(np.concatenate([np.linspace(0.0, t_end, 3001), ref.t]))
    seg = integrate_segment(oscillator, 0.0, t_end, Y0, method, events, samples, rtol=1e-7, atol=1e-9,
                            max_step=0.05)
    assert seg.status == ref.status
    assert np.array_equal(seg.t, ref.t) and np.array_equal(seg.y, ref.y)
    assert seg.nfev == ref.nfev
    read = samples[samples <= ref.t[-1]]
    assert np.array_equal(seg.samples_t, read)
    assert np.array_equal(seg.samples_y, ref.sol(read))
    if events:
        fired = [k for k, te in enumerate(ref.t_events) if len(te)]
        assert fired == [seg.event]
        assert seg.t_event == ref.t_events[seg.event][0]
        assert np.array_equal(seg.y_event, ref.y_events[seg.event][0])


def test_the_first_of_two_events_in_one_step_fires():
    """Two levels crossed within one long step: the earlier root fires, whichever event comes first in the list."""
    events = [below(-0.15), below(-0.1)]
    for order in (events, events[::-1]):
        seg = integrate_segment(oscillator, 0.0, 3.0, Y0, "RK45", order, np.empty(0), rtol=1e-3, atol=1e-3,
                                max_step=1.0)
        assert order[seg.event] is events[1]
        assert abs(seg.y_event[0] + 0.1) < 1e-9


def test_dopri5_takes_rk45s_steps():
    """pamsim's Dormand-Prince against scipy's RK45, the same formulas and step control: the same step times
    and evaluations, states and dense output within rounding."""
    from pamsim.stepping import DormandPrince

    ref = solve_ivp(oscillator, (0.0, 3.0), Y0, method="RK45", rtol=1e-7, atol=1e-9, max_step=0.05, dense_output=True)
    dp = DormandPrince(oscillator, 0.0, Y0, 3.0, rtol=1e-7, atol=1e-9, max_step=0.05)
    ts, ys, dense = [0.0], [Y0], []
    while dp.status == "running":
        assert dp.step() is None
        ts.append(dp.t)
        ys.append(dp.y)
        dense.append(dp.dense_output())
    assert np.array_equal(ts, ref.t) and dp.nfev == ref.nfev
    np.testing.assert_allclose(np.array(ys).T, ref.y, rtol=1e-14, atol=1e-16)
    for k in (0, len(dense) // 2, len(dense) - 1):
        inside = np.linspace(ts[k], ts[k + 1], 7)
        np.testing.assert_allclose(dense[k](inside), ref.sol(inside), rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(dense[k](inside[3]), ref.sol(inside[3]), rtol=1e-13, atol=1e-15)


def test_dopri5_carried_across_switches_meets_the_analytic_solution():
    """A first-order lag under a square wave of 50 Hz switched 100 times, segment by segment, each starting
    from the last one's proposed step (or afresh): against the solution written out switch by switch."""
    tau, period, duty = 5e-3, 0.02, 0.4
    switches = np.sort(np.concatenate([np.arange(0, 1, period) + duty * period, np.arange(period, 1 + 1e-12, period)]))

    def run(carry: bool) -> None:
        t, y, h, x_exact = 0.0, np.array([0.0]), None, 0.0
        for k, t_next in enumerate(switches):
            level = 1.0 if k % 2 == 0 else 0.0
            seg = integrate_segment(lambda t, y: np.array([(level - y[0]) / tau]), t, t_next, y, "DOPRI5", [],
                                    np.array([t_next]), rtol=1e-8, atol=1e-10, max_step=np.inf,
                                    first_step=h if carry else None)
            x_exact = level + (x_exact - level) * np.exp(-(t_next - t) / tau)
            assert abs(seg.samples_y[0, 0] - x_exact) < 1e-7
            t, y, h = t_next, seg.y[:, -1], seg.h_next
            assert 0.0 < h < np.inf
    run(carry=True)
    run(carry=False)


def test_a_pwm_run_with_dopri5_meets_lsoda_and_the_native_engine():
    """A second of 50 Hz PWM on a 3/2 valve (100 switches, stick/slip between them): python with DOPRI5
    against python with LSODA and the native engine (which takes DOPRI5 as RK45, and runs it the same)."""
    import pamsim

    def scenario(method):
        return pamsim.Scenario.from_dict({
            "name": "pwm", "model": {"parameter_set": "shadow_6x300_acra2012"}, "load": {"weight_N": 22.74},
            "pressure": {"source": "valve", "supply_gauge_bar": 3.6,
                         "command": {"kind": "pwm", "start_s": 0.0, "end_s": 1.0, "frequency_Hz": 50.0, "duty": 0.4,
                                     "low": -1.0, "high": 1.0}},
            "simulation": {"duration_s": 1.0, "sample_rate_Hz": 1000.0}, "solver": {"method": method, "rtol": 1e-6}})
    dopri = pamsim.simulate(scenario("DOPRI5"))
    lsoda = pamsim.simulate(scenario("LSODA"))
    native = pamsim.simulate(scenario("DOPRI5"), backend="native")
    assert dopri.stats["method"] == "DOPRI5" and dopri.x_m.max() > 5e-3  # the load moves
    assert np.abs(dopri.x_m - lsoda.x_m).max() < 1e-6 and np.abs(dopri.x_m - native.x_m).max() < 1e-6
    assert np.abs(dopri.p_gauge_Pa - native.p_gauge_Pa).max() < 10.0
    assert np.array_equal(native.x_m, pamsim.simulate(scenario("RK45"), backend="native").x_m)
