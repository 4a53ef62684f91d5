"""Gymnasium environments of the head (optional extra ``gym``).

``import headsim.envs`` registers ``headsim/Fixate-v0``; then
``gymnasium.make("headsim/Fixate-v0")``.  In spawned worker processes
(``gymnasium.make_vec(..., vectorization_mode="async",
vector_kwargs={"context": "spawn"})``) the entry point imports this module.
``gymnasium.make_vec(FIXATE_ID, num_envs=N, vectorization_mode="vector_entry_point")``
makes :class:`headsim.envs.vector.FixateVectorEnv`: N heads in lockstep over arrays
(:mod:`headsim.lockstep`).
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError as err:  # pragma: no cover - depends on the install
    raise ImportError("headsim.envs needs Gymnasium: pip install 'headsim[gym]'") from err

FIXATE_ID = "headsim/Fixate-v0"

if FIXATE_ID not in gymnasium.registry:
    gymnasium.register(
        id=FIXATE_ID,
        entry_point="headsim.envs.fixate:FixateEnv",
        vector_entry_point="headsim.envs.vector:FixateVectorEnv",
    )

__all__ = ["FIXATE_ID"]
