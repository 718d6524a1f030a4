"""The Bouc-Wen model of a muscle's friction: a smooth hysteretic displacement ``z`` on the load's flange, its
force the friction law's level at saturation.

``dz/dt = A v - beta |v| |z|^(n-1) z - gamma v |z|^n`` with ``A = 1`` (:data:`pamsim.hysteresis.bouc_wen.A`:
the scaling that makes the others identifiable), after Bouc (1967) and Wen, "Method for random vibration
of hysteretic systems", Journal of the Engineering Mechanics Division 102(2), 1976.  On a long loading
branch ``z`` tends to ``z_u = (A / (beta + gamma))^(1/n)``; the force on the load is ``-F_c z / z_u``, with
``F_c(x, p, m)`` the level of the ``[model] friction`` law, so that a long slide meets the same friction as
the law's Coulomb force, and the loop's shape between reversals is the model's.  Smooth: no events.
"""

from __future__ import annotations

from ..modeling import TRANSLATIONAL, Component, Equations, Port, Symbols, Var, positive
from ..modeling.smath import if_else
from .element import ElementParameters
from .friction import PROBE_POINTS, _level_N


class BoucWenFriction(ElementParameters, Component):
    """Bouc-Wen hysteresis scaled to the friction law ``element``'s level, in place of its Coulomb force.

    Parameters ``beta_per_m_n``, ``gamma_per_m_n`` (their sum above 0) and ``exponent`` ``n`` (> 0), and the
    law's.  States ``z_m`` and ``E_hysteresis_J``, the work the load has done on it.
    """

    ports = (Port("flange", TRANSLATIONAL, "branch"),)
    inputs = (Var("p_gauge_Pa", "Pa", "gauge pressure in the muscle"), Var("mass_kg", "kg", "load mass"))
    states = (Var("z_m", "m", "hysteretic displacement", 1e-3),
              Var("E_hysteresis_J", "J", "work done by the load on the hysteresis", 0.1))
    outputs = (Var("F_N", "N", "the hysteresis force on the load along x"),
               Var("level_N", "N", "the friction law's level, the force at saturation"),
               Var("z_saturation_m", "m", "(A / (beta + gamma))^(1/n)"))
    # beta and gamma are in m^-n, a unit that depends on n: declared "1", which a unit table can carry.
    extra_parameters = (Var("beta_per_m_n", "1", "Bouc-Wen beta [m^-n]"), Var("gamma_per_m_n", "1", "Bouc-Wen gamma [m^-n]"),
                        positive("exponent", "1", "Bouc-Wen n, the sharpness of the transition"))

    def __init__(self, name: str, element, beta_per_m_n: float, gamma_per_m_n: float, exponent: float,
                 branch: int | None = None):
        if branch not in (None, 1, -1):
            raise ValueError(f"branch {branch}: None, +1 (the contraction grows) or -1")
        self.branch = branch
        values = self.wrap(element, _level_N, PROBE_POINTS)
        values.update(beta_per_m_n=beta_per_m_n, gamma_per_m_n=gamma_per_m_n, exponent=exponent)
        super().__init__(name, values)

    def structure_key(self) -> tuple:
        """The key of :class:`ElementParameters`, with the branch held: it shapes the code."""
        return super().structure_key() + (self.branch,)

    def held(self, branch: int) -> "BoucWenFriction":
        """This model on one branch: ``|v|`` taken as ``branch * v`` (+1 or -1), differentiable at ``v = 0``;
        what a linearisation there differentiates (the branch of the last motion)."""
        values = {k: self.values[k] for k in ("beta_per_m_n", "gamma_per_m_n", "exponent")}
        return BoucWenFriction(self.name, self.element, **values, branch=branch)

    def held_state(self, p_abs_Pa: float) -> dict[str, float]:
        """The states at rest, relaxed (``z = 0``), whatever the pressure ``p_abs_Pa``."""
        return {"z_m": 0.0, "E_hysteresis_J": 0.0}

    def equations(self, s: Symbols) -> Equations:
        """The Bouc-Wen law in time, its force the level times ``z / z_u``."""
        u, flange, P = s.u, s.port["flange"], s.p
        v, z = flange["v_m_s"], s.x["z_m"]
        level = self.element_call(s, "level_N", flange["x_m"], u["p_gauge_Pa"], u["mass_kg"])
        n = P["exponent"]
        magnitude = if_else(z >= 0.0, z, -z) ** n  # |z|^n; |z|^(n-1) z is its sign times it
        sign_z = if_else(z >= 0.0, 1.0, -1.0)
        speed = if_else(v >= 0.0, v, -v) if self.branch is None else self.branch * v
        rate = v - P["beta_per_m_n"] * speed * sign_z * magnitude - P["gamma_per_m_n"] * v * magnitude
        z_u = (1.0 / (P["beta_per_m_n"] + P["gamma_per_m_n"])) ** (1.0 / n)
        force = -level * z / z_u
        return Equations(der={"z_m": rate, "E_hysteresis_J": -force * v},
                         outputs={"F_N": force, "level_N": level, "z_saturation_m": z_u},
                         port={"flange": {"F_N": force}}, initial={"z_m": 0.0, "E_hysteresis_J": 0.0})
