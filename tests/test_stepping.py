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
    """A second of ``pwm_3_2.toml``'s 50 Hz PWM on a 3/2 valve switching at once (100 switches, stick/slip
    between them): python with DOPRI5 against python with LSODA and the native engine (which takes DOPRI5 as
    RK45, and runs it the same)."""
    import pamsim
    from conftest import SCENARIOS

    pwm = pamsim.load_scenario(SCENARIOS / "pwm_3_2.toml")
    command = {**pwm.spec["pressure"]["command"], "start_s": 0.0, "end_s": 1.0, "duty": 0.4,
               "delay_on_s": 0.0, "delay_off_s": 0.0, "rise_s": 0.0, "fall_s": 0.0}

    def scenario(method):
        return pwm.with_changes({"pressure": {"command": command}, "solver": {"method": method},
                                 "simulation": {"duration_s": 1.0, "sample_rate_Hz": 1000.0}})
    dopri = pamsim.simulate(scenario("DOPRI5"))
    lsoda = pamsim.simulate(scenario("LSODA"))
    native = pamsim.simulate(scenario("DOPRI5"), backend="native")
    assert dopri.stats["method"] == "DOPRI5" and dopri.x_m.max() > 5e-3  # the load moves
    assert np.abs(dopri.x_m - lsoda.x_m).max() < 1e-6 and np.abs(dopri.x_m - native.x_m).max() < 1e-6
    assert np.abs(dopri.p_gauge_Pa - native.p_gauge_Pa).max() < 10.0
    assert np.array_equal(native.x_m, pamsim.simulate(scenario("RK45"), backend="native").x_m)


def test_a_slide_from_rest_that_turns_inside_its_first_step_meets_its_stop():
    """From rest the load rises 6.67 um and falls back within 0.3 ms; a stop 5 um up.  DOPRI5 started with one
    0.3 ms step (a held segment's proposal) sees no crossing at the step's ends (v from 0 to -0.15 m/s): the
    step is looked into because it ends moving against its start's acceleration, and the stop is met at its
    analytic time."""
    from scipy.optimize import brentq

    def rise_and_fall(t, y):
        return np.array([y[1], 1e3 - 1e7 * t])

    def stop(t, y):
        return 5e-6 - y[0]
    stop.direction = -1.0
    exact = brentq(lambda t: 500.0 * t ** 2 - 1e7 / 6.0 * t ** 3 - 5e-6, 0.0, 2e-4, xtol=1e-16)
    free = integrate_segment(rise_and_fall, 0.0, 3e-4, np.zeros(2), "DOPRI5", [], np.empty(0), rtol=1e-3,
                             atol=1e-9, max_step=np.inf, v_row=1, first_step=3e-4)
    assert len(free.t) == 2 and (free.y[0] < 5e-6).all()  # one step; its ends show nothing
    seg = integrate_segment(rise_and_fall, 0.0, 3e-4, np.zeros(2), "DOPRI5", [stop], np.empty(0), rtol=1e-3,
                            atol=1e-9, max_step=np.inf, v_row=1, first_step=3e-4)
    assert seg.status == 1 and abs(seg.t_event - exact) < 1e-9


@pytest.mark.parametrize("direction, method", [(1.0, "RK45"), (1.0, "LSODA"), (0.0, "RK45")])
def test_a_long_step_is_looked_into_in_each_events_direction(direction, method):
    """Steps without a longest step (longer than ``LONG_STEP_S``) are looked into, for a crossing in the event's
    own direction only: the oscillator's level -0.1 crossed upwards (or either way) fires where solve_ivp's
    does, the downward crossings before it not (direction +1)."""
    def level(t, y):
        return y[0] + 0.1
    level.terminal, level.direction = True, direction
    ref = solve_ivp(oscillator, (0.0, 3.0), Y0, method=method, events=level, rtol=1e-7, atol=1e-9)
    seg = integrate_segment(oscillator, 0.0, 3.0, Y0, method, [level], np.empty(0), rtol=1e-7, atol=1e-9,
                            max_step=np.inf)
    assert seg.status == 1 == ref.status
    assert abs(seg.t_event - ref.t_events[0][0]) < 1e-9


