"""The reference policies on headsim/Fixate-v0: the paper's servo fixates, random ones truncate."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import headsim.envs
from headsim.envs.policies import RandomPolicy, ServoPolicy

ID = headsim.envs.FIXATE_ID


@pytest.mark.parametrize("units", ["normalised", "physical"])
def test_paper_servo_policy_fixates_and_the_episode_terminates(units: str) -> None:
    env = gymnasium.make(ID, action_space=units)
    policy = ServoPolicy(env.action_space, env.unwrapped.period_s)
    lengths = []
    for seed in range(4):
        obs, info = env.reset(seed=seed)
        policy.reset()
        step = 0
        while step < 30:
            step += 1
            obs, reward, terminated, truncated, info = env.step(policy(obs))
            if terminated or truncated:
                break
        assert terminated and not truncated, f"seed {seed}: not fixated in {step} steps"
        assert np.all(np.abs(info["offsets_px"]) <= 1.0)
        assert reward > -0.02
        lengths.append(step)
    assert max(lengths[1:]) <= 10  # the first episode also probes the Jacobian
    env.close()


def test_random_policy_truncates_at_the_step_limit_and_rewards_are_bounded() -> None:
    env = gymnasium.make(ID, max_steps=5, reward="position")
    policy = RandomPolicy(env.action_space, seed=1)
    obs, _ = env.reset(seed=0)
    for _ in range(5):
        obs, reward, terminated, truncated, _ = env.step(policy(obs))
        assert -1.0 <= reward <= 0.0
        assert env.observation_space.contains(obs)
        if terminated:
            break
    assert truncated or terminated
    env.close()
