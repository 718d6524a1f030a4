"""A prescribed gauge pressure: the model input passed on to whatever reads the muscle's pressure."""

from __future__ import annotations

from ..modeling import Component, Equations, Symbols, Var


class PressureSignal(Component):
    """Output ``p_gauge_Pa`` equal to input ``p_in_gauge_Pa`` (a step, ramp, lag or measured trace)."""

    inputs = (Var("p_in_gauge_Pa", "Pa", "prescribed gauge pressure"),)
    outputs = (Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"),)

    def equations(self, s: Symbols) -> Equations:
        return Equations(outputs={"p_gauge_Pa": s.u["p_in_gauge_Pa"]})
