"""Muscles on a rotary joint: scenarios with several muscles, their runs and results.

>>> from pamsim.joints import load_joint_scenario, simulate_joint
>>> result = simulate_joint(load_joint_scenario("scenarios/antagonistic_pair.toml"))  # doctest: +SKIP
"""

from .result import JointEvent, JointResult
from .scenario import JointScenario, is_joint_spec, load_joint_scenario
from .run import BACKENDS, simulate_joint

__all__ = ["BACKENDS", "JointEvent", "JointResult", "JointScenario", "is_joint_spec", "load_joint_scenario", "simulate_joint"]
