"""
Position and ripple against the PWM duty
========================================

``scenarios/pwm_onoff.toml`` runs the Shadow muscle with its 22.74 N weight on two 2/2 on/off valves, an
inlet under 50 Hz PWM and an exhaust driven complementary, each with its own ISO 6358 (C, b), delays and
switching times.  This sweeps the inlet's duty from 10 to 90 % on the native backend and measures, over
the last second of the modulation (3.5 to 4.5 s), the mean contraction and pressure and their ripple (peak
to peak): the duty sets the mean, as a proportional valve's opening would, and the ripple is the price of
switching.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pamsim  # noqa: E402

base = pamsim.load_scenario("../scenarios/pwm_onoff.toml")
duties = np.round(np.arange(0.1, 0.91, 0.1), 2)
rows = []
for duty in duties:
    inlet = base.spec["pressure"]["inlet"]
    res = pamsim.simulate(base.with_changes({"pressure": {"inlet": {**inlet, "command": {**inlet["command"],
                                                                                       "duty": float(duty)}}}}),
                          backend="native")
    window = (res.t_s >= 3.5) & (res.t_s <= 4.5)
    x_mm, p_bar = res.x_m[window] * 1e3, res.p_gauge_Pa[window] / 1e5
    rows.append((duty, x_mm.mean(), np.ptp(x_mm), p_bar.mean(), np.ptp(p_bar)))
    print(f"duty {duty:.1f}: contraction {x_mm.mean():6.2f} mm, ripple {np.ptp(x_mm):.3f} mm; "
          f"pressure {p_bar.mean():.3f} bar, ripple {np.ptp(p_bar):.3f} bar")
rows = np.array(rows)

fig, (ax_x, ax_p) = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True, layout="constrained")
for ax, mean, ripple, label in ((ax_x, rows[:, 1], rows[:, 2], "contraction [mm]"),
                                (ax_p, rows[:, 3], rows[:, 4], "gauge pressure [bar]")):
    ax.fill_between(rows[:, 0] * 100, mean - ripple / 2, mean + ripple / 2, color="C0", alpha=0.3,
                    label="ripple (peak to peak)")
    ax.plot(rows[:, 0] * 100, mean, "o-", color="C0", label="mean, 3.5-4.5 s")
    ax.set_ylabel(label)
    ax.legend(loc="upper left")
ax_p.set_xlabel("duty [%]")
fig.suptitle("pwm_onoff: two 2/2 on/off valves at 50 Hz (exhaust complementary), 22.74 N weight")
fig.savefig("plot_pwm_duty.png", dpi=110)

# %%
# The averaged model of the pair (``model = "averaged"``: each valve's share of a period from its own trace)
# against switching runs of the same valves switching at once, whose mean pressure over whole periods of
# 7.5-8 s (settled: the small valves take seconds) tends to it as the frequency rises.


def mean_gauge_bar(scenario, frequency_Hz, t0=7.5, t1=8.0):
    res = pamsim.simulate(scenario, backend="native")
    n = round((t1 - t0) * frequency_Hz)
    w = (res.t_s >= t0 - 1e-12) & (res.t_s <= t0 + n / frequency_Hz + 1e-12)
    return float(np.trapezoid(res.p_gauge_Pa[w], res.t_s[w]) / (res.t_s[w][-1] - res.t_s[w][0])) / 1e5


at_once = {"delay_on_s": 0.0, "delay_off_s": 0.0, "rise_s": 0.0, "fall_s": 0.0}
pressure = base.spec["pressure"]


def pair(frequency_Hz, model):
    command = {**pressure["inlet"]["command"], "frequency_Hz": frequency_Hz, "model": model, "end_s": 8.5}
    inlet = {**pressure["inlet"], **at_once, "command": command}
    return base.with_changes({"pressure": {"inlet": inlet, "exhaust": {**pressure["exhaust"], **at_once}},
                              "simulation": {"sample_rate_Hz": 50000.0, "duration_s": 8.0}})


averaged = mean_gauge_bar(pair(50.0, "averaged"), 50.0)
gaps = [abs(mean_gauge_bar(pair(f, "switching"), f) - averaged) * 1e5 for f in (50.0, 200.0, 1000.0)]
print(f"valves switching at once, duty 0.5: averaged {averaged:.4f} bar; |switching - averaged| mean pressure "
      f"{gaps[0]:.1f} Pa at 50 Hz, {gaps[1]:.2f} Pa at 200 Hz, {gaps[2]:.3f} Pa at 1000 Hz")
