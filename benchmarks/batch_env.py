"""headsim/Fixate-v0 vectorised: head-steps per CPU-second, lockstep against SyncVectorEnv.

In one run, for each ``num_envs``: :class:`headsim.envs.vector.FixateVectorEnv` (lockstep
heads, both eyes of every head through one OpenGL context) against Gymnasium's
``SyncVectorEnv`` of single :class:`~headsim.envs.fixate.FixateEnv` s on the classic
renderer, both 128 x 96 per camera, stepping the same seeded random actions (autoresets
included; the first reset and step, which build models and contexts, excluded).  Blocks
of steps alternate between the two, so that a loaded machine weighs on both alike; each
side's figure is head-steps over the process's CPU seconds (llvmpipe's threads included).

Lockstep runs at the classic images' fidelity (2x2 supersampling: the same pixels) and,
separately, at one sample a pixel (``--supersample 1``, a quarter of the pixels, as the
issue's prototype rendered); the classic side always at 2x2.

The host's share: a profile of the lockstep steps, less the time inside OpenGL's draws
and reads (``mjr_render``, ``mjr_readPixels``), per head-step.

    python benchmarks/batch_env.py [--envs 1 16 64] [--steps 20] [--blocks 3] [--json F]
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import time
from typing import Any

import gymnasium
import numpy as np

import headsim.envs
from headsim.envs.fixate import FixateEnv
from headsim.envs.vector import FixateVectorEnv
from headsim.files import write_json_atomic

#: What a profile counts as rendering (OpenGL's work), not the host's.
GL_CALLS = ("mjr_render", "mjr_readPixels")


class Side:
    """One vector env, stepped in blocks: its head-steps and CPU seconds so far."""

    def __init__(self, venv: gymnasium.vector.VectorEnv, seed: int) -> None:
        self.venv = venv
        self.rng = np.random.default_rng(seed)
        venv.reset(seed=seed)
        venv.step(np.zeros(venv.action_space.shape, np.float32))  # warm: models, contexts
        self.head_steps = 0
        self.cpu_s = 0.0
        self.wall_s = 0.0
        self.opengl_s = 0.0  # lockstep only: CPU inside OpenGL's draws and reads

    def block(self, steps: int) -> None:
        shape = tuple(self.venv.action_space.shape or ())
        actions = self.rng.uniform(-0.3, 0.3, (steps, *shape))
        heads = getattr(self.venv, "heads", None)
        opengl = 0.0 if heads is None else heads.opengl_cpu_s
        cpu, wall = time.process_time(), time.perf_counter()
        for action in actions.astype(np.float32):
            self.venv.step(action)
        self.cpu_s += time.process_time() - cpu
        if heads is not None:
            self.opengl_s += heads.opengl_cpu_s - opengl
        self.wall_s += time.perf_counter() - wall
        self.head_steps += self.venv.num_envs * steps

    @property
    def rate(self) -> float:
        """Head-steps per CPU-second."""
        return self.head_steps / self.cpu_s


def host_ms_per_head_step(venv: FixateVectorEnv, steps: int, seed: int) -> dict[str, float]:
    """A profile of ``steps`` lockstep steps: ms per head-step in all, in OpenGL, and the rest."""
    rng = np.random.default_rng(seed)
    shape = tuple(venv.action_space.shape or ())
    actions = rng.uniform(-0.3, 0.3, (steps, *shape)).astype(np.float32)
    profile = cProfile.Profile(time.process_time)
    profile.enable()
    for action in actions:
        venv.step(action)
    profile.disable()
    stats = pstats.Stats(profile)
    total = max(float(s[3]) for s in stats.stats.values())  # type: ignore[attr-defined]
    gl = 0.0
    for (_, _, name), row in stats.stats.items():  # type: ignore[attr-defined]
        if any(call in str(name) for call in GL_CALLS):
            gl += float(row[2])
    per = 1e3 / (venv.num_envs * steps)
    return {"total_ms": total * per, "opengl_ms": gl * per, "host_ms": (total - gl) * per}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, nargs="+", default=[1, 16, 64])
    parser.add_argument("--steps", type=int, default=20, help="steps per block")
    parser.add_argument("--blocks", type=int, default=3)
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    figures: dict[str, Any] = {
        "id": headsim.envs.FIXATE_ID,
        "renderer": "classic OpenGL renderer on the CPU (lockstep: one context for all heads)",
        "load_average_at_start": os.getloadavg()[0],
        "cpus": os.cpu_count(),
    }
    for n in args.envs:
        sides = {
            "lockstep": Side(FixateVectorEnv(n), 0),
            "lockstep_1spp": Side(FixateVectorEnv(n, supersample=1), 0),
            "classic": Side(gymnasium.vector.SyncVectorEnv([FixateEnv for _ in range(n)]), 0),
        }
        for _ in range(args.blocks):
            for side in sides.values():
                side.block(args.steps)
        lockstep = sides["lockstep"].venv
        assert isinstance(lockstep, FixateVectorEnv)
        profile = host_ms_per_head_step(lockstep, args.steps, 1)
        classic = sides["classic"].rate
        row = {
            **{f"{name}_head_steps_per_cpu_s": side.rate for name, side in sides.items()},
            **{
                f"{name}_head_steps_per_wall_s": s.head_steps / s.wall_s
                for name, s in sides.items()
            },
            "lockstep_over_classic": sides["lockstep"].rate / classic,
            "lockstep_1spp_over_classic": sides["lockstep_1spp"].rate / classic,
            "lockstep_profile_ms_per_head_step": profile,
            # The profiler's own cost inflates the host's share: the unprofiled blocks' CPU
            # less their CPU inside OpenGL (timed around each draw and read).
            **{
                f"{name}_host_ms_per_head_step": 1e3 * (s.cpu_s - s.opengl_s) / s.head_steps
                for name, s in sides.items()
                if name != "classic"
            },
        }
        figures[f"num_envs_{n}"] = row
        for side in sides.values():
            side.venv.close()
        print(
            f"num_envs {n:3d}: head-steps per CPU-second: lockstep {sides['lockstep'].rate:7.1f} "
            f"(1 spp {sides['lockstep_1spp'].rate:7.1f}), SyncVectorEnv {classic:7.1f}; "
            f"ratios {row['lockstep_over_classic']:.2f} (1 spp "
            f"{row['lockstep_1spp_over_classic']:.2f}); lockstep per head-step "
            f"{profile['total_ms']:.3f} ms, of it OpenGL {profile['opengl_ms']:.3f}, "
            f"host {profile['host_ms']:.3f}; unprofiled host {row['lockstep_host_ms_per_head_step']:.3f} "
            f"(1 spp {row['lockstep_1spp_host_ms_per_head_step']:.3f})",
            flush=True,
        )
    figures["load_average_at_end"] = os.getloadavg()[0]
    print(
        f"load average (1 min) {figures['load_average_at_start']:.2f} at start, "
        f"{figures['load_average_at_end']:.2f} at end, {figures['cpus']} CPUs"
    )
    if args.json:
        write_json_atomic(args.json, figures)


if __name__ == "__main__":
    main()
