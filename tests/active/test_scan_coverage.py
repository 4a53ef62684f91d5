"""The scans cover every pose the joints allow (issue 40, items 1 and 2): the neck scan
over the whole of both neck ranges in any order of targets, camera 2's search out to the
ends of the eye range, and the reach check seeing a close target as the lens does.
Pure geometry on a constructed head, then a few real renders."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import body_target
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.active.search import (
    SCAN_DIVISIONS,
    SCAN_STRIDE,
    _refinement,
    neck_scan_strides,
    scan_neck_poses,
    search_poses,
)
from headsim.geometry.kinematics import head_to_world
from headsim.runs.runner import run_scenario
from headsim.scenario.loading import load_scenario
from headsim.scenario.reach import ReachHead, model2_refusal
from headsim.sim.settings import paper_head, realistic_head
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import MarkerDetector, find_marker

RED = body_target("marker_red", MarkerDetector("red"))


def _covered(poses: list[tuple[int, int, int]], ranges, strides) -> None:
    """Every whole (yaw, pitch) step of both ranges lies within half a stride of a pose
    along each axis: the grid has no gap wider than a stride anywhere in the range."""
    (ylo, yhi), (plo, phi) = ranges
    yaws = sorted({p[0] for p in poses})
    pitches = sorted({p[1] for p in poses})
    assert (yaws[0], yaws[-1], pitches[0], pitches[-1]) == (ylo, yhi, plo, phi)
    assert max(np.diff(yaws)) <= strides[0] + 1 and max(np.diff(pitches)) <= strides[1] + 1
    assert len(poses) == len(set(poses)) == len(yaws) * len(pitches)  # the whole grid, once


def test_the_neck_scan_covers_both_whole_ranges_before_and_after_a_gain_is_learnt() -> None:
    with HeadSim("default", paper_head()) as sim:
        servo = NeckServo(sim)
        (ylo, yhi), (plo, phi), _ = servo.step_ranges
        # No Jacobian yet: 1/16 of each range apart, all of it (the old scan kept the 48
        # poses nearest the start: about +-0.8 of the neck's +-1.57 rad of yaw).
        strides = neck_scan_strides(servo, (640, 480))
        assert strides == ((yhi - ylo) / SCAN_DIVISIONS, (phi - plo) / SCAN_DIVISIONS)
        poses = scan_neck_poses(servo, (640, 480))
        _covered(poses, ((ylo, yhi), (plo, phi)), strides)
        assert len(poses) == (SCAN_DIVISIONS + 1) ** 2
        assert all(p[2] == 0 for p in poses)
        # Coarse to fine: the farthest corners of the range come within the first
        # quarter of the looks, not last.
        first = poses[: len(poses) // 4]
        assert {(ylo, plo, 0), (yhi, phi, 0)} <= set(first)
        # A learnt Jacobian (2 px per step): 0.7 of a view apart, still the whole range.
        servo.jacobian = np.array([[2.0, 0.0, 1.0], [2.0, 0.0, -1.0], [0.0, 2.0, 0.0]])
        strides = neck_scan_strides(servo, (640, 480))
        assert strides == (SCAN_STRIDE * 640 / 2, SCAN_STRIDE * 480 / 2)
        poses = scan_neck_poses(servo, (640, 480))
        _covered(poses, ((ylo, yhi), (plo, phi)), strides)
        d = [np.hypot(p[0] / strides[0], p[1] / strides[1]) for p in poses]
        assert d == sorted(d)  # nearest the start pose first


def test_the_refinement_looks_half_a_spacing_around_a_pose_within_the_ranges() -> None:
    with HeadSim("default", paper_head()) as sim:
        servo = NeckServo(sim)
        (_, yhi), (_, phi), _ = servo.step_ranges
        around = _refinement(servo, (0, 0, 0), (800.0, 400.0))
        assert set(around) == {
            (i * 400, j * 200, 0) for i in (-1, 0, 1) for j in (-1, 0, 1) if (i, j) != (0, 0)
        }
        assert set(around[:4]) == {(400, 0, 0), (-400, 0, 0), (0, 200, 0), (0, -200, 0)}
        corner = _refinement(servo, (yhi, phi, 0), (800.0, 400.0))
    assert len(corner) == 3 and all(q[0] <= yhi and q[1] <= phi for q in corner)


def test_camera_2s_search_reaches_the_end_of_the_eye_range() -> None:
    with HeadSim("default", paper_head()) as sim:
        servo = EyeServo(sim)
        low, high = servo.step_range
        servo.gains[1] = 2.0  # px per step: a view is 320 steps, a stride 224
        here = high - 100  # less than a stride from the end
        sim.command_eye_steps(here)
        sim.settle()
        poses = search_poses(servo, 2, (), 640)
    assert high in poses  # the old sweep stepped past it and dropped the pose
    assert poses[:2] == [0, high]
    assert all(low <= p <= high for p in poses) and len(poses) == len(set(poses))


def test_the_reach_check_refuses_a_close_target_the_lens_shows_cut_and_keeps_one_it_shows_whole() -> (
    None
):
    # The realistic head's pupils sit 20 mm ahead of the eyes' yaw axes: 0.14 m away,
    # that decides whether a marker's rim leaves the image.
    settings = realistic_head()
    head = ReachHead.of(settings)
    cut_head = np.array([-0.013, 0.025, 0.136])  # low in camera 1 (its cy is 306 of 480)
    whole_head = np.array([0.0364, -0.0215, 0.1216])  # near camera 2's top, still whole
    with HeadSim("default", settings) as sim:
        resolution = settings.encoder_resolution_rad
        for p_head, camera, whole in ((cut_head, 1, False), (whole_head, 2, True)):
            p_world = head_to_world(p_head, 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)
            refusal = model2_refusal(head, p_world, "target", 0.004)
            assert (refusal is None) is whole, refusal
            if not whole:
                assert refusal is not None and refusal.code == "not_in_any_view"
                assert f"camera {camera}" in refusal.message
            sim.set_body_pose("marker_red", p_world)
            alpha = head.model2_angles(head.to_head(p_world))[camera - 1]
            sim.command_eye_steps(round(alpha / resolution))
            sim.settle()
            seen = find_marker(sim.render(camera), "red")
            assert (seen.status is DetectionStatus.FOUND) is whole, seen.status


#: Model 1 on the realistic head, the targets near the neck's limits first, then one the
#: start pose shows: positions in W from the neck pose that faces each (yaw, pitch).
HARD_FIRST = """
description = "Model 1, targets near the neck's limits first"
seed = 0