@pytest.mark.parametrize("n", [1, 2, 3, 5, 9])
def test_dopri5_takes_rk45s_steps_on_random_linear_systems(n):
    """DOPRI5 against scipy's RK45 on damped random linear systems under a sine, at three tolerances: the same
    step times and evaluations (the RMS error norm rounded as scipy rounds it)."""
    from pamsim.stepping import DormandPrince

    rng = np.random.default_rng(n)
    for trial in range(3):
        A = rng.normal(size=(n, n)) - 2.0 * np.eye(n)
        y0 = rng.normal(size=n)

        def f(t, y, A=A):
            return A @ y + np.sin(3.0 * t)
        for rtol in (1e-3, 1e-6, 1e-9):
            ref = solve_ivp(f, (0.0, 5.0), y0, method="RK45", rtol=rtol, atol=1e-9)
            dp = DormandPrince(f, 0.0, y0, 5.0, rtol=rtol, atol=1e-9)
            ts = [0.0]
            while dp.status == "running":
                dp.step()
                ts.append(dp.t)
            assert np.array_equal(ts, ref.t) and dp.nfev == ref.nfev, (trial, rtol)


def test_a_dopri5_segment_of_no_time_reads_its_start():
    """A segment from t to t: no step, the sample at t is the start state, as with scipy's solvers."""
    seg = integrate_segment(oscillator, 1.0, 1.0, Y0, "DOPRI5", [], np.array([1.0]), rtol=1e-6, atol=1e-9,
                            max_step=np.inf)
    ref = integrate_segment(oscillator, 1.0, 1.0, Y0, "RK45", [], np.array([1.0]), rtol=1e-6, atol=1e-9,
                            max_step=np.inf)
    assert seg.status == 0 and np.array_equal(seg.samples_y, ref.samples_y) and np.array_equal(seg.samples_y[:, 0], Y0)


def _dipping_speed(floor: float, center: float = 0.3):
    """A load whose speed is ``(t - center)^2 + floor`` [m/s]: lowest, ``floor``, at ``center``; a falling
    event on the speed, and the start."""
    def f(t, y):
        return np.array([y[1], 2.0 * (t - center)])

    def speed(t, y):
        return y[1]
    speed.direction = -1.0
    return f, speed, np.array([0.0, center ** 2 + floor])


def _one_step(f, events, y0, method):
    """From 0 to 1 s at rtol 1e-2 and atol 1e-6, DOPRI5 starting with one step of 1 s; steps are not looked
    into for their length (``long_step_s`` is infinite).  Dormand-Prince is exact on these quadratics, so
    each step is accepted and ten times longer than the last."""
    return integrate_segment(f, 0.0, 1.0, y0, method, events, np.empty(0), rtol=1e-2, atol=1e-6, max_step=np.inf,
                             v_row=1, first_step=1.0, long_step_s=np.inf)


@pytest.mark.parametrize("method, center, path", [("DOPRI5", 0.3, "parabola"), ("RK45", 0.3, "parabola"),
                                                  ("DOPRI5", 0.5, "midpoint")])
def test_a_speed_that_falls_to_zero_and_back_inside_one_step_fires_where_it_reaches_zero(method, center, path):
    """A speed that falls from 0.08 m/s or more to -0.01 m/s and back inside one step (DOPRI5's step of 1 s,
    RK45's last from 0.14 s): the step's ends show no crossing.  Centred on the step, the midpoint is below
    zero; at 0.3 s the midpoint is above zero and the parabola through the three values finds the dip.
    The event fires at the analytic zero, ``center - 0.1`` (the dense output of a fifth-order step is
    exact on these quadratics)."""
    f, speed, y0 = _dipping_speed(-0.01, center)
    seg = _one_step(f, [speed], y0, method)
    assert seg.status == 1 and abs(seg.t_event - (center - 0.1)) < 1e-9
    f, speed, y0 = _dipping_speed(0.01, center)  # stays above zero: nothing fires
    assert _one_step(f, [speed], y0, method).status == 0


