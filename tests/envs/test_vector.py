"""headsim/Fixate-v0 vectorised on the batch renderer (MuJoCo Warp, CPU here): Gymnasium
1.x's vector API, next-step autoreset, seeding, and heads that see what they see alone."""

from __future__ import annotations

import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import headsim.envs
from headsim.envs.fixate import FixateEnv
from headsim.envs.vector import FixateVectorEnv
from headsim.sim.settings import SettingsError

ID = headsim.envs.FIXATE_ID


def test_make_vec_builds_batched_spaces_and_heads_see_what_they_see_alone() -> None:
    venv = gymnasium.make_vec(ID, num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(venv.unwrapped, FixateVectorEnv)
    assert venv.observation_space["cam1"].shape == (3, 96, 128, 3)
    assert venv.action_space.shape == (3, 3)
    obs, info = venv.reset(seed=5)
    action = np.tile(np.array([0.2, -0.1, 0.3], np.float32), (3, 1))
    obs, reward, _, _, info = venv.step(action)
    assert obs["cam1"].shape == (3, 96, 128, 3) and reward.shape == (3,)
    assert info["found"].all() and info["_found"].all()
    for i in range(3):  # the same episode on the classic renderer
        env = FixateEnv()
        env.reset(seed=5 + i)
        alone, _, _, _, alone_info = env.step(action[i])
        np.testing.assert_array_equal(obs["encoders"][i], alone["encoders"])  # same physics
        # Two renderers: the marker's offsets agree to a fraction of a pixel.
        np.testing.assert_allclose(info["offsets_px"][i], alone_info["offsets_px"], atol=0.3)
        env.close()
    session = venv.unwrapped.session
    # Each capture asks for camera 1 of every head, then camera 2: one Warp call each.
    assert session.stats.largest == 3 and session.stats.calls <= session.stats.images / 2
    venv.close()


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


def test_one_sub_env_passes_gymnasiums_checker_inside_the_batch_session() -> None:
    venv = FixateVectorEnv(1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        venv.session.run([lambda: check_env(venv.envs[0])])
    assert [str(w.message) for w in caught] == []
    assert venv.session.stats.images > 0  # its images came from the batch renderer
    venv.close()


def test_bad_arguments_name_what_is_allowed() -> None:
    with pytest.raises(SettingsError, match="num_envs must be a whole number >= 1, got 0"):
        FixateVectorEnv(0)
    with pytest.raises(ValueError, match=r"reset_mask.*shape \(2,\)"):
        FixateVectorEnv(2).reset(options={"reset_mask": np.array([True])})
