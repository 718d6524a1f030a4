"""
Closed-loop position control
============================

``scenarios/closed_loop_position.toml``: move the 22.74 N load of the Figure 4 test of the ACRA 2012
paper (the dynamic force model of a small and soft McKibben muscle, Australasian Conference on Robotics
and Automation, 2012; its authors and title are not in the text pamsim was built from: full reference in
``docs/model.md``) from rest at 20 mm to 40 mm with the valve, under an LQR controller with integral
action. The controller is designed on the linearisation at 30 mm (valve closed, Coulomb friction
dropped; Bryson's rule sets the weights from the scenario's ``[controller]`` table) and runs, sampled,
on the hybrid stick/slip model, the valve saturating at +-1 (``docs/control.md``). From a shell::

    pamsim run scenarios/closed_loop_position.toml -o out/

which exits with 1 if the run misses the scenario's ``[controller.spec]``.
"""

import pamsim
from pamsim.figure_style import save

run = pamsim.run("../scenarios/closed_loop_position.toml")
controller = run.summary()["controller"]
print("gains K (x [1/m], v [s/m], p [1/Pa], z [1/(m s)]): " + ", ".join(f"{k:.4g}" for k in controller["gains_K"]))
print("design poles [1/s]: " + ", ".join(f"{complex(re, im):.3g}" for re, im in controller["design_poles"]))

# %%
# The response on the hybrid model against the linear loop it was designed on, and the specification:

save(run.figure(), "closed_loop.png")
m, spec = controller["metrics"], controller["spec"]
print(f"rise time {m['rise_time_s'] * 1e3:.0f} ms (at most {spec['rise_time_max_s'] * 1e3:.0f} ms)")
print(f"overshoot {m['overshoot_percent']:.1f} % (at most {spec['overshoot_max_percent']:g} %)")
print(f"settling time into +-{spec['settling_band_mm']:g} mm {m['settling_time_s'] * 1e3:.0f} ms "
      f"(at most {spec['settling_time_max_s'] * 1e3:.0f} ms)")
print(f"steady-state error {m['steady_state_error_mm']:.3f} mm (at most {spec['steady_state_error_max_mm']:g} mm)")
print("meets its specification" if not run.failures else "misses: " + "; ".join(run.failures))
lin = controller["linear_prediction_metrics"]
print(f"the linear loop predicted {lin['overshoot_percent']:.1f} % overshoot: its integral winds up during the "
      "rise; on the hybrid model the anti-windup bleeds it while the valve saturates, and Coulomb friction, "
      "which the design drops, damps the rest")
