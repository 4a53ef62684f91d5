"""Train a small policy on headsim/Fixate-v0 with stable-baselines3 (if installed).

Not part of the tests: ``pip install stable-baselines3`` first.  Two spawned
workers (EGL does not survive a fork), a multi-input PPO policy on the two
128 x 96 images and the encoders, a short run; then the trained policy and
the paper's servo are compared on the same seeded episodes.

    python examples/train_fixate_sb3.py [--steps 20000]
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

import gymnasium
import numpy as np

import headsim.envs
from headsim.envs.policies import ServoPolicy


def success(
    env: gymnasium.Env, act: Callable[[dict], np.ndarray], episodes: int = 20, limit: int = 10
) -> float:
    """Share of seeded episodes fixated within ``limit`` steps."""
    done = 0
    for seed in range(episodes):
        obs, _ = env.reset(seed=10_000 + seed)
        terminated = False
        for _ in range(limit):
            obs, _, terminated, truncated, _ = env.step(act(obs))
            if terminated or truncated:
                break
        done += bool(terminated)
    return done / episodes


def make() -> gymnasium.Env:
    return gymnasium.make(headsim.envs.FIXATE_ID, max_steps=30)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20_000)
    args = parser.parse_args()
    try:
        from stable_baselines3 import PPO
        from stable_baselines3.common.vec_env import SubprocVecEnv
    except ImportError:
        print("stable-baselines3 is not installed: pip install stable-baselines3", file=sys.stderr)
        return 3
    vec = SubprocVecEnv([make, make], start_method="spawn")
    model = PPO("MultiInputPolicy", vec, n_steps=256, batch_size=64, seed=0, verbose=1)
    model.learn(total_timesteps=args.steps)
    vec.close()
    env = make()
    learnt = success(env, lambda obs: model.predict(obs, deterministic=True)[0])
    servo = ServoPolicy(env.action_space, env.unwrapped.period_s)
    paper = success(env, servo)
    print(f"fixated within 10 steps: PPO {100 * learnt:.0f} %, paper servo {100 * paper:.0f} %")
    env.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
