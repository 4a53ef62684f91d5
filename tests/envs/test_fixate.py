"""headsim/Fixate-v0: Gymnasium's API check, seeding, rewards, bad options, spawned vector envs."""

from __future__ import annotations

import warnings
from dataclasses import replace

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import headsim.envs
from headsim.envs.fixate import MOTOR_SPEED_LIMITS_RAD_S
from headsim.envs.policies import ServoPolicy
from headsim.geometry.kinematics import head_to_world
from headsim.paper import ENCODER_RESOLUTION_RAD
from headsim.sim.settings import HeadBelief, SettingsError

ID = headsim.envs.FIXATE_ID


def test_env_passes_gymnasiums_checker_without_a_warning() -> None:
    env = gymnasium.make(ID)
    assert env.action_space == gymnasium.spaces.Box(-1.0, 1.0, (3,), np.float32)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert [str(w.message) for w in caught] == []
    env.close()


def test_a_normalised_action_commands_the_share_of_each_motors_speed_limit() -> None:
    """One unit of the default action is the limit; the physical space takes rad/s."""
    moved = {}
    for units, action in (("normalised", [0.5, -0.25, 0.1]), ("physical", [1.5, -0.75, 0.8])):
        env = gymnasium.make(ID, action_space=units)
        env.reset(seed=4)
        moved[units] = env.step(np.array(action, np.float32))[0]["encoders"]
        env.close()
    np.testing.assert_array_equal(moved["normalised"], moved["physical"])
    assert np.all(np.abs(moved["physical"]) > 0)
    physical = gymnasium.make(ID, action_space="physical")
    np.testing.assert_array_equal(physical.action_space.high, MOTOR_SPEED_LIMITS_RAD_S)
    np.testing.assert_array_equal(physical.unwrapped.action_scale_rad_s, np.ones(3))
    with pytest.warns(UserWarning, match="symmetric and normalized"):
        check_env(physical.unwrapped)  # the checker's advice, taken by the default
    physical.close()


def test_same_seed_gives_identical_observations_and_another_seed_does_not() -> None:
    env = gymnasium.make(
        ID,
        randomise={
            "kx": (100.0, 130.0),
            "mount_yaw_rad": (-0.02, 0.02),
            "nodal_offset_m": (0.01, 0.03),  # the realistic head's optical centres
        },
    )
    first, _ = env.reset(seed=7)
    drawn = [c.nodal_offset_m for c in env.unwrapped._settings.cameras]
    assert all(0.01 <= n <= 0.03 for n in drawn) and drawn[0] != drawn[1]
    action = np.array([0.3, -0.2, 1.0], np.float32)
    after_first = env.step(action)[0]
    other, _ = env.reset(seed=8)
    second, _ = env.reset(seed=7)
    after_second = env.step(action)[0]
    for key in ("cam1", "cam2", "encoders"):
        np.testing.assert_array_equal(first[key], second[key])
        np.testing.assert_array_equal(after_first[key], after_second[key])
    assert not np.array_equal(first["cam1"], other["cam1"])
    assert first["cam1"].shape == (96, 128, 3) and first["cam1"].dtype == np.uint8
    env.close()


def test_position_reward_is_small_when_fixated() -> None:
    env = gymnasium.make(ID, reward="position")
    policy = ServoPolicy(env.action_space, env.unwrapped.period_s)
    obs, _ = env.reset(seed=3)
    first = env.step(np.zeros(3, np.float32))[1]
    reward, terminated = first, False
    for _ in range(30):
        obs, reward, terminated, _, _ = env.step(policy(obs))
        if terminated:
            break
    assert terminated
    assert first < -0.5  # eyes parallel: no estimate yet
    # 1 px at 128 x 96 is 8.6 mrad of vergence: Model 1 within 10 % of the distance.
    assert -0.1 < reward <= 0.0
    env.close()


def test_bad_options_name_the_field() -> None:
    with pytest.raises(SettingsError, match="unknown field 'focal'"):
        gymnasium.make(ID, randomise={"focal": (1, 2)})
    with pytest.raises(
        SettingsError, match="reward for scene 'marker' must be one of offsets, position"
    ):
        gymnasium.make(ID, reward="distance")
    with pytest.raises(SettingsError, match="action_space must be one of normalised, physical"):
        gymnasium.make(ID, action_space="rad/s")


