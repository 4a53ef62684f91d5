"""headsim/Fixate-v0 vectorised: environment steps per second, batch renderer against classic.

In one run, for each ``num_envs``: :class:`headsim.envs.vector.FixateVectorEnv` (every
head's two 128 x 96 images ray-cast together by MuJoCo Warp) against Gymnasium's
``SyncVectorEnv`` of the same envs on the classic renderer, stepping seeded random
actions (autoresets included; the first reset, which builds Warp's kernels and scenes,
excluded).  Steps per second count every head's steps.

    python benchmarks/batch_env.py [--envs 1 16 64] [--steps 20] [--device cpu] [--json F]
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import gymnasium
import numpy as np

import headsim.envs
from headsim.envs.fixate import FixateEnv
from headsim.envs.vector import FixateVectorEnv
from headsim.files import write_json_atomic


def rate(venv: gymnasium.vector.VectorEnv, steps: int, seed: int) -> float:
    """Head-steps per second over ``steps`` vector steps of seeded random actions."""
    venv.reset(seed=seed)
    venv.step(np.zeros(venv.action_space.shape, np.float32))  # warm: scenes and kernels
    rng = np.random.default_rng(seed)
    start = time.perf_counter()
    for _ in range(steps):
        venv.step(rng.uniform(-0.3, 0.3, venv.action_space.shape).astype(np.float32))
    return venv.num_envs * steps / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, nargs="+", default=[1, 16, 64])
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--device", default="cpu", choices=("cpu", "cuda"))
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    figures: dict[str, Any] = {"id": headsim.envs.FIXATE_ID, "device": args.device}
    for n in args.envs:
        batch = FixateVectorEnv(n, device=args.device)
        batch_rate = rate(batch, args.steps, 0)
        stats = batch.session.stats
        batch.close()
        classic = gymnasium.vector.SyncVectorEnv([FixateEnv for _ in range(n)])
        classic_rate = rate(classic, args.steps, 0)
        classic.close()
        figures[f"num_envs_{n}"] = {
            "batch_steps_per_s": batch_rate,
            "classic_steps_per_s": classic_rate,
            "batch_over_classic": batch_rate / classic_rate,
            "warp_mean_batch": stats.mean_batch,
            "warp_largest": stats.largest,
        }
        print(
            f"num_envs {n:3d}: batch {batch_rate:7.1f} steps/s, classic {classic_rate:7.1f} "
            f"steps/s, ratio {batch_rate / classic_rate:.2f} (Warp: mean batch "
            f"{stats.mean_batch:.1f}, largest {stats.largest})",
            flush=True,
        )
    if args.json:
        write_json_atomic(args.json, figures)


if __name__ == "__main__":
    main()
