"""The proportional spool valve (:mod:`pamsim.elements.spool`) as a component: its spool's position and
velocity as states, its two paths' flows into a pneumatic port."""

from __future__ import annotations

from ..modeling import Equations, Symbols, Var
from .pwm_valve import two_path_flows
from .valve import ProportionalValve


class SpoolValve(ProportionalValve):
    """:class:`pamsim.elements.spool.SpoolValve33`: a pneumatic branch with the proportional valve's ports,
    inputs, outputs and parameters, the spool's natural frequency, damping ratio, overlap and leakage
    besides, and its position and velocity as states (at rest in the centre at the start).

    The command drives the spool; the flow follows the spool's position, not the command.
    """

    states = (Var("spool_position", "1", "spool position as a fraction of its stroke (+1 open to supply)", 0.1),
              Var("spool_velocity_per_s", "1/s", "spool velocity in strokes per second", 100.0))

    def equations(self, s: Symbols) -> Equations:
        """The spool's second-order lag behind the command, and the two paths' flows at its position."""
        valve = self.symbolic_element(s.p)
        position, velocity = s.x["spool_position"], s.x["spool_velocity_per_s"]
        outputs, port = two_path_flows(self, s, position)
        return Equations(der={"spool_position": velocity,
                              "spool_velocity_per_s": valve.spool_acceleration(position, velocity, s.u["command"])},
                         initial={"spool_position": 0.0, "spool_velocity_per_s": 0.0}, outputs=outputs, port=port)
