"""Lockstep heads on a device: images and head-steps per second through MuJoCo Warp.

The device loop: every head's motors in numpy and physics in one ``mujoco.batch``
rollout on the host (``--threads``), the poses uploaded, both eyes of every head cast
in one Warp call with 2 x 2 rays a pixel, and the red marker's sums reduced on the
device (only (w, u, v) per image copied back).  For each image size and number of
worlds: images per second of the cast alone, head-steps per second of the whole loop,
and where a step's time goes (host physics, upload and cast, the device's reduction).
Then the largest number of worlds that fits, doubling from the last until the device
refuses (``--max-worlds`` bounds the search).

Meant for a GPU (``--device cuda``); without one it says it did not run.  ``--device
cpu`` runs the same code on Warp's CPU device (slow: small figures only).

    python benchmarks/batch_device.py [--worlds 1024 8192] [--sizes 128x96 640x480]
        [--steps 5] [--device cuda] [--json F]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any

import numpy as np

from headsim.envs.fixate import TARGET_BODY, FixateEnv
from headsim.files import write_json_atomic
from headsim.live.paths import Static
from headsim.lockstep import LockstepHeads
from headsim.lockstep.warp_eyes import WarpEyes
from headsim.sim.batch import BatchError, check_device


def heads_and_eyes(
    n: int, size: tuple[int, int], device: str, threads: int
) -> tuple[LockstepHeads, WarpEyes]:
    """``n`` Gym-env heads with ``size`` images, reset before seeded targets, and their eyes."""
    env = FixateEnv(width=size[0], height=size[1])
    settings = env.base_settings
    heads = LockstepHeads(
        n, settings, target_body=TARGET_BODY, prepare=env.prepare_model, threads=threads
    )
    rng = np.random.default_rng(0)
    targets = [Static((x, y, 0.42)) for x, y in rng.uniform((-0.1, 0.6), (0.1, 1.4), (n, 2))]
    # No OpenGL drawing: the device's eyes are what is measured.
    heads.reset(np.arange(n), [settings] * n, targets, images=False)
    cam = settings.cameras[0]
    eyes = WarpEyes(heads.model(0), heads.camera_names(0), (cam.width, cam.height), n, device)
    return heads, eyes


def measure(n: int, size: tuple[int, int], device: str, steps: int, threads: int) -> dict[str, Any]:
    heads, eyes = heads_and_eyes(n, size, device, threads)
    ids = np.arange(n)
    rng = np.random.default_rng(1)
    eyes.cast(heads.poses())  # warm: kernels compiled, BVH built
    eyes.marker_sums("red")
    physics = cast = reduce = 0.0
    for _ in range(steps):
        heads.command_velocity(ids, rng.uniform(-1.0, 1.0, (n, 3)))
        start = time.perf_counter()
        heads.capture(ids, images=False)
        middle = time.perf_counter()
        eyes.cast(heads.poses())
        eyes.synchronize()  # time the cast, not its launch
        end = time.perf_counter()
        sums = eyes.marker_sums("red")
        physics, cast, reduce = (
            physics + middle - start,
            cast + end - middle,
            reduce + time.perf_counter() - end,
        )
    total = physics + cast + reduce
    seen = float(np.mean(sums[..., 0] > 0))
    return {
        "worlds": n,
        "images_per_s": 2 * n * steps / cast,
        "head_steps_per_s": n * steps / total,
        "share_host_physics": physics / total,
        "share_upload_and_cast": cast / total,
        "share_device_reduction": reduce / total,
        "images_with_the_marker": seen,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, nargs="+", default=[1024, 8192])
    parser.add_argument("--sizes", nargs="+", default=["128x96", "640x480"])
    parser.add_argument("--steps", type=int, default=5)
    parser.add_argument("--device", default="cuda", choices=("cpu", "cuda"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--max-worlds", type=int, default=65536)
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    try:
        check_device(args.device)
    except BatchError as err:
        print(f"batch_device did not run: {err}")
        if args.json:
            write_json_atomic(args.json, {"did_not_run": str(err)})
        sys.exit(0)
    figures: dict[str, Any] = {"device": args.device, "threads": args.threads}
    for text in args.sizes:
        width, height = (int(v) for v in text.split("x"))
        rows = []
        for n in args.worlds:
            row = measure(n, (width, height), args.device, args.steps, args.threads)
            rows.append(row)
            print(
                f"{text} x {n} worlds: {row['images_per_s']:,.0f} images/s, "
                f"{row['head_steps_per_s']:,.0f} head-steps/s (host physics "
                f"{row['share_host_physics']:.0%}, cast {row['share_upload_and_cast']:.0%}, "
                f"reduction {row['share_device_reduction']:.0%})",
                flush=True,
            )
        largest = max(args.worlds)
        while largest * 2 <= args.max_worlds:
            try:
                measure(largest * 2, (width, height), args.device, 1, args.threads)
            except Exception as err:  # the device's memory: the last that fitted stands
                print(f"{text}: {largest * 2} worlds did not fit ({type(err).__name__})")
                break
            largest *= 2
        print(f"{text}: the largest batch that ran: {largest} worlds", flush=True)
        figures[text] = {"rows": rows, "largest_worlds": largest}
    if args.json:
        write_json_atomic(args.json, figures)


if __name__ == "__main__":
    main()
