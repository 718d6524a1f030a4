"""A muscle alone driven by its length (a scenario's ``[motion]`` table): prescribed-length force cycles on the
python, native and FMU backends, through the muscle-only assembly (:mod:`pamsim.assemblies.muscle_only`)."""

from .motion import Motion, motion_of
from .result import LengthDrivenResult
from .run import BACKENDS, LengthDrive, simulate_length_drive

__all__ = ["BACKENDS", "LengthDrive", "LengthDrivenResult", "Motion", "motion_of", "simulate_length_drive"]