def test_a_dip_below_the_integrations_resolution_is_no_event():
    """The speed dips 1e-9 m/s below zero, a thousandth of its absolute tolerance: no event.  A dip of
    1e-5 m/s fires at its analytic zero, ``0.3 - sqrt(1e-5)`` s."""
    f, speed, y0 = _dipping_speed(-1e-9)
    assert _one_step(f, [speed], y0, "DOPRI5").status == 0
    f, speed, y0 = _dipping_speed(-1e-5)
    seg = _one_step(f, [speed], y0, "DOPRI5")
    assert seg.status == 1 and abs(seg.t_event - (0.3 - 1e-5 ** 0.5)) < 1e-9


@pytest.mark.parametrize("direction", [1.0, 0.0])
def test_a_rising_event_that_dips_from_below_fires(direction):
    """The speed's negative, which rises from -0.08 m/s to +0.01 m/s and back inside the step: an event
    rising through zero (or either way) fires at 0.2 s."""
    f, speed, y0 = _dipping_speed(-0.01)

    def minus_speed(t, y):
        return -y[1]
    minus_speed.direction = direction
    seg = _one_step(f, [minus_speed], y0, "DOPRI5")
    assert seg.status == 1 and abs(seg.t_event - 0.2) < 1e-9


def switched(sign: float):
    """The oscillator under a force of ``sign``: a run switches it at its breakpoints."""
    def f(t, y):
        return np.array([y[1], -40.0 * y[0] - 0.3 * y[1] + sign * 2.0])
    return f


@pytest.mark.parametrize("events", [[], [below(-0.05), speed_zero]], ids=["breakpoints", "breakpoints and events"])
def test_lsoda_restarted_at_each_segment_takes_a_new_solvers_steps(events):
    """A run of segments (the force switching at each breakpoint, two longest steps, one segment of no time)
    with LSODA kept and restarted (:class:`LsodaRestarts`) against a new solver per segment: the same steps,
    samples, events and counts, bit for bit."""
    from pamsim.stepping import LsodaRestarts

    breaks = [0.0, 0.13, 0.4, 0.4, 0.71, 1.2, 1.25, 2.0]
    grid = np.linspace(0.0, 2.0, 2001)

    def run(restarts):
        t, y, out = 0.0, Y0.copy(), []
        for k, t_break in enumerate(breaks[1:]):
            while True:
                seg = integrate_segment(switched((-1.0) ** k), t, t_break, y, "LSODA", events,
                                        grid[(grid >= t) & (grid <= t_break)], rtol=1e-7, atol=1e-9,
                                        max_step=0.05 if k % 2 else np.inf, restarts=restarts)
                out.append(seg)
                t, y = (seg.t_event, seg.y_event + [0.0, 1e-3]) if seg.status == 1 else (t_break, seg.y[:, -1])
                if seg.status != 1:
                    break
        return out

    fresh, kept = run(None), run(LsodaRestarts())
    assert len(fresh) == len(kept) >= len(breaks) - 1
    for a, b in zip(fresh, kept):
        assert np.array_equal(a.t, b.t) and np.array_equal(a.y, b.y)
        assert np.array_equal(a.samples_t, b.samples_t) and np.array_equal(a.samples_y, b.samples_y)
        assert (a.status, a.event, a.t_event, a.nfev, a.njev) == (b.status, b.event, b.t_event, b.nfev, b.njev)
    assert sum(s.status == 1 for s in kept) >= (2 if events else 0)


def test_a_restarted_lsoda_refuses_a_state_that_is_not_finite_as_scipys_does():
    from pamsim.stepping import LsodaRestarts

    restarts = LsodaRestarts()
    integrate_segment(oscillator, 0.0, 0.1, Y0, "LSODA", [], np.empty(0), rtol=1e-7, atol=1e-9, max_step=np.inf,
                      restarts=restarts)
    for kept in (None, restarts):
        with pytest.raises(ValueError, match="must be finite"):
            integrate_segment(oscillator, 0.1, 0.2, np.array([np.nan, 0.0]), "LSODA", [], np.empty(0), rtol=1e-7,
                              atol=1e-9, max_step=np.inf, restarts=kept)


