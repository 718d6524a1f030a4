"""
The averaged model of the PWM valve
===================================

``scenarios/pwm_3_2.toml`` drives the Shadow muscle through a 3/2 on/off valve under PWM.  With
``model = "averaged"`` in its ``[pressure.command]`` table the valve runs as the mean of its supply and
exhaust paths' flows over a period, its input the duty.  This compares, on the native backend, the mean
chamber pressure of the switching runs (over the whole periods from 3.5 to 4.5 s, sampled at 50 kHz)
with the averaged runs':

1. the valve switching at once, at 50, 200 and 1000 Hz: the gap shrinks as the frequency rises;
2. a valve that closes later and more slowly than it opens, at 50, 100 and 200 Hz: the averaged model
   with its effective duties against the same model without them;
3. against the duty, with the proportional valve held at command ``2 duty - 1``, which is not the
   averaged valve.
"""

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pamsim  # noqa: E402

base = pamsim.load_scenario("../scenarios/pwm_3_2.toml")
timed = dict(base.spec["pressure"]["command"])
instant = {**timed, "delay_on_s": 0.0, "delay_off_s": 0.0, "rise_s": 0.0, "fall_s": 0.0}


def mean_bar(command: dict, frequency_Hz: float = 50.0, settled: bool = False) -> float:
    """Mean gauge pressure [bar] over the whole periods from 3.5 to 4.5 s of a run with this command (with
    ``settled``: from 8.5 to 9.5 s of a 10 s run, when the gas's slow thermal mode has died out)."""
    t0 = 8.5 if settled else 3.5
    res = pamsim.simulate(base.with_changes({"pressure": {"command": command},
                                             "simulation": {"sample_rate_Hz": 50000.0,
                                                            "duration_s": 10.0 if settled else 5.0}}), backend="native")
    n = round(1.0 * frequency_Hz)
    w = (res.t_s >= t0 - 1e-12) & (res.t_s <= t0 + n / frequency_Hz + 1e-12)
    return float(np.trapezoid(res.p_gauge_Pa[w], res.t_s[w]) / (res.t_s[w][-1] - res.t_s[w][0])) / 1e5


print("1. valve switching at once: |switching - averaged| mean pressure [Pa]")
for duty in (0.3, 0.5, 0.7):
    averaged = mean_bar({**instant, "duty": duty, "model": "averaged"})
    gaps = [abs(mean_bar({**instant, "duty": duty, "frequency_Hz": f}, f) - averaged) * 1e5 for f in (50.0, 200.0, 1000.0)]
    rate = math.log(gaps[1] / gaps[2]) / math.log(1000.0 / 200.0)
    print(f"duty {duty}: averaged {averaged:.4f} bar; gap {gaps[0]:.1f} Pa at 50 Hz, {gaps[1]:.2f} Pa at 200 Hz, "
          f"{gaps[2]:.2f} Pa at 1000 Hz (1/f^{rate:.1f} from 200 to 1000 Hz)")

print("2. a valve that opens after 1 ms in 1 ms and closes after 2 ms in 2 ms, duty 0.5: mean pressure over 8.5-9.5 s [bar]")
late = {**timed, "delay_on_s": 1e-3, "delay_off_s": 2e-3, "rise_s": 1e-3, "fall_s": 2e-3, "end_s": 9.5}
for f in (50.0, 100.0, 200.0):
    switching = mean_bar({**late, "frequency_Hz": f}, f, settled=True)
    with_times = mean_bar({**late, "frequency_Hz": f, "model": "averaged"}, f, settled=True)
    without = mean_bar({**instant, "end_s": 9.5, "frequency_Hz": f, "model": "averaged"}, f, settled=True)
    print(f"{f:g} Hz: switching {switching:.4f}, averaged {with_times:.4f} (gap {abs(with_times - switching) * 1e5:.0f} Pa), "
          f"averaged without the times {without:.4f}")

print("3. against the duty (50 Hz, 2 ms times): mean pressure [bar]")
duties = np.round(np.arange(0.1, 0.91, 0.1), 2)
rows = []
for duty in duties:
    proportional = {"kind": "step", "time_s": timed["start_s"], "initial": 0.0, "final": float(2 * duty - 1)}
    rows.append((mean_bar({**timed, "duty": float(duty)}), mean_bar({**timed, "duty": float(duty), "model": "averaged"}),
                 mean_bar(proportional)))
    print(f"duty {duty:.1f}: switching {rows[-1][0]:.3f}, averaged {rows[-1][1]:.3f}, "
          f"proportional valve at {2 * duty - 1:+.1f}: {rows[-1][2]:.3f}")
rows = np.array(rows)

fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
ax.plot(duties * 100, rows[:, 0], "o", color="C0", label="switching, 50 Hz")
ax.plot(duties * 100, rows[:, 1], "-", color="C1", label="averaged valve")
ax.plot(duties * 100, rows[:, 2], "s--", color="C2", label="proportional valve at 2 duty - 1")
ax.set_xlabel("duty [%]")
ax.set_ylabel("mean gauge pressure, 3.5-4.5 s [bar]")
ax.legend(loc="upper left")
fig.suptitle("pwm_3_2: the averaged valve against switching runs")
fig.savefig("plot_pwm_averaged.png", dpi=110)
