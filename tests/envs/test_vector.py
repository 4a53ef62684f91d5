"""headsim/Fixate-v0 vectorised on lockstep heads: Gymnasium 1.x's vector API, next-step
autoreset, seeding, a reset mask, and heads that step as the single env does, image for
image (real renders, both sides)."""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
import pytest

import headsim.envs
from headsim.envs.fixate import FixateEnv
from headsim.envs.vector import FixateVectorEnv
from headsim.sim.settings import SettingsError

ID = headsim.envs.FIXATE_ID


def test_make_vec_builds_batched_spaces() -> None:
    venv = gymnasium.make_vec(ID, num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(venv.unwrapped, FixateVectorEnv)
    assert venv.observation_space["cam1"].shape == (3, 96, 128, 3)  # type: ignore[index]
    assert venv.action_space.shape == (3, 3)
    obs, _ = venv.reset(seed=5)
    assert venv.observation_space.contains(obs)
    obs, reward, _, _, info = venv.step(np.full((3, 3), 0.2, np.float32))
    assert venv.observation_space.contains(obs) and reward.shape == (3,)
    assert info["found"].all() and info["_found"].all() and info["_truth_world_m"].all()
    assert "one context" in venv.unwrapped.describe()
    venv.close()


@pytest.mark.parametrize("reward", ["offsets", "position"])
def test_each_head_steps_as_the_single_env_does_autoresets_included(reward: str) -> None:
    """Randomised cameras and noise, moving targets, episodes of 3 steps: every head's
    observations, rewards, flags and infos are the single env's, seeded s + i, reset
    when its episode ends."""
    kwargs: dict[str, Any] = {
        "reward": reward,
        "max_steps": 3,
        "randomise": {"kx": (100.0, 130.0), "noise_std": (0.0, 2.0), "speed_m_s": (0.0, 0.3)},
    }
    venv = FixateVectorEnv(3, **kwargs)
    rng = np.random.default_rng(1)
    actions = rng.uniform(-0.5, 0.5, (8, 3, 3)).astype(np.float32)
    batched: list[tuple] = [venv.reset(seed=20)]
    batched += [venv.step(a) for a in actions]
    venv.close()
    assert sum(bool(out[2].any() or out[3].any()) for out in batched[1:]) >= 2  # episodes ended
    for head in range(3):
        env = FixateEnv(**kwargs)
        obs, info = env.reset(seed=20 + head)
        alone: list[tuple] = [(obs, info)]
        done = False
        for action in actions[:, head]:
            if done:  # next-step autoreset
                obs, info = env.reset()
                alone.append((obs, 0.0, False, False, info))
                done = False
                continue
            out = env.step(action)
            alone.append(out)
            done = out[2] or out[3]
        env.close()
        for ours, theirs in zip(batched, alone, strict=True):
            for key in ("cam1", "cam2", "encoders"):
                np.testing.assert_array_equal(ours[0][key][head], theirs[0][key])
            info, single = ours[-1], theirs[-1]
            np.testing.assert_array_equal(info["offsets_px"][head], single["offsets_px"])
            assert info["found"][head] == single["found"]
            assert info["steps"][head] == single["steps"]
            assert info["time_s"][head] == single["time_s"]
            np.testing.assert_array_equal(info["truth_world_m"][head], single["truth_world_m"])
            estimate = single["estimate_world_m"]
            if estimate is None:
                assert not info["_estimate_world_m"][head]
            else:
                np.testing.assert_allclose(info["estimate_world_m"][head], estimate, atol=1e-12)
            if len(ours) == 5:
                assert ours[1][head] == pytest.approx(theirs[1], abs=1e-12)
                assert (ours[2][head], ours[3][head]) == (theirs[2], theirs[3])


def test_next_step_autoreset_resets_a_finished_head_with_no_reward() -> None:
    venv = FixateVectorEnv(2, max_steps=2)
    assert venv.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.NEXT_STEP
    venv.reset(seed=0)
    zero = np.zeros((2, 3), np.float32)
    venv.step(zero)
    _, _, terminated, truncated, info = venv.step(zero)
    assert (terminated | truncated).all() and list(info["steps"]) == [2, 2]
    _, reward, terminated, truncated, info = venv.step(zero)
    assert list(reward) == [0.0, 0.0] and not terminated.any() and not truncated.any()
    assert list(info["steps"]) == [0, 0]  # the step only reset them
    _, _, _, _, info = venv.step(zero)
    assert list(info["steps"]) == [1, 1]
    venv.close()


def test_same_seed_same_batches_and_a_reset_mask_resets_only_its_heads() -> None:
    runs = []
    for _ in range(2):
        venv = FixateVectorEnv(2, randomise={"kx": (100.0, 130.0), "noise_std": (0.0, 2.0)})
        first, _ = venv.reset(seed=11)
        after, *_ = venv.step(np.full((2, 3), 0.3, np.float32))
        runs.append((first, after))
        venv.close()
    for key in ("cam1", "cam2", "encoders"):
        np.testing.assert_array_equal(runs[0][0][key], runs[1][0][key])
        np.testing.assert_array_equal(runs[0][1][key], runs[1][1][key])
    assert not np.array_equal(runs[0][0]["cam1"][0], runs[0][0]["cam1"][1])  # own draws
    venv = FixateVectorEnv(2)
    venv.reset(seed=1)
    moved, *_ = venv.step(np.full((2, 3), 0.5, np.float32))
    obs, info = venv.reset(seed=1, options={"reset_mask": np.array([False, True])})
    np.testing.assert_array_equal(obs["encoders"][0], moved["encoders"][0])  # kept
    assert not np.array_equal(obs["encoders"][1], moved["encoders"][1])  # back at rest
    assert list(info["_steps"]) == [False, True]
    venv.close()


def test_one_sample_per_pixel_renders_the_same_scene_coarser() -> None:
    fine, coarse = FixateVectorEnv(1), FixateVectorEnv(1, supersample=1)
    (a, info_a), (b, info_b) = fine.reset(seed=3), coarse.reset(seed=3)
    assert not np.array_equal(a["cam1"], b["cam1"])
    np.testing.assert_allclose(info_a["offsets_px"], info_b["offsets_px"], atol=0.5)
    fine.close()
    coarse.close()


def test_bad_arguments_name_what_is_allowed() -> None:
    with pytest.raises(SettingsError, match="num_envs must be a whole number >= 1, got 0"):
        FixateVectorEnv(0)
    with pytest.raises(SettingsError, match="the marker scene only"):
        FixateVectorEnv(1, scene="textured_plane")
    venv = FixateVectorEnv(2)
    with pytest.raises(ValueError, match=r"reset_mask.*shape \(2,\)"):
        venv.reset(options={"reset_mask": np.array([True])})
    venv.reset(seed=0)
    with pytest.raises(ValueError, match=r"actions must have shape \(2, 3\)"):
        venv.step(np.zeros(3, np.float32))
    venv.close()


def test_the_device_path_steps_the_same_episodes_on_warps_cpu_device() -> None:
    """renderer="warp-cpu": the GPU's code (one Warp call for every head's two eyes), run on
    Warp's CPU device; the marker is where the OpenGL heads see it (two rasterisers)."""
    opengl, warp = FixateVectorEnv(2, renderer="opengl"), FixateVectorEnv(2, renderer="warp-cpu")
    assert "Warp on cpu" in warp.describe() and "OpenGL" in opengl.describe()
    action = np.full((2, 3), 0.3, np.float32)
    for venv in (opengl, warp):
        venv.reset(seed=4)
    ours, theirs = warp.step(action), opengl.step(action)
    np.testing.assert_array_equal(ours[0]["encoders"], theirs[0]["encoders"])  # same physics
    assert ours[-1]["found"].all() and theirs[-1]["found"].all()
    np.testing.assert_allclose(ours[-1]["offsets_px"], theirs[-1]["offsets_px"], atol=0.3)
    opengl.close()
    warp.close()
    with pytest.raises(SettingsError, match="renderer must be one of auto, opengl"):
        FixateVectorEnv(1, renderer="vulkan")
