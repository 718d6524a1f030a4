"""Gymnasium environments of pamsim's muscles (the ``rl`` extra: ``pip install 'pamsim[rl]'``).

Importing this package registers them with Gymnasium:

    import gymnasium
    import pamsim.envs  # noqa: F401  (or gymnasium.make("pamsim.envs:pamsim/MusclePosition-v0"))

    env = gymnasium.make("pamsim/MusclePosition-v0")              # the native backend
    env = gymnasium.make("pamsim/MusclePosition-v0", backend="python", command="pressure")

``docs/rl.md`` describes them: spaces with their units, reward, episodes, backends, speed.
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError as exc:  # pragma: no cover - the extra is installed wherever the tests run
    raise ImportError("pamsim.envs needs Gymnasium: pip install 'pamsim[rl]'") from exc

from .muscle_position import MusclePositionEnv

MUSCLE_POSITION_ID = "pamsim/MusclePosition-v0"
"""The registered id of :class:`MusclePositionEnv`."""

if MUSCLE_POSITION_ID not in gymnasium.registry:
    gymnasium.register(id=MUSCLE_POSITION_ID, entry_point="pamsim.envs.muscle_position:MusclePositionEnv")

__all__ = ["MUSCLE_POSITION_ID", "MusclePositionEnv"]
