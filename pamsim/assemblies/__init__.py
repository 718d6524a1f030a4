"""Assemblies of components: the systems pamsim simulates, as connected components."""

from .one_muscle import one_muscle_assembly, scenario_assembly

__all__ = ["one_muscle_assembly", "scenario_assembly"]
