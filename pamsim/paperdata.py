"""Measured data shipped with pamsim (copied from the papers, with provenance)."""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources

import numpy as np

from .references import REFERENCES

ACRA2012_STEADY_STATE = "acra2012_steady_state.csv"
"""Tables 1 and 2 of the ACRA 2012 paper: 66 steady states (6-8 s averages)."""

STEADY_STATE_SETS = ("acra2012",)
"""Names of the measured steady states a scenario's ``[measured] steady_state`` may name."""

MATCH_BAR = 0.005
MATCH_N = 0.005
"""A scenario's supply step [bar] and hung weight [N] name a test of the paper's tables when they lie this close
to its nominal step and weight (the tables give them to two decimals)."""


def acra2012_steady_state() -> np.ndarray:
    """The 66 measured steady states as a structured array.

    Fields: ``weight_N`` (holder included), ``pressure_step_bar``,
    ``pressure_stable_bar`` (gauge) and ``contraction_stable_mm``.
    """
    text = resources.files("pamsim.data").joinpath(ACRA2012_STEADY_STATE).read_text()
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    return np.genfromtxt(lines, delimiter=",", names=True)


@dataclass(frozen=True)
class SteadyState:
    """The measured end of one step test: the mean contraction and pressure over the window ``window_s``
    of the test's record, which is all the paper gives of it as numbers (its figures draw the trace)."""

    weight_N: float
    pressure_step_bar: float
    pressure_stable_bar: float
    contraction_mm: float
    window_s: tuple[float, float]
    source: str
    """Where the numbers are printed, e.g. ``"ACRA 2012, Tables 1 and 2"``."""


def steady_state(name: str, pressure_step_bar: float, weight_N: float) -> SteadyState | None:
    """The measured steady state of the test with this supply step and hung weight (holder included) in the
    data set ``name`` (one of :data:`STEADY_STATE_SETS`), or None when the paper has no such test.

    ``"acra2012"``: Tables 1 and 2 of the ACRA 2012 paper, means over 6-8 s of the 8 s records (its
    section 3.2); the tests of its Figures 3-6 are among them.
    """
    if name != "acra2012":
        raise ValueError(f"unknown measured steady states {name!r} (known: {', '.join(STEADY_STATE_SETS)})")
    rows = acra2012_steady_state()
    hit = rows[(np.abs(rows["pressure_step_bar"] - pressure_step_bar) <= MATCH_BAR)
               & (np.abs(rows["weight_N"] - weight_N) <= MATCH_N)]
    if not len(hit):
        return None
    row = hit[0]
    return SteadyState(float(row["weight_N"]), float(row["pressure_step_bar"]), float(row["pressure_stable_bar"]),
                       float(row["contraction_stable_mm"]), (6.0, 8.0),
                       f"{REFERENCES['acra2012'].short}, Tables 1 and 2")