@pytest.mark.parametrize("restarted", [False, True], ids=["new solver", "restarted"])
def test_lsoda_fed_nan_fails_the_segment_where_scipy_carries_on(restarted):
    """scipy's LSODA takes a step whose right-hand side is NaN as a success; the segment fails there."""
    from pamsim.stepping import LsodaRestarts

    def nan_after(t, y):
        return oscillator(t, y) * (np.nan if t > 0.05 else 1.0)

    plain = solve_ivp(nan_after, (0.0, 0.1), Y0, method="LSODA", rtol=1e-7, atol=1e-9)
    assert plain.status == 0 and np.isnan(plain.y[:, -1]).all()  # what the check is for
    seg = integrate_segment(nan_after, 0.0, 0.1, Y0, "LSODA", [], np.linspace(0.0, 0.1, 11), rtol=1e-7, atol=1e-9,
                            max_step=np.inf, restarts=LsodaRestarts() if restarted else None)
    assert seg.status == -1 and "not finite" in seg.message
    assert np.isfinite(seg.y).all() and np.isfinite(seg.samples_y).all() and seg.t[-1] <= 0.05 + 1e-3


def test_an_lsoda_failure_says_odepacks_reason():
    """scipy says "Unexpected istate in LSODA." and warns the reason; the segment's message carries it."""
    with pytest.warns(UserWarning, match="lsoda: Excess accuracy"):
        seg = integrate_segment(lambda t, y: -1e3 * y, 0.0, 1e4, np.array([1.0]), "LSODA", [], np.empty(0),
                                rtol=1e-6, atol=np.array([0.0]), max_step=np.inf)
    assert seg.status == -1
    assert seg.message == "LSODA: Excess accuracy requested (tolerances too small)."


def robertson(t, y):
    """Robertson's stiff kinetics: LSODA switches to BDF and changes its order both ways."""
    return np.array([-0.04 * y[0] + 1e4 * y[1] * y[2], 0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] ** 2,
                     3e7 * y[1] ** 2])


@pytest.mark.parametrize("fun, y0, t_end", [(oscillator, Y0, 3.0), (robertson, np.array([1.0, 0.0, 0.0]), 1e3)],
                         ids=["oscillator (Adams)", "Robertson (BDF)"])
def test_lsodas_dense_output_read_from_its_nordsieck_array_is_scipys(fun, y0, t_end):
    """The segment loop reads LSODA's dense output itself (:class:`_Nordsieck`): at every step, at its ends and
    at random times inside it, one at a time and as an array, the numbers of scipy's own, bit for bit; over
    orders rising and falling, which rescales the array's last column."""
    from scipy.integrate import LSODA

    from pamsim.stepping import _Nordsieck

    rng = np.random.default_rng(7)
    solver = LSODA(fun, 0.0, y0, t_end, rtol=1e-7, atol=1e-10)
    falling = 0
    while solver.status == "running":
        solver.step()
        iwork = solver._lsoda_solver._integrator.iwork
        falling += int(iwork[14] < iwork[13])
        ref, mine = solver.dense_output(), _Nordsieck(solver)
        times = np.concatenate([[solver.t_old, solver.t], rng.uniform(solver.t_old, solver.t, 4)])
        assert np.array_equal(mine(times), ref(times))
        assert all(np.array_equal(mine(float(t)), ref(t)) for t in times)
    assert falling > 0


def test_a_restarted_lsoda_counts_its_own_segments_jacobians_only():
    """A stiff segment (Robertson's, where LSODA forms Jacobians), then one of no time, then another: each
    restarted solver reports the evaluations and Jacobians of its own segment, as a new solver does (a
    segment of no time after a stiff one reported the stiff one's Jacobians when they were not reset)."""
    from pamsim.stepping import LsodaRestarts

    def run(restarts):
        t, y, counts = 0.0, np.array([1.0, 0.0, 0.0]), []
        for t_break in (1.0, 1.0, 10.0):
            seg = integrate_segment(robertson, t, t_break, y, "LSODA", [], np.empty(0), rtol=1e-6, atol=1e-10,
                                    max_step=np.inf, restarts=restarts)
            counts.append((seg.nfev, seg.njev))
            t, y = t_break, seg.y[:, -1]
        return counts

    fresh = run(None)
    assert run(LsodaRestarts()) == fresh
    assert fresh[0][1] > 0 and fresh[1] == (0, 0)
