"""
Chamber laws: isothermal, polytropic, thermal
=============================================

``scenarios/thermal_drift.toml`` fills the muscle from a 3.6 bar supply for 0.6 s and then closes the
valve.  The ``[chamber]`` table chooses the law its gas follows; ``Scenario.with_changes`` runs the same
test under each law.  The polytropic law runs here with the adiabatic index 1.4: with the Shadow
muscle's own index (1) and the wall at the supply's temperature it is the isothermal law.

- **isothermal**: the gas stays at the wall's temperature; the pressure holds once the valve closes.
- **polytropic** (n = 1.4): filling heats the gas and nothing cools it; the pressure holds too.
- **thermal**: the energy equation with the wall's heat ``h A(x) (T_wall - T)``; the gas cools after
  the fill, and the pressure drifts down for seconds with the valve closed.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import pamsim

scenario = pamsim.load_scenario("../scenarios/thermal_drift.toml")
runs = {
    "isothermal": scenario.with_changes({"chamber": {"law": "isothermal"}}),
    "polytropic, n = 1.4": scenario.with_changes({"chamber": {"law": "polytropic"},
                                                  "parameters": {"polytropic_index": 1.4}}),
    "thermal, h = 15.7 W/(m^2 K)": scenario,
}
results = {label: pamsim.simulate(sc) for label, sc in runs.items()}

fig, (ax_x, ax_p, ax_T) = plt.subplots(3, 1, sharex=True, figsize=(8, 8), constrained_layout=True)
for k, (label, res) in enumerate(results.items()):
    style = {"color": f"C{k}", "linestyle": ("-", "--", "-.")[k]}
    ax_x.plot(res.t_s, res.x_m * 1e3, label=label, **style)
    ax_p.plot(res.t_s, res.p_gauge_Pa / 1e5, label=label, **style)
    ax_T.plot(res.t_s, res.signals["gas_temperature_K"], label=label, **style)
ax_T.axvspan(0.2, 0.8, color="0.9", label="valve open")
ax_x.set_ylabel("contraction [mm]")
ax_p.set_ylabel("gauge pressure [bar]")
ax_T.set_ylabel("gas temperature [K]")
ax_T.set_xlabel("time [s]")
for ax in (ax_x, ax_p, ax_T):
    ax.grid(alpha=0.3)
ax_T.legend(fontsize=8)
fig.suptitle("thermal_drift: a 0.6 s fill at 3.6 bar, then the valve closed")
fig.savefig("chamber_laws.png", dpi=110)

# %%
# With the valve closed (from 0.8 s) the air mass is fixed: what the pressure does then is the law's.

for label, res in results.items():
    at_close, end = res.p_gauge_Pa[res.t_s.searchsorted(0.8)], res.p_gauge_Pa[-1]
    print(f"{label}: {at_close / 1e5:.3f} bar at the close, {end / 1e5:.3f} bar at 5 s, "
          f"peak gas temperature {res.signals['gas_temperature_K'].max():.1f} K")
