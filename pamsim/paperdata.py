"""Measured data shipped with pamsim (copied from the papers, with provenance)."""

from __future__ import annotations

from importlib import resources

import numpy as np

ACRA2012_STEADY_STATE = "acra2012_steady_state.csv"
"""Tables 1 and 2 of the ACRA 2012 paper: 66 steady states (6-8 s averages)."""


def acra2012_steady_state() -> np.ndarray:
    """The 66 measured steady states as a structured array.

    Fields: ``weight_N`` (holder included), ``pressure_step_bar``,
    ``pressure_stable_bar`` (gauge) and ``contraction_stable_mm``.
    """
    text = resources.files("pamsim.data").joinpath(ACRA2012_STEADY_STATE).read_text()
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    return np.genfromtxt(lines, delimiter=",", names=True)
