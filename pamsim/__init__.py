"""pamsim: dynamic simulation of McKibben pneumatic artificial muscles.

    import pamsim
    result = pamsim.simulate(pamsim.load_scenario("scenarios/acra2012_fig4.toml"))
    result.plot("fig4.png")
"""

from .api import simulate
from .model import Mode, MuscleModel
from .muscles import load_muscle
from .parameters import ParameterSet, get_parameter_set
from .result import Result
from .scenario import Scenario, ScenarioError, load_scenario
from .simulator import SolverFailure, SolverOptions, simulate_model
from . import static_models
from . import sweep  # a callable package: pamsim.sweep(spec, executor) runs a sweep

__all__ = ["simulate", "load_scenario", "Scenario", "ScenarioError", "Result", "Mode", "MuscleModel",
           "ParameterSet", "get_parameter_set", "SolverFailure", "SolverOptions",
           "simulate_model", "load_muscle", "static_models"]
__version__ = "0.1.0"
