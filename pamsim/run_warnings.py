"""Warnings on a run that cannot show what it was set up to show.

They go with the fit-range warnings into ``Result.warnings`` (so into the JSON
summary), and ``pamsim run`` prints each on stderr; the run itself is kept.
"""

from __future__ import annotations

import numpy as np

from .constants import PA_PER_BAR
from .elements.pressure_source import PrescribedPressure, ValveChamberSource


def pointless_run_warnings(model, t_s: np.ndarray, at_rest_at_end: bool, v_end_m_s: float) -> list[str]:
    """The valve never opens, the load is beyond the blocked force, or the load still moves at the end."""
    t_end = float(t_s[-1])
    out = []
    src = model.source
    if isinstance(src, ValveChamberSource) and not np.any(np.asarray(src.command(t_s)) > 0.0):
        opens = getattr(src.command, "time_s", None)  # a step's opening time
        when = f"opens at {opens:g} s, after the run ends at {t_end:g} s" if opens is not None else \
            f"stays closed (command <= 0) until the run ends at {t_end:g} s"
        out.append(f"the valve {when}: the muscle never sees the supply "
                   "(raise simulation.duration_s or open the valve earlier)")
    supply = _largest_supply_Pa(src, t_s)
    if supply is not None:
        blocked = float(model.static_force.force_N(0.0, supply))
        weight = model.load.weight_N
        if weight > blocked + float(np.max(model.load.external_N(t_s))):
            out.append(f"the load, {weight:.4g} N, is beyond the muscle's blocked force at the supply pressure, "
                       f"{blocked:.4g} N at {supply / PA_PER_BAR:.4g} bar: it cannot lift it")
    if not at_rest_at_end:
        out.append(f"still moving at the end ({v_end_m_s * 1e3:.3g} mm/s at {t_end:g} s): the run ends before the "
                   "load settles (raise simulation.duration_s)")
    return out


def _largest_supply_Pa(source, t_s: np.ndarray) -> float | None:
    """Highest gauge pressure [Pa] the source offers during the run: the valve's supply or the prescribed
    pressure; None for a source driven by something else (a controller)."""
    if isinstance(source, ValveChamberSource):
        return float(np.max(source.supply_gauge_Pa(t_s)))
    if isinstance(source, PrescribedPressure):
        return float(np.max(source.p_gauge_Pa(t_s)))
    return None
