"""Where lockstep Model 2's CPU goes: OpenGL's draws and reads against the host's share.

The quick start's fast variant over ``--seeds`` seeds (each seed's head, its targets, the
classic calibration's knowledge): every target of every seed a head of one
:class:`~headsim.lockstep.settled.SettledHeads`, measured together.  CPU seconds of this
process (llvmpipe's threads included) split into OpenGL's (``opengl_cpu_s``) and the
rest: settling, finishing images (lens, noise), detection, the servo's law and the
estimator.  Per eye image and per head-step (one image of one head).

    python benchmarks/lockstep_servo_host.py [--seeds 8]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import numpy as np

import headsim  # noqa: F401  (chooses MUJOCO_GL before mujoco loads)
from headsim.lockstep.model2_run import scenario_targets
from headsim.lockstep.servo import HeadJob, measure_model2_heads
from headsim.lockstep.settled import SettledHeads
from headsim.runs.calibrate import calibrate
from headsim.runs.context import model2_config, servo_config
from headsim.runs.events import Hub
from headsim.scenario.loading import load_scenario


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--profile", type=int, default=12, help="rows of the profile shown")
    args = parser.parse_args()
    jobs, settings, places = [], [], []
    for seed in range(args.seeds):
        scenario = load_scenario("quickstart", fast=True, seed=seed)
        run, _ = calibrate(scenario, Hub(()))
        if run is None:
            raise SystemExit(f"the classic calibration failed (seed {seed})")
        for k, target in enumerate(scenario_targets(scenario)):
            jobs.append(
                HeadJob(target, run.knowledge, model2_config(scenario), servo_config(scenario))
            )
            settings.append(scenario.settings)
            places.append(scenario.scene.targets[: k + 1])
    with SettledHeads(settings) as heads:
        for head, placed in enumerate(places):
            for p in placed:
                heads.place(head, p.body, np.array(p.position_world_m))
        profile = cProfile.Profile()
        cpu, wall = time.process_time(), time.perf_counter()
        profile.enable()
        found = measure_model2_heads(heads, jobs)
        profile.disable()
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        images, opengl = heads.images, heads.opengl_cpu_s
    host = cpu - opengl
    ok = sum(f.ok for f in found)
    print(f"{len(jobs)} heads ({args.seeds} seeds), {ok} measured, {images} eye images")
    print(f"wall {wall:.2f} s, CPU {cpu:.2f} s: OpenGL {opengl:.2f} s, host {host:.2f} s")
    print(
        f"per head-step (one image of one head): CPU {1e3 * cpu / images:.2f} ms, "
        f"OpenGL {1e3 * opengl / images:.2f} ms, host {1e3 * host / images:.2f} ms"
    )
    pstats.Stats(profile).sort_stats("tottime").print_stats(args.profile)


if __name__ == "__main__":
    main()
