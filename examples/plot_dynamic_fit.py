"""
A dynamic fit
=============

Friction and damping from step responses, as the ACRA 2012 paper (the dynamic force model of a small and
soft McKibben muscle, Australasian Conference on Robotics and Automation, 2012; its authors and title
are not in the text pamsim was built from: full reference in ``docs/model.md``) fitted them (its eq.
13): the five coefficients D1, D2 (damping) and N2, N1, N0 (the load-dependent Coulomb level) chosen to
minimise the squared difference between simulated and recorded contraction, with pamsim's hybrid
stick/slip model inside the fit (``docs/identification.md``).

**The traces are synthetic**: pamsim's own runs of the paper's Figure 4 test (3.6 bar valve step at
1 s) under 12.74, 22.74 and 32.74 N with known coefficients other than the paper's (D1 = -0.5,
D2 = 1.2, N2 = 200, N1 = -80, N0 = 6), 2.5 s long, the pressure recorded, Gaussian noise of 0.05 mm on
the contraction (seeds 0, 1, 2).  The fit starts from the paper's coefficients (its Table 4) and runs
its simulations on the native backend (compiled C); from a shell::

    pamsim fit dynamic trace_12.74N.csv trace_22.74N.csv trace_32.74N.csv \\
        --scenario scenarios/acra2012_fig4.toml --backend native -o fit/
"""

import shutil
import tempfile
from pathlib import Path

import pamsim
from pamsim.identification import fit_dynamic, read_trace
from pamsim.identification.columns import write_trace_csv
from pamsim.identification.report import write_dynamic_fit
from pamsim.identification.synthetic import synthetic_trace

TRUTH = {"D1_N_s_per_m": -0.5, "D2_N_s2_per_m2": 1.2, "N2_N_per_bar_m2": 200.0, "N1_N_per_bar_m": -80.0,
         "N0_N_per_bar": 6.0}
scenario = pamsim.load_scenario("../scenarios/acra2012_fig4.toml")
work = Path(tempfile.mkdtemp(prefix="pamsim_dynamic_fit_"))
files = []
for seed, weight_N in enumerate((12.74, 22.74, 32.74)):
    noisy, _ = synthetic_trace(scenario, TRUTH, weight_N, noise_m=0.05e-3, seed=seed, duration_s=2.5)
    files.append(work / f"trace_{weight_N:g}N.csv")
    write_trace_csv(noisy, files[-1])  # columns t_s, x_m, p_gauge_Pa, weight_N: what a rig records
print(", ".join(f.name for f in files))

# %%
# The fit reads the traces as it would read measured ones, and pools them: several loads separate
# friction from damping, which one trace cannot.

traces = [read_trace(f) for f in files]
fit = fit_dynamic(scenario, traces, backend="native")
write_dynamic_fit(fit, work / "fit")
shutil.copy(work / "fit" / "fit.png", "dynamic_fit.png")
print(f"{fit.n_simulations} simulations, pooled residual RMS {fit.rms_pooled_mm:.4f} mm (the noise: 0.05 mm)")
se = dict(zip(fit.uncertainty.names, fit.uncertainty.standard_errors))
print(f"{'coefficient':<16}{'truth':>9}{'start':>9}{'fitted':>10}{'std. error':>12}")
for (name, value), start in zip(fit.parameters.items(), fit.start):
    print(f"{name:<16}{TRUTH[name]:>9g}{start:>9g}{value:>10.4g}{se[name]:>12.2g}")
for a, b, r in fit.uncertainty.inseparable_pairs():
    print(f"{a} and {b} correlate at r = {r:+.3f}")
shutil.rmtree(work)
