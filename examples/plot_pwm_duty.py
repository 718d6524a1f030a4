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
