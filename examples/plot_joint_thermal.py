"""
Chamber laws and lines on a joint's muscles
===========================================

The shipped antagonistic pair with each muscle's chamber under the thermal law, the flexor's valve feeding
it through 1 m of 4 mm tube, against the pair as shipped (polytropic chambers, no tube); then the slider
form of three one-muscle rigs with their pneumatics against the rigs themselves (docs/pneumatics.md,
"Where the laws apply").
"""

import tomllib
from pathlib import Path

import numpy as np

from pamsim.api import simulate
from pamsim.joints import JointScenario, simulate_joint
from pamsim.joints.scenario import slider_of_rig
from pamsim.scenario import load_scenario

SCENARIOS = Path("../scenarios")

spec = tomllib.loads((SCENARIOS / "antagonistic_pair.toml").read_text())
shipped = JointScenario.from_dict(spec, origin="antagonistic_pair.toml", base_dir=SCENARIOS)
for muscle in spec["muscle"]:
    muscle["chamber"] = {"law": "thermal"}  # the default h and wall temperature (docs/pneumatics.md)
flexor = spec["muscle"][0]
flexor["pressure"]["outlet_port"] = "tube.inlet"
flexor["component"] = [{"name": "tube", "type": "tube", "inlet": "volume", "length_m": 1.0, "diameter_m": 0.004,
                        "connect": {"outlet": "chamber.port"}}]
thermal = JointScenario.from_dict(spec, origin="thermal pair", base_dir=SCENARIOS)

runs = {"shipped": simulate_joint(shipped), "thermal + tube": simulate_joint(thermal)}
for name, run in runs.items():
    theta = np.degrees(run.theta_rad)
    line = f"{name:15s} final angle {theta[-1]:.3f} deg, peak {np.max(theta):.3f} deg"
    for m in run.thermal_muscles():
        gas = run.muscle(m, "gas_temperature_K")
        line += f"; {m} gas peak {np.max(gas) - 273.15:.1f} degC, final {gas[-1] - 273.15:.2f} degC"
    print(line)
runs["thermal + tube"].plot("joint_thermal.png")

for name in ("supply_chain", "pwm_onoff", "thermal_drift"):
    rig_scenario = load_scenario(SCENARIOS / f"{name}.toml")
    rig, slider = simulate(rig_scenario), simulate_joint(slider_of_rig(rig_scenario))
    print(f"{name:15s} slider against the rig: largest gap {np.max(np.abs(rig.x_m - slider.position)):.2e} m, "
          f"{np.max(np.abs(rig.p_gauge_Pa - slider.muscle('muscle', 'p_gauge_Pa'))):.3g} Pa")
