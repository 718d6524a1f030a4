"""
Your own muscle, end to end
===========================

A muscle of your own, from its file to an FMU: the path of the README's "Your own muscle", in Python.

1. the muscle file (the README's home-made 10 mm muscle, with an assumed friction);
2. the atlas of every static model whose parameters the file gives;
3. a static fit of the muscle's model to static tests read from a CSV file;
4. a step run of the fitted muscle;
5. its linearisation at the end of the step;
6. an FMU built for that step run, simulated by plain ``fmpy.simulate_fmu``, compared with the Python run.

**The static tests are synthetic**: no rig measured them.  They are the equilibrium contractions of the
muscle file's own static model (Chou and Hannaford's) under hung weights, with Gaussian noise of
0.2 mm drawn from a fixed seed, so the fit should find the file's values back within its standard errors.
Everything is written into a temporary folder; the figures shown are copied beside this script.
Each step names the command that does the same from a shell.

Chou and Hannaford's model (1996) is pamsim's ``chou_hannaford``, as K. P. Ashwin and A. Ghosal give it
(eq. 5 of "A Survey on Static Modeling of Miniaturized Pneumatic Artificial Muscles with New Model and
Experimental Results", Applied Mechanics Reviews 70(4), 2018).
"""

import shutil
import tempfile
from pathlib import Path

import fmpy
import numpy as np

import pamsim
import pamsim.fmu
from pamsim.atlas import build_atlas
from pamsim.control import linearize, open_valve_equilibrium
from pamsim.fmu.preset import for_scenario
from pamsim.identification import fit_static, read_static_data
from pamsim.identification.report import write_static_fit
from pamsim.static import static_report

work = Path(tempfile.mkdtemp(prefix="pamsim_own_muscle_"))

# %%
# 1. The muscle file
# ------------------
# Every value carries its unit in its name and its source.  The README's example muscle gives the
# geometry that the braid models need; this one adds a constant Coulomb friction of 1.5 N, *assumed*
# (without it the file's friction is pamsim's default, zero, and the load would ring for seconds).

muscle_file = work / "my_muscle.toml"
muscle_file.write_text('''
name = "my_muscle"
description = "home-made 10 mm muscle, latex tube in a PET sleeve"
citation = "own measurements, 2026"
default_static_force = "chou_hannaford"
rated_pressure_gauge_Pa = 5e5

[parameters.L0_m]
value = 0.15
source = "measured with a ruler"
[parameters.r0_m]
value = 0.005
source = "sleeve diameter 10 mm, measured"
[parameters.wall_thickness_m]
value = 0.001
source = "tube datasheet"
[parameters.theta0_deg]
value = 25.0
source = "measured from the sleeve's pitch"
[parameters.coulomb_constant_N]
value = 1.5
source = "assumed for this example"
''')
muscle = pamsim.load_muscle(muscle_file)
print(f"{muscle.name}: default model {muscle.default_static_force}; "
      f"models that apply: {', '.join(muscle.applicable_models())}")

# %%
# 2. The atlas (``pamsim atlas --muscle my_muscle.toml -o atlas/``)
# -----------------------------------------------------------------
# Every applicable model's force against contraction at four pressures up to the rating.  Gaylord's
# model and the three that reduce to it at their default corrections give one curve: one line, one
# legend entry.

atlas = build_atlas(str(muscle_file))
atlas.write(work / "atlas")
shutil.copy(work / "atlas" / "atlas_all.png", "own_muscle_atlas.png")
for group in atlas.groups:
    blocked = [c.blocked_force_N for c in atlas.curves if c.model == group[0]]
    print(f"{' = '.join(group)}: blocked force {blocked[0]:.1f} N at {atlas.pressures_Pa[0] / 1e5:g} bar, "
          f"{blocked[-1]:.1f} N at {atlas.pressures_Pa[-1] / 1e5:g} bar")

# %%
# 3. A static fit from a CSV file (``pamsim fit static tests.csv --muscle my_muscle.toml -o fit/``)
# -------------------------------------------------------------------------------------------------
# The CSV file a rig would give: gauge pressure, contraction and hung weight, with units in the column
# names.  Its rows here are synthetic (see the top of the page): the equilibrium that ``pamsim static``
# computes for each pressure and weight, plus noise.

params = pamsim.get_parameter_set(str(muscle_file))  # the file's values and the dynamics' defaults
model = muscle.static_force()
rng = np.random.default_rng(2026)
rows = []
for p_bar in (1.0, 2.0, 3.0, 4.0, 5.0):
    for weight_N in (20.0, 40.0, 80.0, 120.0):
        x_m = static_report(params, model, p_bar * 1e5, weight_N)["equilibrium_contraction_m"]
        if x_m > 0.0:  # lifted; a load left on the lower stop reads 0 without noise
            x_m += rng.normal(0.0, 0.2e-3)
        rows.append(f"{p_bar:g},{x_m * 1e3:.3f},{weight_N:g}")
csv = work / "tests.csv"
csv.write_text("# synthetic static tests: the equilibria of my_muscle.toml's own model (chou_hannaford),\n"
               "# plus Gaussian noise of 0.2 mm (numpy default_rng(2026)); not measured\n"
               "pressure_bar,contraction_mm,weight_N\n" + "\n".join(rows) + "\n")

