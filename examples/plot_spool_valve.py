"""
The proportional spool valve, open and in a closed loop
=======================================================

A ``[pressure.spool]`` table makes the rig's valve a 3/3 spool valve of the Festo MPYE class: the command
drives the spool's position through a second-order lag, and each path's ISO 6358 conductance follows the
position.

1. The spool's step response on Figure 4's test (the command steps 0 -> 1 at 1 s), under-, well- and
   overdamped, against the closed form of the second-order lag.
2. A fast, zero-lapped spool without leakage against the proportional valve's run: the gap is the spool's
   delay ``2 zeta / wn`` times the run's fastest rate, so it falls as ``1 / f``.
3. ``scenarios/proportional_valve.toml``: the closed position loop (20 -> 40 mm) through the spool valve and
   1 m of tube, against the same loop through the spool valve alone and through the rig's proportional
   valve (``closed_loop_position.toml``).  The figure draws the spool's steps and the three loops.
4. The design's check on the full linearisation (spool and tube): a spool too slow for the loop is refused.
"""

import copy
import math
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import pamsim
from pamsim.control.closed_loop import design_closed_loop
from pamsim.errors import InputError

fig4 = pamsim.load_scenario("../scenarios/acra2012_fig4.toml")
fig, (ax_s, ax_x) = plt.subplots(2, 1, figsize=(8, 7.5), constrained_layout=True)

print("1. spool step (125 Hz), largest gap from the closed form over 1-1.05 s, python backend")
w = 2 * math.pi * 125.0
for k, zeta in enumerate((0.3, 0.7, 2.0)):
    run = pamsim.simulate(fig4.with_changes({"pressure": {"spool": {"damping_ratio": zeta}},
                                             "simulation": {"duration_s": 1.05, "sample_rate_Hz": 20000.0}}))
    t = run.t_s[run.t_s >= 1.0] - 1.0
    if zeta < 1.0:
        wd = w * math.sqrt(1 - zeta ** 2)
        exact = 1 - np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta * w / wd * np.sin(wd * t))
    else:
        p1, p2 = -zeta * w + w * math.sqrt(zeta ** 2 - 1), -zeta * w - w * math.sqrt(zeta ** 2 - 1)
        exact = 1 - (p2 * np.exp(p1 * t) - p1 * np.exp(p2 * t)) / (p2 - p1)
    spool = run.signals["spool_position"][run.t_s >= 1.0]
    print(f"zeta {zeta}: peak {spool.max():.4f}, gap {np.max(np.abs(spool - exact)):.2e}")
    ax_s.plot(t * 1e3, spool, color=f"C{k}", label=f"run, zeta = {zeta}")
    ax_s.plot(t * 1e3, exact, color="k", linestyle=":", linewidth=1)
ax_s.set_xlabel("time after the command's step [ms]")
ax_s.set_ylabel("spool position [stroke]")
ax_s.set_title("the spool's step (dotted: the second-order lag's closed form)")
ax_s.legend()

print("2. a fast spool (zeta 1, no overlap or leakage) against the proportional valve, Figure 4 over 3 s")
short = fig4.with_changes({"simulation": {"duration_s": 3.0}})
plain = pamsim.simulate(short)
v_max = np.max(np.abs(plain.v_m_s))
for f in (500.0, 2000.0, 20000.0):
    run = pamsim.simulate(short.with_changes({"pressure": {"spool": {"natural_frequency_Hz": f, "damping_ratio": 1.0}}}))
    print(f"{f:7.0f} Hz: contraction gap {np.max(np.abs(run.x_m - plain.x_m)) * 1e3:.4f} mm, "
          f"delay x fastest speed {v_max / (math.pi * f) * 1e3:.4f} mm")

print("3. the closed loop 20 -> 40 mm, native backend")
with open("../scenarios/proportional_valve.toml", "rb") as fh:
    spec = tomllib.load(fh)
no_tube = copy.deepcopy(spec)
del no_tube["pressure"]["outlet_port"], no_tube["component"]
loops = {"spool valve and 1 m tube (proportional_valve.toml)": pamsim.Scenario.from_dict(spec, base_dir="../scenarios"),
         "spool valve, no tube": pamsim.Scenario.from_dict(no_tube, base_dir="../scenarios"),
         "rig's valve, C = 1e-9 (closed_loop_position.toml)": "../scenarios/closed_loop_position.toml"}
for k, (label, scenario) in enumerate(loops.items()):
    run = pamsim.run(scenario, backend="native")
    m = run.closed_loop.metrics
    print(f"{label}: rise {m['rise_time_s'] * 1e3:.1f} ms, overshoot {m['overshoot_percent']:.2f} %, settling "
          f"{m['settling_time_s'] * 1e3:.1f} ms, error {m['steady_state_error_mm']:.3f} mm; meets spec: {not run.failures}")
    ax_x.plot(run.result.t_s, run.result.x_m * 1e3, color=f"C{k}", linestyle=("-", "--", "-.")[k], label=label)
print("4. the design checked on the full linearisation, with slower spools")
for f in (35.0, 30.0):
    slow = pamsim.Scenario.from_dict({**spec, "pressure": {**spec["pressure"], "spool": {"natural_frequency_Hz": f}}},
                                     base_dir="../scenarios")
    try:
        poles = design_closed_loop(slow).design.full_loop_poles
        print(f"{f:.0f} Hz spool: accepted, slowest pole of the full loop {max(poles.real):.3f} 1/s")
    except InputError as exc:
        print(f"{f:.0f} Hz spool: refused: {exc}")
ax_x.set_xlim(0.4, 1.2)
ax_x.set_xlabel("time [s]")
ax_x.set_ylabel("contraction [mm]")
ax_x.set_title("the position loop through each valve")
ax_x.legend()
fig.savefig("spool_valve.png", dpi=110)
