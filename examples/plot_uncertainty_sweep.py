"""
A sweep with uncertainty
========================

How far the Figure 4 test (3.6 bar supply step, 22.74 N) of the ACRA 2012 paper (the dynamic force model
of a small and soft McKibben muscle, Australasian Conference on Robotics and Automation, 2012; its
authors and title are not in the text pamsim was built from: full reference in ``docs/model.md``) moves
when the valve and the friction are not known exactly. The shipped study
``scenarios/acra2012_fig4_uncertainty.toml`` varies the valve's sonic conductance C and the three
coefficients of the load-dependent Coulomb friction level (N2, N1, N0) by +-10 % about their values,
uniformly, in a Latin hypercube of 10,000 samples (``pamsim sweep
scenarios/acra2012_fig4_uncertainty.toml -o out/fig4_uq``). The +-10 % is assumed: the paper gives no
uncertainty for its coefficients, and C is itself assumed (``docs/scaling.md``).

Here the same study runs with 200 samples on the native backend (compiled C), under the load-dependent
friction and, for comparison, the constant 2.5 N friction that paper took from Chou and Hannaford
(1996).
"""

import shutil
import tempfile
import tomllib
from pathlib import Path

import pamsim

study = tomllib.loads(Path("../scenarios/acra2012_fig4_uncertainty.toml").read_text())
study["uncertainty"]["samples"] = 200
study["friction_models"] = ["load_dependent", "constant"]
study["backend"] = "native"
spec = pamsim.sweep.sweep_from_dict(study, base_dir="../scenarios", origin="acra2012_fig4_uncertainty (200 samples)")
for dist in spec.uncertainty.parameters:
    print(f"{dist.name}: {dist.describe()}")

# %%
# Run every sample under both friction models, in this process (``pamsim.sweep(spec, executor)`` takes a
# process pool or a Dask cluster's executor for large studies), and write the tables and figures.

result = pamsim.sweep(spec)
out = Path(tempfile.mkdtemp(prefix="pamsim_uq_"))
result.write(out)
for name in ("uncertainty_histograms.png", "uncertainty_ecdf.png"):
    shutil.copy(out / name, name)
models = result.uncertainty.friction_models
print(f"{len(models) * spec.uncertainty.samples} runs, {sum(map(result.uncertainty.failed, models))} failed")

# %%
# The quantiles of each quantity (``uncertainty_summary.csv``; contractions in mm, times in s):

levels = spec.uncertainty.quantiles
print(f"{'friction':>15} {'quantity':<26}" + "".join(f"{f'q{p:g}':>9}" for p in levels))
for row in result.uncertainty.quantile_rows():
    in_mm = row["quantity"].endswith("_m")
    quantity = row["quantity"][:-2] + (" [mm]" if in_mm else " [s]")
    print(f"{row['friction_model']:>15} {quantity:<26}"
          + "".join(f"{row[f'q{p:g}'] * (1e3 if in_mm else 1.0):9.3f}" for p in levels))
shutil.rmtree(out)
