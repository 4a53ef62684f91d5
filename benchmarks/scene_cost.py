"""What a textured room costs: 640x480 frames of natural_field's room (as shipped, and
with shadows on) over the marker quick start's scene, and the experiment's wall time per
target of ``natural_field --fast`` over ``quickstart --fast``, in one run.

Both scenarios' heads as loaded (the realistic preset: distortion and noise); the
renders, and the runs, are interleaved so that the machine's load falls on both alike.
Not a test: speed depends on the machine.

    python benchmarks/scene_cost.py [--frames 40] [--runs 3] [--json out.json]
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.files import write_json_atomic
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario
from headsim.sim.simulator import HeadSim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--runs", type=int, default=3, help="fast runs of each scenario")
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    markers = load_scenario("quickstart", fast=True)
    field = load_scenario("natural_field", fast=True)
    room = field.scene.room
    assert room is not None
    shadowed = replace(room, light=replace(room.light, shadows=True))
    sims = {
        "markers (quickstart)": HeadSim("default", markers.settings),
        "room (natural_field)": HeadSim("default", field.settings, room=room),
        "room, shadows on": HeadSim("default", field.settings, room=shadowed),
    }
    times: dict[str, list[float]] = {name: [] for name in sims}
    try:
        for sim in sims.values():
            for camera in (1, 2):  # warm-up: GL contexts, texture upload, shaders
                sim.render(camera)
        for i in range(args.frames):
            for name, sim in sims.items():
                start = time.perf_counter()
                sim.render(1 + i % 2)
                times[name].append((time.perf_counter() - start) * 1e3)
    finally:
        for sim in sims.values():
            sim.close()
    base = statistics.median(times["markers (quickstart)"])
    out: dict[str, dict[str, float]] = {}
    for name, values in times.items():
        median = statistics.median(values)
        out[name] = {"median_ms": median, "ratio": median / base, "frames": len(values)}
        print(f"{name:24s} {median:7.2f} ms per 640x480 frame  x{median / base:.2f}")
    per_target: dict[str, list[float]] = {"quickstart": [], "natural_field": []}
    for _ in range(args.runs):
        for name in per_target:
            result = run_scenario(load_scenario(name, fast=True))
            # A markerless target may fail honestly (its cause counted); its time counts too.
            assert result.records and (result.ok or name == "natural_field"), result.failures
            per_target[name].append(result.timing_s["experiment"] / len(result.records))
    runs = {name: statistics.median(values) for name, values in per_target.items()}
    ratio = runs["natural_field"] / runs["quickstart"]
    print(
        f"experiment per target, --fast: quickstart {runs['quickstart']:.3f} s, "
        f"natural_field {runs['natural_field']:.3f} s  x{ratio:.2f}"
    )
    out["experiment_per_target_s"] = {**runs, "ratio": ratio, "runs": args.runs}
    if args.json:
        write_json_atomic(args.json, out)


if __name__ == "__main__":
    main()
