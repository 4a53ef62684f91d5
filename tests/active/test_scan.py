"""The scan for a target that the start pose does not show but the head can fixate:
found on binned previews from images and encoders alone, measured, its renders counted;
bounded where it is nowhere.  Real renders."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.active.failure import FailureCause
from headsim.active.measurement import body_target
from headsim.active.model1 import measure_model1
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.active.search import scan_eye_poses
from headsim.runs.runner import run_scenario
from headsim.runs.serialise import results_payload
from headsim.runs.summary import summary_text
from headsim.scenario.loading import load_scenario
from headsim.scenario.reach import ReachHead, scene_occluders, target_refusal
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector, find_marker

RED = body_target("marker_red", MarkerDetector("red"))

#: Camera 2 sees it at the start pose, camera 1 (0.64 rad off its axis) does not.
ASIDE = """
description = "a target camera 1 does not see at the start pose"

[experiment]
procedure = "model2"

[[scene.targets]]
name = "aside"
position_head_m = [0.3, 0.0, 0.5]
"""


def test_model2_scans_the_eyes_for_a_target_the_start_pose_misses_and_measures_it(
    tmp_path: Path,
) -> None:
    path = tmp_path / "aside.toml"
    path.write_text(ASIDE)
    scenario = load_scenario(path)  # accepted now: both eyes can fixate it
    target = scenario.scene.targets[0]
    with HeadSim("default", scenario.settings) as sim:
        sim.set_body_pose("marker_red", np.array(target.position_world_m))
        assert not find_marker(sim.render(1), "red").found  # out of camera 1's start view
        assert find_marker(sim.render(2), "red").found
    result = run_scenario(scenario)
    m = result.records[0].measurement
    assert m.ok, m.status_text
    assert m.error_pct_of_depth < 0.3
    # The scan: previews from the eye poses nearest the start pose outward, no gain
    # learnt yet (a first target): 1/16 of the eye range apart.
    assert 1 <= m.scan_renders <= 4
    assert m.search_renders >= m.scan_renders  # and camera 2's search after it
    payload = results_payload(result)
    assert list(payload["scenario"]["scene"]["acceptance"]["outside_start_view"]) == ["aside"]
    assert payload["measurements"][0]["scan_renders"] == m.scan_renders
    summary = payload["summary"]["none"]
    assert (summary["scanned"], summary["scan_renders"]) == (1, m.scan_renders)
    assert summary["outside_start_view"]["count"] == summary["outside_start_view"]["ok"] == 1
    assert "at the edge of the field (not seen whole by both cameras at the start pose): " in (
        summary_text(result)
    )


def test_model1_scans_the_neck_for_a_target_neither_camera_sees_at_the_start_pose() -> None:
    with HeadSim("default") as sim:
        p_world = sim.transform_points(np.array([0.45, -0.15, 0.6]), "head", "world")[0]
        head, hiding = ReachHead.of(sim.settings), scene_occluders("default", None, "marker_red")
        # The neck brings it in: Model 1 can fixate it; Model 2's eyes alone cannot.
        assert target_refusal(head, "model1", p_world, "target", 0.004, hiding) is None
        refusal = target_refusal(head, "model2", p_world, "target", 0.004, hiding)
        assert refusal is not None and refusal.code == "eye_range"
        sim.set_body_pose("marker_red", p_world)
        assert not find_marker(sim.render(1), "red").found
        assert not find_marker(sim.render(2), "red").found
        m = measure_model1(sim, NeckServo(sim), RED)
    assert m.ok, m.status_text
    assert m.scan_renders > 0 and m.search_renders > m.scan_renders
    assert m.error_pct_of_depth < 0.5


def test_a_scan_is_bounded_and_fails_by_cause_where_the_target_is_nowhere() -> None:
    with HeadSim("default") as sim:
        sim.set_body_pose("marker_red", [0.0, -1.0, 0.2])  # behind the head
        servo = EyeServo(sim)
        poses = scan_eye_poses(servo, 1, sim.camera_settings(1).width)
        m = measure_model2(sim, servo, RED)
    assert m.failure is not None and m.failure.cause is FailureCause.LOST
    # Every pose of the range but the one it stood at, one preview each.
    assert m.scan_renders == m.search_renders == len(poses) - 1 == 16
    assert m.detail.endswith("not seen from the 16 eye poses scanned)")
