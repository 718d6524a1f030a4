"""A loop measured at a hanging load: the pressure is cycled, the contraction measured, and the force the
muscle's hysteresis carries is what its static force misses of the weight (docs/hysteresis.md,
"A loop at a hanging load").

At rest, or slowly enough that the load's inertia and damping are negligible, the load's balance is
``F_static(x, p) - W + F_h = 0`` with ``F_h`` the hysteresis elements' force on it, so the pull that the
contraction-to-force models of :mod:`pamsim.hysteresis.fit` describe (the elements resisting the contraction)
is ``W - F_static(x, p)``. The static force and the weight come from a scenario's muscle and load; whatever
the static model misses goes into the fitted offset and slope (``F0``, ``k0``) or, if it is not linear in the
contraction, into the residual.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..elements.friction import FRICTION_MODELS


def hysteresis_pull_N(static_force, weight_N: float, x_m, p_gauge_Pa) -> np.ndarray:
    """``W - F_static(x, p)`` [N]: what the static force ``static_force`` misses of the weight ``weight_N`` at
    each sample of ``x_m`` [m] and ``p_gauge_Pa`` [Pa], the hysteresis' pull in the sign of
    :mod:`pamsim.hysteresis.fit`."""
    return weight_N - np.asarray(static_force.force_N(x_m, p_gauge_Pa), dtype=float)


@dataclass(frozen=True)
class HangingWeight:
    """The muscle's static force and the hung weight that turn a pressure-contraction loop into the force the
    hysteresis carries."""

    static_force: object
    """An element with ``force_N(x_m, p_gauge_Pa)`` (the scenario's static force model)."""
    weight_N: float
    label: str
    """Where the two come from, for the fit's report: ``W - F_static(x, p)`` with the scenario's names."""
    friction: object
    """The scenario's friction law (``level_N(x_m, p_gauge_Pa, mass_kg)``), whose level the rig's Maxwell-slip
    elements share."""
    mass_kg: float
    level_label: str

    @classmethod
    def from_scenario(cls, path) -> "HangingWeight":
        """The static force and weight of the one-muscle rig of the scenario file ``path``.  Refused, naming the
        key: a muscle driven by its length (``[motion]``: no hung weight), a force on the load the derivation
        would leave out (``[load] external_force``, a ``[[component]]`` on the load), and ``friction =
        "none"`` (no level for the elements to share)."""
        from ..scenario import ScenarioError, load_scenario

        scenario = load_scenario(path)
        if "motion" in scenario.spec:
            raise ScenarioError(f"{path}: [motion]: the muscle is driven by its length; a loop at a hanging "
                                "load needs a scenario with a [load]")
        if "external_force" in scenario.spec.get("load", {}):
            raise ScenarioError(f"{path}: load.external_force: a loop at a hanging load is derived from the weight "
                                "and the static force alone; this force would be left out")
        on_load = [a.component.name for a in scenario.added_components
                   if any(t.startswith("load.") for t in a.connect.values()) and a.component.name != "hysteresis"]
        if on_load:
            raise ScenarioError(f"{path}: component {on_load[0]!r}: it acts on the load, and a loop at a hanging "
                                "load is derived from the weight and the static force alone")
        if scenario.spec["model"]["friction"] == "none":
            raise ScenarioError(f"{path}: model.friction = 'none': its level is 0, so elements that share it "
                                "have no slip force; give the friction law the rig's elements share")
        model = scenario.build_model()
        m = scenario.spec["model"]
        label = f"W - F_static(x, p): weight {model.load.weight_N:g} N, static force of {m['muscle']} ({path})"
        law = FRICTION_MODELS[m["friction"]](scenario.parameters, m)
        return cls(model.static_force, float(model.load.weight_N), label, law, float(model.load.mass_kg),
                   f"the {m['friction']} friction law's level F_c(x, p, m) ({path})")

    def pull_N(self, x_m, p_gauge_Pa) -> np.ndarray:
        """``W - F_static(x, p)`` [N] at each sample: the hysteresis' pull, in the sign of
        :mod:`pamsim.hysteresis.fit`."""
        return hysteresis_pull_N(self.static_force, self.weight_N, x_m, p_gauge_Pa)

    def level_N(self, x_m, p_gauge_Pa) -> np.ndarray:
        """The friction law's level [N] at each sample: the sum of the rig's elements' slip forces over shares."""
        x = np.asarray(x_m, dtype=float)
        return np.asarray(self.friction.level_N(x, p_gauge_Pa, self.mass_kg), dtype=float) + 0.0 * x
