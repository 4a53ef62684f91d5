"""The head frame from stereo extrinsics, and rotations, against the simulator's exact poses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim, invert_transform
from headsim.stereo.frames import (
    axis_rotation,
    frame_deviation,
    head_from_cam1_from_extrinsics,
    head_from_cam1_from_eye,
    rotation_angle,
)

from .helpers import calibration_from_truth


def test_head_frame_from_extrinsics_is_exact_for_mount_yaws_and_reports_other_offsets() -> None:
    # Paper preset: the mounts are yawed (0.039 / -0.056 rad); H is still exact.
    with HeadSim("default", paper_head()) as sim:
        truth = sim.head_from_camera(1)
        cam2_from_cam1 = invert_transform(sim.world_from_camera(2)) @ sim.world_from_camera(1)
        built = head_from_cam1_from_extrinsics(cam2_from_cam1)
        np.testing.assert_allclose(built, truth, atol=1e-12)
        # The paper's construction matches it when given the true mount yaw ...
        yaw = sim.settings.cameras[0].mount_yaw_rad
        np.testing.assert_allclose(
            head_from_cam1_from_eye(yaw, sim.settings.baseline_m), truth, atol=1e-12
        )
        # ... and is off by the centre ray's angle when given the effective direction,
        effective = sim.effective_initial_direction(1)
        rotation, _ = frame_deviation(
            head_from_cam1_from_eye(effective, sim.settings.baseline_m), truth
        )
        assert rotation == pytest.approx(abs(effective - yaw), abs=1e-12)
        assert rotation > 0.018
        # ... which the calibrated intrinsics give back.
        centre_ray = calibration_from_truth(sim).cam1.centre_ray_yaw_rad
        assert effective - centre_ray == pytest.approx(yaw, abs=1e-12)
    # A mount pitch tilts camera 1 out of the plane the construction assumes.
    pitched = HeadSettings(cameras=(CameraSettings(mount_pitch_rad=0.02), CameraSettings()))
    with HeadSim("default", pitched) as sim:
        cam2_from_cam1 = invert_transform(sim.world_from_camera(2)) @ sim.world_from_camera(1)
        rotation, translation = frame_deviation(
            head_from_cam1_from_extrinsics(cam2_from_cam1), sim.head_from_camera(1)
        )
    assert rotation == pytest.approx(0.01, abs=1e-9)  # half the pitch: y is the mean of both
    assert translation < 1e-12


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_axis_rotations_are_right_handed_and_their_angle_comes_back(axis: int) -> None:
    for angle in (-2.5, -0.3, 0.0, 0.7, math.pi):
        rotation = axis_rotation(axis, angle)
        np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-15)
        assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-15)
        np.testing.assert_allclose(rotation[:, axis], np.eye(3)[axis], atol=0)  # the axis stays
        assert rotation_angle(rotation) == pytest.approx(abs(angle), abs=1e-7)
    # A quarter turn about each axis takes the next axis to the one after it (x -> y -> z -> x).
    quarter = axis_rotation(axis, math.pi / 2)
    np.testing.assert_allclose(
        quarter @ np.eye(3)[(axis + 1) % 3], np.eye(3)[(axis + 2) % 3], atol=1e-15
    )


def test_frame_deviation_of_a_known_offset() -> None:
    truth = np.eye(4)
    truth[:3, 3] = [0.1, -0.2, 0.3]
    estimate = truth.copy()
    estimate[:3, :3] = axis_rotation(1, 0.01)
    estimate[:3, 3] += [0.0, 0.003, -0.004]
    rotation, translation = frame_deviation(estimate, truth)
    assert rotation == pytest.approx(0.01, abs=1e-9)
    assert translation == pytest.approx(0.005, abs=1e-15)
