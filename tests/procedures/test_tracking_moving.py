"""A moving target followed with Model 1, with real rendering."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from headsim.active.measurement import body_target
from headsim.active.neck_servo import NeckServo
from headsim.head.sim_head import SimHead
from headsim.procedures.tracking import track_moving_target
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))


def test_tracking_follows_a_moving_target_with_fewer_renders_after_the_first() -> None:
    with HeadSim("default", replace(HeadSettings(), seed=1)) as sim:

        def path(t: float) -> np.ndarray:
            return np.array([0.1 * np.sin(t), 0.8, 0.25 + 0.05 * t])

        head = SimHead(sim)
        run = track_moving_target(head, NeckServo(head), RED, "marker_red", path, [0.0, 0.3, 0.6])
        assert all(m.ok for m in run.measurements)
        assert np.all(run.errors_world_m < 0.006)
        renders = [m.renders for m in run.measurements]
        assert max(renders[1:]) < renders[0]


def test_tracking_searches_around_its_last_fixation_for_a_target_that_left_both_views() -> None:
    # Twice the focal length: the view at 0.8 m is about +-0.2 m wide, and the
    # target moves 0.25 m between fixations, out of both views and out of the
    # start pose's view too (the old fallback).
    base = replace(HeadSettings(), seed=1)
    cams = tuple(replace(c, kx=c.kx * 2, ky=c.ky * 2) for c in base.cameras)
    with HeadSim("default", replace(base, cameras=cams)) as sim:  # type: ignore[arg-type]

        def path(t: float) -> np.ndarray:
            return np.array([0.25 * t, 0.8, 0.3])

        assert not sim.stereo_view().sees_whole(path(1.0)[None], 0.01)[0]  # not from the start pose
        head = SimHead(sim)
        run = track_moving_target(
            head, NeckServo(head), RED, "marker_red", path, [0.0, 1.0, 2.0, 2.6]
        )
    assert all(m.ok for m in run.measurements), [m.status for m in run.measurements]
    searched = [m.search_renders for m in run.measurements]
    assert searched[0] == 0 and searched[1] > 0
    # The first look (2 renders) and at most 3 poses of 2 renders each.
    assert max(searched) <= 8
    assert all(m.error_pct_of_depth < 0.2 for m in run.measurements)