[head]
preset = "realistic"

[experiment]
procedure = "model1"

[[scene.targets]]
name = "right_low"   # neck yaw -1.45, pitch -0.57 rad
position_world_m = [0.8279, 0.1021, -0.3133]

[[scene.targets]]
name = "left"        # neck yaw 1.23, pitch 0.12 rad
position_world_m = [-0.9080, 0.3227, 0.3233]

[[scene.targets]]
name = "ahead"       # in the start view
position_world_m = [-0.2523, 1.0041, 0.3167]
"""


def test_model1_measures_every_target_when_the_hard_ones_come_first(tmp_path: Path) -> None:
    path = tmp_path / "hard_first.toml"
    path.write_text(HARD_FIRST)
    result = run_scenario(load_scenario(path))  # the reach check accepts all three
    ms = [r.measurement for r in result.records]
    assert [m.ok for m in ms] == [True, True, True], [m.status_text for m in ms]
    # Neither hard target is in the start view: both scanned, before any gain is learnt
    # (the old scan gave up on both after 48 poses), within the whole grid's poses.
    assert ms[0].scan_renders > 0 and ms[1].scan_renders > 0 and ms[2].scan_renders == 0
    assert max(m.scan_renders for m in ms) < 48
    assert all(m.scan_renders <= 2 * (SCAN_DIVISIONS + 1) ** 2 for m in ms)


def test_model2_measures_a_close_lateral_target_camera_2_sees_only_near_the_eye_range_end() -> None:
    # 0.15 m away, left of the midline: once Ca1 fixates it (eye 0.24 rad), Ca2 needs
    # about 0.6 rad, less than a search stride from the eye range's end (0.7 rad).
    settings = realistic_head()
    p_head = np.array([-0.0277, -0.0120, 0.1545])
    p_world = head_to_world(p_head, 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m)
    assert model2_refusal(ReachHead.of(settings), p_world, "target", 0.004) is None
    with HeadSim("default", settings) as sim:
        sim.set_body_pose("marker_red", p_world)
        m = measure_model2(sim, EyeServo(sim), RED)
        high = EyeServo(sim).step_range[1]
    assert m.ok, m.status_text
    assert m.search_renders > 0  # Ca2 was searched for
    assert round(m.details["gamma2_rad"] / settings.encoder_resolution_rad) == high
