"""The head frame from stereo extrinsics against the simulator's exact poses."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.geometry.transforms import frame_deviation, invert_transform
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim
from headsim.stereo.frames import head_from_cam1_from_extrinsics, head_from_cam1_from_eye

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
