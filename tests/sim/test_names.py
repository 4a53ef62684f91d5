"""The Camera type: number, MJCF name and inward sign agree with the model's geometry."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.geometry.kinematics import eye_from_camera_rotation
from headsim.sim import names
from headsim.sim.model import load_spec


def test_a_camera_is_found_by_number_name_or_itself() -> None:
    ca1, ca2 = names.EYE_CAMERAS
    assert names.Camera.of(1) is ca1 and names.Camera.of("cam2") is ca2
    assert names.Camera.of(ca2) is ca2
    assert [c.number for c in names.EYE_CAMERAS] == [1, 2]
    assert [c.name for c in names.EYE_CAMERAS] == list(names.CAMERAS)
    for bad in (0, 3, True, "cam3"):
        with pytest.raises(ValueError, match="allowed: 1, 2, cam1, cam2"):
            names.Camera.of(bad)


def test_a_positive_mount_yaw_turns_each_camera_towards_the_midline() -> None:
    spec = load_spec("base")
    for camera in names.EYE_CAMERAS:
        rotation = eye_from_camera_rotation(camera.inward, 0.2)
        axis_h = rotation @ np.array([0.0, 0.0, 1.0])  # the optical axis in the eye (= H) frame
        eye_x = spec.body(names.EYE_BODIES[camera.index]).pos[0]  # the eye's side of the midline
        assert np.sign(axis_h[0]) == -np.sign(eye_x) == camera.inward
        assert axis_h[0] == pytest.approx(camera.inward * np.sin(0.2), abs=1e-15)


def test_the_simulator_takes_a_camera_by_number_name_or_camera() -> None:
    from headsim.sim.settings import SettingsError, paper_head
    from headsim.sim.simulator import HeadSim

    with HeadSim("default", paper_head()) as sim:
        for camera in names.EYE_CAMERAS:
            assert sim.camera_index(camera) == camera.index
            assert sim.camera_index(camera.number) == camera.index
            assert sim.camera_index(camera.name) == camera.index
            assert sim.camera_settings(camera) is sim.camera_settings(camera.number)
        with pytest.raises(SettingsError, match="unknown camera 3; allowed: 1, 2"):
            sim.camera_index(3)
