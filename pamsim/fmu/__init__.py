"""Export the muscle model as an FMU (FMI 2.0 and 3.0, Model Exchange and
Co-Simulation) and run scenarios through it.

``build()`` compiles the C model in ``fmu/`` (see ``docs/fmu.md``); ``build_assembly()`` the model
generated from a scenario's assembly of components;
``simulate_fmu()`` runs a :class:`~pamsim.scenario.Scenario` through fmpy.
"""

from .assembly_fmu import build_assembly
from .muscle_spec import build
from .runner import simulate_fmu

__all__ = ["build", "build_assembly", "simulate_fmu"]
