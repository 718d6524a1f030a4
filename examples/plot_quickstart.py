"""
Simulate and plot
=================

The three-line path of the README: simulate the ACRA 2012 paper's Figure 4 test (3.6 bar supply,
22.74 N load) and plot contraction, pressure and forces.  ``result.plot`` takes the format from the
file's suffix: ``"fig4.pdf"`` or ``"fig4.svg"`` give vector graphics for a paper, and ``dpi=300``
sets the resolution.
"""

import pamsim

result = pamsim.simulate("../scenarios/acra2012_fig4.toml")
result.plot("fig4.png")

# %%
# The result holds every signal of the run (``result.t_s``, ``result.x_m``, ``result.p_gauge_Pa``,
# the forces) and says where the load came to rest and how well the work balances:

summary = result.summary()
print(f"final contraction {1e3 * summary['final_contraction_m']:.2f} mm, "
      f"peak {1e3 * summary['peak_contraction_m']:.2f} mm, final mode {summary['final_mode']}")
print(f"work balance: residual {result.energy_balance()['relative']:.1e} of the muscle's work")

# %%
# The paper gives this test's measured end as numbers (its Tables 1 and 2: the contraction and pressure
# averaged over 6-8 s), not its trace, and the scenario's ``[measured]`` table names them.
# ``pamsim run`` marks them on its figure; in Python, pass them to the plot:

scenario = pamsim.load_scenario("../scenarios/acra2012_fig4.toml")
measured = scenario.measured_steady_state()
result.plot("fig4_measured.png", measured=measured)
print(f"measured final contraction {measured.contraction_mm:.2f} mm ({measured.source}), "
      f"simulated {1e3 * summary['final_contraction_m']:.2f} mm")