fit = fit_static(read_static_data(csv), muscle.parameters, model=muscle.default_static_force)
write_static_fit(fit, work / "fit")
shutil.copy(work / "fit" / "fit.png", "own_muscle_fit.png")
print(f"{fit.n_points} tests ({fit.n_censored} not lifted), RMS {fit.rms_contraction_mm:.3f} mm, "
      f"leave-one-out {fit.cv_rms_contraction_mm:.3f} mm")
for name, value in fit.parameters.items():
    se = fit.uncertainty.standard_errors[fit.uncertainty.names.index(name)]
    print(f"  {name}: {value:.5g} +- {se:.2g} (file: {muscle.parameters[name]:.5g})")
for a, b, r in fit.uncertainty.inseparable_pairs():
    print(f"  {a} and {b} correlate at r = {r:+.3f}: the data do not separate them")

# %%
# The fit wrote ``fit/muscle.toml``: the muscle with the fitted values and their provenance, and a copy
# of the tests beside it.  It is a muscle file like any other.

fitted_file = work / "fit" / "muscle.toml"
fitted = pamsim.load_muscle(fitted_file)
source = fitted.parameters.entries["r0_m"].source
print(f"{fitted.name}: r0_m = {fitted.parameters['r0_m']:.5g} m, {source.split(' on ')[0]}")

# %%
# 4. A step run of the fitted muscle (``pamsim run my_step.toml -o out/``)
# ------------------------------------------------------------------------
# 3 bar from 0.2 s on, 40 N hanging, constant Coulomb friction (the file's 1.5 N).

scenario = pamsim.Scenario.from_dict({
    "name": "my_step",
    "model": {"muscle": str(fitted_file), "friction": "constant"},
    "load": {"weight_N": 40.0},
    "pressure": {"source": "valve", "supply_gauge_bar": 3.0, "valve_open_time_s": 0.2},
    "simulation": {"duration_s": 2.0},
})
result = pamsim.simulate(scenario)
result.plot("own_muscle_step.png")
s = result.summary()
print(f"final contraction {s['final_contraction_m'] * 1e3:.2f} mm, peak {s['peak_contraction_m'] * 1e3:.2f} mm, "
      f"final mode {s['final_mode']}")

# %%
# 5. Linearised at the end of the step (``pamsim linearize my_step.toml``)
# ------------------------------------------------------------------------
# The valve open, the chamber at the 3 bar supply, the load at rest where the static force holds it;
# Coulomb friction dropped (it has no linearisation at rest).

op = open_valve_equilibrium(scenario.build_model(), scenario.final_pressure_gauge_Pa)
lin = linearize(scenario.build_model(), op)
mode = lin.mechanical_mode()
print(op.description)
print(f"mechanical mode: {mode.omega_n_rad_s / (2 * np.pi):.2f} Hz, damping ratio {mode.damping_ratio:.4f}")

# %%
# 6. The FMU of the step run, in fmpy (``pamsim fmu build --scenario my_step.toml -o my_step.fmu``)
# -------------------------------------------------------------------------------------------------
# Built for the scenario, the FMU starts with its muscle, its load and its valve step, so plain
# ``fmpy.simulate_fmu`` with nothing set runs the same test.  Chou and Hannaford's model is baked into
# it as a force table (bicubic), the rest is the same model in C.

fmu = pamsim.fmu.build(work / "my_step.fmu", preset=for_scenario(scenario))
fmu_run = fmpy.simulate_fmu(str(fmu))
x_fmu_m = np.interp(result.t_s, fmu_run["time"], fmu_run["contraction_m"])
difference_mm = (x_fmu_m - result.x_m) * 1e3
print(f"FMU against Python: largest contraction difference {np.max(np.abs(difference_mm)):.2e} mm; "
      f"final {fmu_run['contraction_m'][-1] * 1e3:.4f} mm against {result.x_m[-1] * 1e3:.4f} mm")

# %%
# The two runs, and their difference.

from matplotlib.figure import Figure  # noqa: E402

from pamsim.figure_style import save, series  # noqa: E402

fig = Figure(figsize=(8, 5.5), constrained_layout=True)
ax_x, ax_d = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2, 1]})
ax_x.plot(result.t_s, result.x_m * 1e3, label="pamsim.simulate (Python)", **series(0))
ax_x.plot(fmu_run["time"], fmu_run["contraction_m"] * 1e3, label="fmpy.simulate_fmu (the FMU)", **series(1))
ax_x.set_ylabel("contraction [mm]")
ax_x.legend()
ax_d.plot(result.t_s, difference_mm * 1e3, lw=0.5, **series(0, "k"))
ax_d.set_ylabel("FMU - Python [um]")
ax_d.set_xlabel("time [s]")
for ax in (ax_x, ax_d):
    ax.grid(alpha=0.3)
fig.suptitle("my_step: the FMU built for the scenario against the Python run")
save(fig, "own_muscle_fmu.png")
shutil.rmtree(work)
