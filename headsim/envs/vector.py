"""``headsim/Fixate-v0`` vectorised: ``num_envs`` heads that step and render in one call.

``gymnasium.make_vec("headsim/Fixate-v0", num_envs=64,
vectorization_mode="vector_entry_point")`` makes a :class:`FixateVectorEnv`.  Each
sub-environment is a :class:`~headsim.envs.fixate.FixateEnv` with its own head, episode
draws and noise; a ``reset`` or ``step`` runs all of them in lockstep in one
:class:`~headsim.sim.batch.BatchSession`, so both cameras of every head are ray-cast
together by MuJoCo Warp (``headsim[batch]``; ``device="cuda"`` on a GPU).  Physics,
encoders, marker detection and rewards stay each head's own, as in the single env.

Gymnasium 1.x semantics: batched ``Dict`` observations and ``Box`` actions
(:func:`gymnasium.vector.utils.batch_space`), infos with ``_key`` masks, and
next-step autoreset (``metadata["autoreset_mode"]``): the step after a head's episode
ends resets it, with reward 0 and neither flag set.  ``reset(seed=s)`` seeds head i with
``s + i``; ``options["reset_mask"]`` resets only the heads marked.
"""

from __future__ import annotations

import functools
from copy import deepcopy
from dataclasses import replace
from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array, iterate

from headsim.envs import FIXATE_ID
from headsim.envs.fixate import FixateEnv
from headsim.sim.batch import BatchSession
from headsim.sim.settings import SettingsError


class FixateVectorEnv(VectorEnv):
    """``num_envs`` :class:`~headsim.envs.fixate.FixateEnv` heads rendered in batches.

    ``device``: ``"cpu"`` or ``"cuda"``.  ``samples_per_pixel``: the batch renderer's
    rays per pixel per axis (None: the head's own ``render.supersample``).  Every other
    keyword goes to each sub-environment.
    """

    metadata: dict[str, Any] = {  # noqa: RUF012 (gymnasium.VectorEnv declares it an instance attribute)
        "render_modes": ["rgb_array"],
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 1,
        *,
        device: str = "cpu",
        samples_per_pixel: int | None = None,
        **env_kwargs: Any,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int) or num_envs < 1:
            raise SettingsError(f"num_envs must be a whole number >= 1, got {num_envs!r}")
        if env_kwargs.get("scene", "marker") != "marker":
            raise SettingsError(
                "scene: the vectorised env has the marker scene only (its batch renderer "
                "keeps the textures it was made with); use FixateEnv for 'textured_plane'"
            )
        self.session = BatchSession(device, samples_per_pixel)
        self.envs = [FixateEnv(**env_kwargs) for _ in range(num_envs)]
        spec = gymnasium.registry.get(FIXATE_ID)
        for env in self.envs:  # each sub-env as gymnasium.make would make it
            env.spec = None if spec is None else replace(spec, kwargs=dict(env_kwargs))
        self.num_envs = num_envs
        self.render_mode = self.envs[0].render_mode
        self.single_observation_space = self.envs[0].observation_space
        self.single_action_space = self.envs[0].action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._observations: Any = create_empty_array(self.single_observation_space, num_envs)
        self._rewards = np.zeros(num_envs, np.float64)
        self._terminations = np.zeros(num_envs, np.bool_)
        self._truncations = np.zeros(num_envs, np.bool_)
        self._autoreset = np.zeros(num_envs, np.bool_)

    def reset(
        self,
        *,
        seed: int | list[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        seeds = (
            [None] * self.num_envs
            if seed is None
            else [seed + i for i in range(self.num_envs)]
            if isinstance(seed, int)
            else list(seed)
        )
        if len(seeds) != self.num_envs:
            raise ValueError(f"seed: a list of {self.num_envs} seeds, got {len(seeds)}")
        options = dict(options or {})
        mask = np.asarray(options.pop("reset_mask", np.ones(self.num_envs, np.bool_)))
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_ or not mask.any():
            raise ValueError(
                f"options['reset_mask']: a bool array of shape ({self.num_envs},) with a True"
            )
        heads = [i for i in range(self.num_envs) if mask[i]]
        calls = [
            functools.partial(self.envs[i].reset, seed=seeds[i], options=options or None)
            for i in heads
        ]
        infos: dict[str, Any] = {}
        observations = self._split()
        for i, (observation, info) in zip(heads, self.session.run(calls), strict=True):
            observations[i] = observation
            infos = self._add_info(infos, info, i)
        self._terminations[mask] = False
        self._truncations[mask] = False
        self._autoreset[mask] = False
        return self._batch(observations), infos

    def step(
        self, actions: np.ndarray
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        calls = []
        for i, action in enumerate(iterate(self.action_space, actions)):
            env = self.envs[i]
            calls.append(env.reset if self._autoreset[i] else functools.partial(env.step, action))
        observations = self._split()
        infos: dict[str, Any] = {}
        results: list[Any] = self.session.run(calls)
        for i, result in enumerate(results):
            if self._autoreset[i]:  # next-step autoreset: this step only reset the head
                observations[i], info = result
                self._rewards[i], self._terminations[i], self._truncations[i] = 0.0, False, False
            else:
                (
                    observations[i],
                    self._rewards[i],
                    self._terminations[i],
                    self._truncations[i],
                    info,
                ) = result
            infos = self._add_info(infos, info, i)
        self._autoreset = np.logical_or(self._terminations, self._truncations)
        return (
            self._batch(observations),
            self._rewards.copy(),
            self._terminations.copy(),
            self._truncations.copy(),
            infos,
        )

    def render(self) -> tuple[np.ndarray, ...] | None:
        """Each head's two camera images side by side (``render_mode="rgb_array"``)."""
        frames = [env.render() for env in self.envs]
        if self.render_mode != "rgb_array" or any(f is None for f in frames):
            return None
        return tuple(f for f in frames if f is not None)

    def close_extras(self, **kwargs: Any) -> None:
        for env in self.envs:
            env.close()

    def _split(self) -> list[Any]:
        return list(iterate(self.single_observation_space, self._observations))

    def _batch(self, observations: list[Any]) -> dict[str, np.ndarray]:
        self._observations = concatenate(
            self.single_observation_space, observations, self._observations
        )
        batched: dict[str, np.ndarray] = deepcopy(self._observations)
        return batched


__all__ = ["FixateVectorEnv"]
