"""A marker half hidden from a camera's entrance pupil (20 mm ahead of its eye's yaw axis on
the realistic head), though clear of the axis: the reach check refuses it, and the detector
calls the rendered half disc occluded rather than placing a biased centroid."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.scenario.occlusion import hidden_by
from headsim.scenario.reach import ReachHead, body_radius, model2_refusal, scene_occluders
from headsim.scenario.scene import start_head_to_world
from headsim.sim import names
from headsim.sim.model import neck_of
from headsim.sim.settings import realistic_head
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import find_marker

TARGET, BLOCKER = names.MARKERS[0], names.MARKERS[1]  # red, seen past green
#: The target in H at the start pose, m: 0.3 rad off camera 1's axis, so that the pupil
#: 20 mm ahead of the yaw axis looks at it along another line than the axis does.
TARGET_HEAD_M = np.array([0.08, 0.0, 0.5])
#: Where along camera 1's line of sight the blocker stands (of the way to the target).
BLOCKER_FRACTION = 0.3


def _layout(lateral_m: float = 0.0) -> tuple[ReachHead, np.ndarray, np.ndarray, np.ndarray]:
    """The head, the target's and the blocker's world positions, and camera 1's yaw-axis
    centre (what the check tested from before): the blocker's edge on the line from
    camera 1's pupil at the start pose to the target's centre, on the side away from
    the axis's line, ``lateral_m`` farther out."""
    settings = realistic_head()
    head = ReachHead.of(settings)
    target = start_head_to_world(settings, TARGET_HEAD_M[None])[0]
    pupil = head.optical_centre(0)  # eyes and neck at 0: where the procedure first looks
    axis = neck_of(settings.head).head_to_world(
        np.array([-settings.baseline_m / 2, 0.0, 0.0]), 0.0, 0.0, settings.neck_d1_m,
        settings.neck_a2_m,
    )  # fmt: skip
    on_line = pupil + BLOCKER_FRACTION * (target - pupil)
    along = (target - axis) / np.linalg.norm(target - axis)
    away = on_line - axis - ((on_line - axis) @ along) * along  # from the axis's line
    blocker = on_line + (body_radius(BLOCKER) + lateral_m) * away / np.linalg.norm(away)
    return head, target, blocker, axis


def test_a_partial_occlusion_the_yaw_axis_missed_is_refused_from_the_pupil() -> None:
    head, target, blocker, axis = _layout()
    occluders = scene_occluders("default", {BLOCKER: blocker}, TARGET)
    radius = body_radius(TARGET)
    margin = 2.0 / head.settings.cameras[0].kx
    # The check before: from the yaw axis the blocker passes clear of the target.
    assert hidden_by(axis, target, radius, margin, occluders) is None
    refusal = model2_refusal(head, target, "target", radius, occluders)
    assert refusal is not None and refusal.code == "occluded"
    assert "hidden from camera 1 by marker_green" in refusal.message
    # 3 cm farther out it hides nothing from either camera at any pose: accepted.
    head, target, clear, _ = _layout(0.03)
    occluders = scene_occluders("default", {BLOCKER: clear}, TARGET)
    assert model2_refusal(head, target, "target", radius, occluders) is None


@pytest.mark.render
def test_the_rendered_half_disc_is_occluded_and_the_whole_one_found() -> None:
    head, target, blocker, _ = _layout()
    _, _, clear, _ = _layout(0.03)
    with HeadSim("default", head.settings) as sim:
        sim.set_body_pose(names.MARKERS[2], [0.0, -3.0, -1.0])  # blue out of the way
        sim.set_body_pose(TARGET, target)
        sim.set_body_pose(BLOCKER, clear)
        whole = find_marker(sim.render(1), "red")
        assert whole.found
        truth = sim.project(sim.position(TARGET), 1)[0]
        # The detector's tolerance on renders (tests/vision/test_markers.py): 0.15 px.
        assert np.linalg.norm(np.asarray(whole.uv) - truth) < 0.15

        sim.set_body_pose(BLOCKER, blocker)
        hidden = find_marker(sim.render(1), "red")
        assert hidden.status is DetectionStatus.OCCLUDED and hidden.uv is None
        # About half of it still shows: the blob alone says it is not whole.
        assert 0.3 * whole.area_px < hidden.area_px < 0.75 * whole.area_px
