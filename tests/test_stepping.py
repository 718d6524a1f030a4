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
