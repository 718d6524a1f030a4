"""
A supply line: supply, reservoir, valve, tube, muscle
=====================================================

``scenarios/supply_chain.toml`` puts the Shadow muscle at the end of a line: an ideal regulated supply at
3.6 bar, 2 m of 4 mm hose into a 0.1 L reservoir, the rig's valve, then 1 m of 4 mm tube into the muscle.
The valve opens at 0.5 s and the muscle lifts Figure 4's 22.74 N weight.

The same test runs three ways: the line as shipped; without the tube (the valve straight into the
muscle, the reservoir still before it); and without the line (the valve on an ideal supply, the rig as
it always was).  The figure draws the pressure drop across each element of the line (from the pressure of
every volume, columns of the run), the muscle's pressure and the contraction.

Then the shipped line again with the hose's and the tube's turbulent law (``resistance = "turbulent"``: the
fill's Reynolds numbers are near 8000), and with the tube in 10 cells whose gas has inertia as well
(``segments = 10``, ``inertia = true``: pressure waves along it at the speed of sound).
"""

import copy
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import pamsim

with open("../scenarios/supply_chain.toml", "rb") as f:
    spec = tomllib.load(f)

no_tube = copy.deepcopy(spec)
del no_tube["pressure"]["outlet_port"]
no_tube["component"] = [c for c in no_tube["component"] if c["name"] != "tube"]
no_line = copy.deepcopy(no_tube)
del no_line["pressure"]["supply_port"]
del no_line["component"]

runs = {"line with the 1 m tube": spec, "line without the tube": no_tube, "ideal supply, no line": no_line}
results = {label: pamsim.simulate(pamsim.Scenario.from_dict(s, base_dir="../scenarios")) for label, s in runs.items()}

fig, (ax_p, ax_m, ax_x) = plt.subplots(3, 1, sharex=True, figsize=(8, 9), constrained_layout=True)
line = results["line with the 1 m tube"]
nodes = [line.signals[f"{name}.p_gauge_Pa"] for name in ("supply", "feed", "reservoir", "tube")] + [line.p_gauge_Pa]
drops = {"feed hose: supply - its bore": (0, 1), "feed hose: its bore - reservoir": (1, 2),
         "valve: reservoir - tube": (2, 3), "tube: its bore - muscle": (3, 4)}
for k, (label, (a, b)) in enumerate(drops.items()):
    ax_p.plot(line.t_s, (nodes[a] - nodes[b]) / 1e3, color=f"C{k}", linestyle=("-", "--", "-.", ":")[k], label=label)
ax_p.set_yscale("symlog", linthresh=0.1)
ax_p.set_title("the line with the tube: the pressure drop across each element")
for k, (label, res) in enumerate(results.items()):
    style = {"color": f"C{k}", "linestyle": ("-", "--", "-.")[k], "label": label}
    ax_m.plot(res.t_s, res.p_gauge_Pa / 1e5, **style)
    ax_x.plot(res.t_s, res.x_m * 1e3, **style)
for ax, label in ((ax_p, "pressure drop [kPa]"), (ax_m, "muscle pressure [bar]"), (ax_x, "contraction [mm]")):
    ax.set(ylabel=label)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
ax_x.set_xlabel("time [s]")
fig.savefig("supply_chain.png", dpi=110)

# %%
# The time the muscle takes, from the valve's opening, to reach 90 % of the supply's pressure; the
# lowest reservoir pressure; the largest contraction and the final one.

for label, res in results.items():
    t90 = res.t_s[np.argmax(res.p_gauge_Pa >= 0.9 * 3.6e5)] - 0.5
    dip = res.signals["reservoir.p_gauge_Pa"].min() / 1e5 if "reservoir.p_gauge_Pa" in res.signals else 3.6
    print(f"{label}: 90 % after {t90 * 1e3:.0f} ms, reservoir down to {dip:.3f} bar, "
          f"peak {res.x_m.max() * 1e3:.2f} mm, final {res.x_m[-1] * 1e3:.2f} mm")
re_tube = line.signals["tube.reynolds_number"].max()
re_feed = line.signals["feed.reynolds_number"].max()
print(f"largest Reynolds number: tube {re_tube:.0f}, feed hose {re_feed:.0f} (laminar below about 2300)")

# %%
# The turbulent law, and the tube's gas's inertia.  Each tube of the line takes the larger of the laminar and
# Blasius drops for its flow; then the muscle's tube is cut into 10 cells with a mass-flow state each.


def tubes(base, **keys):
    out = copy.deepcopy(base)
    for c in out["component"]:
        if c["type"] == "tube" and (c["name"] == "tube" or "segments" not in keys):
            c.update(keys)
    return out


turbulent = tubes(spec, resistance="turbulent")
variants = {"turbulent hose and tube": turbulent,
            "turbulent, the tube in 10 cells with inertia": tubes(turbulent, segments=10, inertia=True)}
for label, s in variants.items():
    res = pamsim.simulate(pamsim.Scenario.from_dict(s, base_dir="../scenarios"))
    sig = res.signals
    t90 = res.t_s[np.argmax(res.p_gauge_Pa >= 0.9 * 3.6e5)] - 0.5
    drop = np.max(sig["tube.p_gauge_Pa"] - res.p_gauge_Pa) / 1e3
    print(f"{label}: 90 % after {t90 * 1e3:.0f} ms, peak {res.x_m.max() * 1e3:.2f} mm, final {res.x_m[-1] * 1e3:.2f} mm, "
          f"largest drop along the tube {drop:.2f} kPa, Reynolds number up to {sig['tube.reynolds_number'].max():.0f}")
drop_laminar = np.max(line.signals["tube.p_gauge_Pa"] - line.p_gauge_Pa) / 1e3
print(f"laminar line: largest drop along the tube {drop_laminar:.2f} kPa")
