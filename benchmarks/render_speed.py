"""Milliseconds per rendered eye-camera frame for the default scene.

Prints figures (median and 90th percentile over --frames renders, after a
warm-up) for 640x480 and 320x240 ideal cameras and the paper's distorted
cameras.  Not a test: speed depends on the machine.

    python benchmarks/render_speed.py [--frames 60] [--json out.json]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.files import write_json_atomic
from headsim.sim.imperfections.noise import GaussianNoise
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim

CASES = {
    "640x480 ideal": HeadSettings(),
    "320x240 ideal": HeadSettings(
        cameras=(CameraSettings(width=320, height=240, kx=289.7, ky=289.7),) * 2
    ),
    "640x480 paper (distorted)": paper_head(),
    "640x480 ideal + noise": HeadSettings(cameras=(CameraSettings(noise_std=2.0),) * 2),
}


def time_case(settings: HeadSettings, frames: int) -> dict[str, float]:
    with HeadSim("default", settings) as sim:
        sim.move(eye=0.05)
        for camera in (1, 2):  # warm-up: GL contexts, shader compilation
            sim.render(camera)
        times = []
        for i in range(frames):
            start = time.perf_counter()
            sim.render(1 + i % 2)
            times.append((time.perf_counter() - start) * 1e3)
    times.sort()
    return {
        "median_ms": statistics.median(times),
        "p90_ms": times[int(0.9 * (len(times) - 1))],
        "frames": frames,
    }


def time_noise(frames: int) -> dict[str, float]:
    """Noise alone on a 640x480 frame (std 2): the alias sampler, and float samples as before."""
    image = np.full((480, 640, 3), 128, dtype=np.uint8)
    noise = GaussianNoise.of(2.0)
    rng = np.random.default_rng(0)

    def float_samples() -> np.ndarray:
        z = rng.standard_normal(size=image.shape, dtype=np.float32)
        return np.clip(np.rint(image + np.float32(2.0) * z), 0, 255).astype(np.uint8)

    figures = {}
    for name, add in (
        ("alias_ms", lambda k: noise.apply(image, (0, 0), k)),
        ("float_ms", lambda k: float_samples()),
    ):
        times = []
        for k in range(frames):
            start = time.perf_counter()
            add(k)
            times.append((time.perf_counter() - start) * 1e3)
        figures[name] = statistics.median(times)
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--json", help="also write the figures to this JSON file")
    args = parser.parse_args()
    print(
        f"MUJOCO_GL={os.environ.get('MUJOCO_GL')}, {os.cpu_count()} CPUs, {args.frames} frames per case"
    )
    print(f"{'case':28s} {'median ms':>10s} {'p90 ms':>8s}")
    results = {}
    for name, settings in CASES.items():
        figures = time_case(settings, args.frames)
        results[name] = figures
        print(f"{name:28s} {figures['median_ms']:10.1f} {figures['p90_ms']:8.1f}")
    noise = time_noise(max(args.frames, 100))
    results["noise 640x480"] = noise
    print(
        f"{'noise only, 640x480':28s} {noise['alias_ms']:10.2f} ms "
        f"(float samples as before: {noise['float_ms']:.1f} ms)"
    )
    if args.json:
        write_json_atomic(args.json, results)


if __name__ == "__main__":
    main()
