"""headsim/Fixate-v0: environment steps per second per core, and the reference policies.

Steps per second: one process (one core), 128 x 96 images from both cameras,
zero actions (the environment alone) and the paper-servo policy (environment
plus the policy's two marker detections); resets excluded.  Policies: over
``--episodes`` seeded episodes, the share that fixates within 10 steps; the
servo policy probes its Jacobian in its first episode (3 extra steps) and
keeps it, so the figure is given with and without that first episode.  Also
checks the API: gymnasium's check_env, two same-seed resets, 2 spawned workers.

The textured plane (``scene="textured_plane"``): its step time over the marker
scene's (zero actions, interleaved blocks in this process, resets excluded), and
the image-based vergence policy's share of pink-noise episodes within tolerance
(1 px at eye 2's focal length) in 10 steps.

    python benchmarks/gym_env.py [--episodes 100] [--json out.json]
"""

from __future__ import annotations

import argparse
import time

import gymnasium
import numpy as np
from gymnasium.utils.env_checker import check_env

import headsim.envs
from headsim.envs.fixate import FixateEnv
from headsim.envs.policies import RandomPolicy, ServoPolicy, VergencePolicy
from headsim.files import write_json_atomic

ID = headsim.envs.FIXATE_ID


def steps_per_second(env: gymnasium.Env, policy: object | None, steps: int) -> float:
    obs, _ = env.reset(seed=0)
    elapsed, done = 0.0, 0
    while done < steps:
        start = time.perf_counter()
        action = np.zeros(3, np.float32) if policy is None else policy(obs)  # type: ignore[operator]
        obs, _, terminated, truncated, _ = env.step(action)
        elapsed += time.perf_counter() - start
        done += 1
        if terminated or truncated:
            obs, _ = env.reset(seed=done)
    return done / elapsed


def step_over_render_ratio(
    env: gymnasium.Env, blocks: int = 6, size: int = 50
) -> tuple[float, float]:
    """Env step time over a bare stereo render's (the same renderer), interleaved in blocks.

    A ratio survives a loaded machine better than a rate.  Returns (ratio,
    bare stereo renders per second).
    """
    env.reset(seed=0)
    sim = env.unwrapped._sim
    zero = np.zeros(3, np.float32)
    step_s = render_s = 0.0
    for _ in range(blocks):
        start = time.perf_counter()
        for _ in range(size):
            if any(env.step(zero)[2:4]):
                env.reset(seed=0)
        step_s += time.perf_counter() - start
        start = time.perf_counter()
        for _ in range(size):
            sim.render(1)
            sim.render(2)
        render_s += time.perf_counter() - start
    return step_s / render_s, blocks * size / render_s


def plane_over_marker_step(blocks: int = 6, size: int = 50) -> tuple[float, float, float]:
    """The textured plane's env step time over the marker scene's: zero actions, 128 x 96,
    blocks interleaved, each step timed alone (no resets).  Returns (ratio, marker ms,
    plane ms) per step."""
    envs = [FixateEnv(max_steps=10**6), FixateEnv(scene="textured_plane", max_steps=10**6)]
    zero = np.zeros(3, np.float32)
    totals = [0.0, 0.0]
    for env in envs:
        env.reset(seed=0)
        env.step(zero)  # the renderer made, the texture uploaded
    for _ in range(blocks):
        for index, env in enumerate(envs):
            for _ in range(size):
                start = time.perf_counter()
                env.step(zero)
                totals[index] += time.perf_counter() - start
    for env in envs:
        env.close()
    marker_ms, plane_ms = (1000 * t / (blocks * size) for t in totals)
    return plane_ms / marker_ms, marker_ms, plane_ms


def episodes(env: gymnasium.Env, policy: object, count: int, limit: int = 10) -> list[int | None]:
    lengths: list[int | None] = []
    for seed in range(count):
        obs, _ = env.reset(seed=1000 + seed)
        policy.reset()  # type: ignore[attr-defined]
        length = None
        for step in range(1, limit + 1):
            obs, _, terminated, truncated, _ = env.step(policy(obs))  # type: ignore[operator]
            if terminated:
                length = step
                break
            if truncated:
                break
        lengths.append(length)
    return lengths


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=100)
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--json")
    args = parser.parse_args()
    env = gymnasium.make(ID)
    check_env(env.unwrapped)
    first, _ = env.reset(seed=5)
    second, _ = env.reset(seed=5)
    identical = all(np.array_equal(first[k], second[k]) for k in first)
    vec = gymnasium.make_vec(
        ID, num_envs=2, vectorization_mode="async", vector_kwargs={"context": "spawn"}
    )
    vec.reset(seed=[0, 1])
    for _ in range(5):
        vec.step(vec.action_space.sample())
    vec.close()
    servo = ServoPolicy(env.action_space, env.unwrapped.period_s)
    results: dict[str, float] = {
        "check_env": 1.0,
        "same_seed_identical": float(identical),
        "vector_env_2_spawned_workers": 1.0,
        "env_steps_per_s_zero_action": steps_per_second(env, None, args.steps),
        "env_steps_per_s_with_servo_policy": steps_per_second(env, servo, args.steps),
    }
    ratio, renders = step_over_render_ratio(env)
    results["env_step_over_bare_stereo_render"] = ratio
    results["bare_stereo_renders_per_s"] = renders
    servo = ServoPolicy(env.action_space, env.unwrapped.period_s)
    lengths = episodes(env, servo, args.episodes)
    fixated = [n is not None for n in lengths]
    results["servo_fixated_within_10_steps_pct"] = 100 * float(np.mean(fixated))
    results["servo_fixated_within_10_steps_pct_after_first"] = 100 * float(np.mean(fixated[1:]))
    results["servo_mean_steps_to_fixation"] = float(np.mean([n for n in lengths if n is not None]))
    random_lengths = episodes(env, RandomPolicy(env.action_space, seed=0), min(args.episodes, 20))
    results["random_fixated_within_10_steps_pct"] = 100 * float(
        np.mean([n is not None for n in random_lengths])
    )
    env.close()
    ratio, marker_ms, plane_ms = plane_over_marker_step()
    results["plane_step_over_marker_step"] = ratio
    results["marker_step_ms"] = marker_ms
    results["plane_step_ms"] = plane_ms
    plane = FixateEnv(scene="textured_plane")
    verging = episodes(plane, VergencePolicy(plane.action_space, plane.period_s), args.episodes)
    verged = [n for n in verging if n is not None]
    results["vergence_policy_within_tolerance_in_10_steps_pct"] = 100 * len(verged) / len(verging)
    results["vergence_policy_mean_steps"] = float(np.mean(verged)) if verged else float("nan")
    plane.close()
    for key, value in results.items():
        print(f"{key:<48} {value:10.2f}")
    if args.json:
        write_json_atomic(args.json, results)


if __name__ == "__main__":
    main()
