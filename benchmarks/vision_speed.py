"""Milliseconds per call of each detector in headsim.vision on rendered 640x480 images.

Each detector runs on an image of its own scene (ideal cameras; the target in
view) and, where it matters, on one without its target (the LOST path can
cost more than the found one).  Prints median and 90th percentile over
--calls calls after a warm-up.  Not a test: speed depends on the machine.

    python benchmarks/vision_speed.py [--calls 50] [--json out.json]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.files import write_json_atomic
from headsim.sim import names
from headsim.sim.settings import ideal_head
from headsim.sim.simulator import HeadSim
from headsim.vision.chessboard import find_chessboard
from headsim.vision.crosses import find_cross_point
from headsim.vision.markers import find_marker, find_markers

OBJECT_COLOURS = dict(
    zip(names.RELATIVE_OBJECTS, ("red", "green", "blue", "yellow", "magenta", "cyan"), strict=True)
)


def render(scene: str) -> np.ndarray:
    with HeadSim(scene, ideal_head()) as sim:
        sim.move(eye=0.05)
        return sim.render(1)


def time_calls(call: Callable[[], object], calls: int) -> dict[str, float]:
    call()  # warm-up
    times = []
    for _ in range(calls):
        start = time.perf_counter()
        call()
        times.append((time.perf_counter() - start) * 1e3)
    times.sort()
    return {
        "median_ms": statistics.median(times),
        "p90_ms": times[int(0.9 * (len(times) - 1))],
        "calls": calls,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=50)
    parser.add_argument("--json", help="also write the figures to this JSON file")
    args = parser.parse_args()
    images = {scene: render(scene) for scene in ("default", "blocks", "chessboard")}
    cases: dict[str, Callable[[], object]] = {
        "find_marker (found)": lambda: find_marker(images["default"], "red"),
        "find_marker (lost)": lambda: find_marker(images["chessboard"], "red"),
        "find_markers (6 objects)": lambda: find_markers(images["blocks"], OBJECT_COLOURS),
        "find_chessboard (found)": lambda: find_chessboard(images["chessboard"]),
        "find_chessboard (lost)": lambda: find_chessboard(images["blocks"]),
        "find_cross_point (found)": lambda: find_cross_point(images["blocks"]),
        "find_cross_point (lost)": lambda: find_cross_point(images["default"]),
    }
    print(f"MUJOCO_GL={os.environ.get('MUJOCO_GL')}, {os.cpu_count()} CPUs, 640x480 images")
    print(f"{'detector':28s} {'median ms':>10s} {'p90 ms':>8s}")
    results = {}
    for name, call in cases.items():
        figures = time_calls(call, args.calls)
        results[name] = figures
        print(f"{name:28s} {figures['median_ms']:10.2f} {figures['p90_ms']:8.2f}")
    if args.json:
        write_json_atomic(args.json, results)


if __name__ == "__main__":
    main()