def test_vector_env_runs_two_spawned_workers() -> None:
    envs = gymnasium.make_vec(
        ID, num_envs=2, vectorization_mode="async", vector_kwargs={"context": "spawn"}
    )
    try:
        obs, _ = envs.reset(seed=[1, 2])
        assert obs["cam1"].shape == (2, 96, 128, 3)
        assert not np.array_equal(obs["cam1"][0], obs["cam1"][1])
        for _ in range(3):
            obs, rewards, _, _, _ = envs.step(envs.action_space.sample())
        assert rewards.shape == (2,) and obs["encoders"].shape == (2, 3)
    finally:
        envs.close()


def test_position_reward_is_the_heads_estimate_with_its_belief_and_no_truth_is_observed() -> None:
    """Same true head and target, two beliefs: identical observations, the estimate and the
    position reward move with the believed baseline (they would not with the true one)."""
    design = HeadBelief()
    wider = replace(design, baseline_m=1.2 * design.baseline_m)
    runs, spaces = {}, []
    for name, belief in (("design", design), ("wider", wider)):
        env = gymnasium.make(ID, reward="position", belief=belief)
        spaces.append(env.observation_space)
        policy = ServoPolicy(env.action_space, env.unwrapped.period_s)
        obs, info = env.reset(seed=3)
        steps = []
        for _ in range(12):
            obs, reward, terminated, _, info = env.step(policy(obs))
            steps.append((obs, reward, info, env.unwrapped._frame.truth_joints_rad))
            if terminated:
                break
        assert terminated
        runs[name] = steps
        env.close()
    assert spaces[0] == spaces[1]
    assert set(spaces[0].keys()) == set(runs["design"][-1][0]) == {"cam1", "cam2", "encoders"}
    true_off_counts = []
    for (obs_a, _, info_a, joints), (obs_b, _, info_b, _) in zip(*runs.values(), strict=True):
        for key in obs_a:
            np.testing.assert_array_equal(obs_a[key], obs_b[key])
        np.testing.assert_array_equal(info_a["truth_world_m"], info_b["truth_world_m"])
        # The encoders are readings (whole counts), not the true joint angles.
        counts = obs_a["encoders"].astype(float) / ENCODER_RESOLUTION_RAD
        np.testing.assert_allclose(counts, np.round(counts), atol=0.01)
        true_off_counts.append(np.max(np.abs(joints / ENCODER_RESOLUTION_RAD - counts)))
    assert max(true_off_counts) > 0.05
    (obs, reward_a, info_a, _), (_, reward_b, info_b, _) = runs["design"][-1], runs["wider"][-1]
    yaw, pitch, _ = obs["encoders"].astype(float)
    eyes = head_to_world(np.zeros(3), yaw, pitch, design.neck_d1_m, design.neck_a2_m)
    reach = [np.linalg.norm(info["estimate_world_m"] - eyes) for info in (info_a, info_b)]
    assert reach[1] / reach[0] == pytest.approx(1.2, rel=1e-6)  # float32 encoders
    truth = info_a["truth_world_m"]
    distance = np.linalg.norm(truth - np.array([0.0, 0.0, 0.21]))
    for reward, info in ((reward_a, info_a), (reward_b, info_b)):
        expected = -min(np.linalg.norm(info["estimate_world_m"] - truth) / distance, 1.0)
        assert reward == pytest.approx(expected, rel=1e-9)
    assert reward_a > -0.1 and reward_b < reward_a - 0.1  # 20 % too wide: ~20 % too far


def test_a_randomised_baseline_moves_the_truth_and_not_the_belief() -> None:
    """Unless given a belief, the head believes its design: a drawn baseline is not believed."""
    env = gymnasium.make(ID, randomise={"baseline_m": (0.14, 0.16)})
    env.reset(seed=3)
    settings = env.unwrapped._settings
    design = env.unwrapped.base_settings.baseline_m
    assert settings.baseline_m != design and 0.14 <= settings.baseline_m <= 0.16
    assert settings.believed.baseline_m == design
    assert set(env.unwrapped.belief_sources.values()) == {"design"}
    env.close()
    told = gymnasium.make(ID, belief=HeadBelief(baseline_m=0.151))
    assert set(told.unwrapped.belief_sources.values()) == {"given"}
    told.reset(seed=3)
    assert told.unwrapped._settings.believed.baseline_m == 0.151
    told.close()
