"""``headsim/Fixate-v0`` vectorised: ``num_envs`` heads in lockstep over arrays.

``gymnasium.make_vec("headsim/Fixate-v0", num_envs=64,
vectorization_mode="vector_entry_point")`` makes a :class:`FixateVectorEnv`.  Its heads
are one :class:`~headsim.lockstep.LockstepHeads`: a step advances every head's motors in
numpy and their physics in one MuJoCo batch rollout, draws both eyes of every head
through one OpenGL context, and finds the marker over the whole stack of images.  Each
head keeps :class:`~headsim.envs.fixate.FixateEnv`'s episode draws, noise streams,
physics, detections and rewards: head i of a batch seeded ``s`` steps as a single
``FixateEnv`` seeded ``s + i`` does, image for image (tests/envs/test_vector.py).

Gymnasium 1.x semantics: batched ``Dict`` observations and ``Box`` actions
(:func:`gymnasium.vector.utils.batch_space`), infos with ``_key`` masks, and
next-step autoreset (``metadata["autoreset_mode"]``): the step after a head's episode
ends resets it, with reward 0 and neither flag set.  ``reset(seed=s)`` seeds head i with
``s + i``; ``options["reset_mask"]`` resets only the heads marked.  Infos are arrays
over heads: ``estimate_world_m`` and ``truth_world_m`` (num_envs, 3) with NaN rows
where a head has none (and False in their ``_key`` masks).

``supersample``: each image's supersampling (None: the head's, 2, the classic env's
images; 1 renders a quarter of the pixels).  The marker scene only.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from headsim.envs.fixate import (
    TARGET_BODY,
    TARGET_COLOUR,
    FixateEnv,
    draw_marker_path,
    draw_settings,
    estimate_world,
    marker_goals,
    offsets_reward,
    position_reward,
)
from headsim.lockstep import Frames, LockstepHeads, find_markers_stacked
from headsim.sim.settings import SettingsError


class FixateVectorEnv(VectorEnv):
    """``num_envs`` :class:`~headsim.envs.fixate.FixateEnv` heads in lockstep (see the
    module docstring).  ``supersample``: images' supersampling (None: the head's).
    ``renderer``: :data:`headsim.lockstep.heads.RENDERERS` (default ``"auto"``: MuJoCo
    Warp on a GPU, else OpenGL on the CPU; :meth:`describe` says which).  Every other
    keyword is ``FixateEnv``'s."""

    metadata: dict[str, Any] = {  # noqa: RUF012 (gymnasium.VectorEnv declares it an instance attribute)
        "render_modes": ["rgb_array"],
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 1,
        *,
        supersample: int | None = None,
        renderer: str = "auto",
        **env_kwargs: Any,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int) or num_envs < 1:
            raise SettingsError(f"num_envs must be a whole number >= 1, got {num_envs!r}")
        if env_kwargs.get("scene", "marker") != "marker":
            raise SettingsError(
                "scene: the vectorised env has the marker scene only; "
                "use FixateEnv for 'textured_plane'"
            )
        #: The single env whose arguments, spaces and draws every head shares (never reset).
        self.template = FixateEnv(**env_kwargs)
        template = self.template
        self.heads = LockstepHeads(
            num_envs,
            template.base_settings,
            template.live_config,
            target_body=TARGET_BODY,
            prepare=template.prepare_model,
            supersample=supersample,
            renderer=renderer,
        )
        self.num_envs = num_envs
        self.render_mode = template.render_mode
        self.single_observation_space = template.observation_space
        self.single_action_space = template.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._rngs: list[np.random.Generator | None] = [None] * num_envs
        self._goals = np.zeros((num_envs, 3))
        cam = template.base_settings.cameras[0]
        image_shape = (cam.height, cam.width, 3)
        self._images = np.zeros((num_envs, *image_shape), np.uint8)
        self._images2 = np.zeros_like(self._images)
        self._encoders = np.zeros((num_envs, 3), np.float32)
        self._steps = np.zeros(num_envs, np.int64)
        self._time_s = np.zeros(num_envs)
        self._found = np.zeros(num_envs, np.bool_)
        self._offsets = np.full((num_envs, 3), np.nan)
        self._estimates = np.full((num_envs, 3), np.nan)
        self._truths = np.full((num_envs, 3), np.nan)
        self._rewards = np.zeros(num_envs, np.float64)
        self._terminations = np.zeros(num_envs, np.bool_)
        self._truncations = np.zeros(num_envs, np.bool_)
        self._autoreset = np.zeros(num_envs, np.bool_)

    def describe(self) -> str:
        """How the heads are run and rendered, in words."""
        return self.heads.describe()

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
        ids = np.flatnonzero(mask)
        for head in ids:
            if seeds[head] is not None or self._rngs[head] is None:
                self._rngs[head], _ = seeding.np_random(seeds[head])
        self._start(ids, options)
        self._rewards[ids] = 0.0
        self._terminations[ids] = False
        self._truncations[ids] = False
        self._autoreset[ids] = False
        return self._observations(), self._infos(ids)

    def _start(self, ids: np.ndarray, options: dict[str, Any]) -> None:
        """New episodes for ``ids``: each head's draws from its own generator, as
        ``FixateEnv.reset`` draws them, then frame 0."""
        template = self.template
        ranges = template.episode_ranges(options)
        settings, paths = [], []
        for head in ids:
            rng = self._rngs[head]
            assert rng is not None
            drawn = draw_settings(rng, template.base_settings, ranges)
            duration_s = template.max_steps * template.period_s
            paths.append(draw_marker_path(rng, drawn, ranges, options, duration_s))
            settings.append(drawn)
            self._goals[head] = marker_goals(drawn)
        self._steps[ids] = 0
        self._take(self.heads.reset(ids, settings, paths))

    def step(
        self, actions: np.ndarray
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        actions = np.asarray(actions)
        if actions.shape != self.action_space.shape:
            raise ValueError(
                f"actions must have shape {self.action_space.shape}, got {actions.shape}"
            )
        space = self.template.action_space
        restart = np.flatnonzero(self._autoreset)
        going = np.flatnonzero(~self._autoreset)
        if len(restart):  # next-step autoreset: this step only resets the head
            self._start(restart, {})
            self._rewards[restart] = 0.0
            self._terminations[restart] = False
            self._truncations[restart] = False
        if len(going):
            speeds = np.clip(actions[going].astype(float), space.low, space.high)
            self.heads.command_velocity(going, speeds * self.template.action_scale_rad_s)
            self._take(self.heads.capture(going))
            self._steps[going] += 1
            self._score(going)
        self._autoreset = self._terminations | self._truncations
        return (
            self._observations(),
            self._rewards.copy(),
            self._terminations.copy(),
            self._truncations.copy(),
            self._infos(np.arange(self.num_envs)),
        )

    # -- measurements ------------------------------------------------------------
    def _take(self, frames: Frames) -> None:
        """A capture's images, encoders and clock, and what the heads measure in it."""
        ids = frames.heads
        self._images[ids] = frames.images[:, 0]
        self._images2[ids] = frames.images[:, 1]
        self._encoders[ids] = frames.encoders_rad.astype(np.float32)
        self._time_s[ids] = frames.time_s
        self._truths[ids] = frames.truth_target_world_m
        height, width = frames.images.shape[2:4]
        seen = find_markers_stacked(frames.images.reshape(-1, height, width, 3), TARGET_COLOUR)
        uv = np.full((len(ids), 2, 2), np.nan)
        for index, detection in enumerate(seen):
            if detection.found and detection.uv is not None:
                uv[index // 2, index % 2] = detection.uv
        found = ~np.isnan(uv).any(axis=(1, 2))
        self._found[ids] = found
        seen_uv = np.stack([uv[:, 0, 0], uv[:, 1, 0], (uv[:, 0, 1] + uv[:, 1, 1]) / 2], axis=1)
        self._offsets[ids] = np.where(found[:, None], seen_uv - self._goals[ids], np.nan)
        rows = {int(head): row for row, head in enumerate(ids)}
        for settings, members in self._by_settings(ids).items():
            encoders = frames.encoders_rad[[rows[head] for head in members]]
            self._estimates[members] = estimate_world(encoders, settings, self.template.knowledge)

    def _by_settings(self, ids: np.ndarray) -> dict[Any, np.ndarray]:
        """``ids`` grouped by their heads' settings (one group when none is randomised)."""
        groups: dict[int, list[int]] = {}
        kept: dict[int, Any] = {}
        for head in ids:  # heads of equal settings share one settings object: no deep hash
            settings = self.heads.settings(head)
            groups.setdefault(id(settings), []).append(int(head))
            kept[id(settings)] = settings
        return {kept[key]: np.array(members) for key, members in groups.items()}

    def _score(self, ids: np.ndarray) -> None:
        """Rewards and ends of ``ids``' episodes after a step, as ``FixateEnv.step`` scores."""
        template = self.template
        for settings, heads in self._by_settings(ids).items():
            if template.reward_kind == "offsets":
                reward = offsets_reward(self._offsets[heads], self._found[heads], settings)
            else:
                reward = position_reward(self._estimates[heads], self._truths[heads], settings)
            self._rewards[heads] = reward
        within = np.all(np.abs(self._offsets[ids]) <= template.tolerance_px, axis=1)
        self._terminations[ids] = self._found[ids] & within
        self._truncations[ids] = ~self._terminations[ids] & (self._steps[ids] >= template.max_steps)

    def _observations(self) -> dict[str, np.ndarray]:
        return {
            "cam1": self._images.copy(),
            "cam2": self._images2.copy(),
            "encoders": self._encoders.copy(),
        }

    def _infos(self, ids: np.ndarray) -> dict[str, Any]:
        """Infos of ``ids`` (arrays over all heads, ``_key`` masks marking ``ids``)."""
        mask = np.zeros(self.num_envs, np.bool_)
        mask[ids] = True
        has_estimate = mask & ~np.isnan(self._estimates).any(axis=1)
        has_truth = mask & ~np.isnan(self._truths).any(axis=1)
        shown = mask[:, None]
        infos: dict[str, Any] = {
            "found": self._found & mask,
            "offsets_px": np.where(shown, self._offsets, 0.0),
            "estimate_world_m": np.where(has_estimate[:, None], self._estimates, np.nan),
            "time_s": np.where(mask, self._time_s, 0.0),
            "truth_world_m": np.where(has_truth[:, None], self._truths, np.nan),
            "steps": np.where(mask, self._steps, 0),
        }
        masks = {f"_{key}": mask.copy() for key in infos}
        masks["_estimate_world_m"] = has_estimate
        masks["_truth_world_m"] = has_truth
        return {**infos, **masks}

    def render(self) -> tuple[np.ndarray, ...] | None:
        """Each head's two camera images side by side (``render_mode="rgb_array"``)."""
        if self.render_mode != "rgb_array":
            return None
        return tuple(
            np.concatenate((self._images[i], self._images2[i]), axis=1)
            for i in range(self.num_envs)
        )

    def close_extras(self, **kwargs: Any) -> None:
        self.heads.close()


__all__ = ["FixateVectorEnv"]
