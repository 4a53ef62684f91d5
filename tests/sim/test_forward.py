"""The settings -> forward model converter: the StereoHead it builds, and the effective
directions it gives, against the simulator's rendered geometry."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.geometry.synthetic import fixation_angles, mount_yaw_for_direction
from headsim.sim.forward import effective_directions, stereo_head
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head, realistic_head
from headsim.sim.simulator import HeadSim


def test_stereo_head_carries_the_true_settings() -> None:
    settings = realistic_head()
    head = stereo_head(settings)
    assert head.baseline == settings.baseline_m
    assert head.encoder_resolution == settings.encoder_resolution_rad
    for index, cam in enumerate(settings.cameras):
        assert head.camera(index + 1) == cam.pinhole()
        assert head.offsets(index + 1) == (cam.nodal_offset_m, cam.side_offset_m)
    assert (head.alpha_e1, head.alpha_e2) == tuple(c.mount_yaw_rad for c in settings.cameras)
    assert head.target_columns == tuple(c.image_centre[0] for c in settings.cameras)


def test_effective_directions_are_the_simulators_and_invert_exactly() -> None:
    settings = paper_head()
    directions = effective_directions(settings)
    assert directions == pytest.approx((0.0578, -0.0254), abs=1e-15)
    with HeadSim("default", settings) as sim:
        for camera in (1, 2):
            assert sim.effective_initial_direction(camera) == pytest.approx(
                directions[camera - 1], abs=1e-12
            )
    for index, cam in enumerate(settings.cameras):
        mount = mount_yaw_for_direction(index + 1, directions[index], cam.pinhole())
        assert mount == pytest.approx(cam.mount_yaw_rad, abs=1e-16)


def test_a_point_on_an_eyes_effective_direction_needs_no_eye_turn() -> None:
    # Without distortion the image centre's column has one ray angle on every row.
    cams = (
        CameraSettings(cx=300.0, mount_yaw_rad=0.03),
        CameraSettings(cx=330.0, mount_yaw_rad=-0.02),
    )
    settings = HeadSettings(cameras=cams)
    head = stereo_head(settings)
    e1, e2 = effective_directions(settings)
    half, depth = settings.baseline_m / 2, 0.8
    # Each image centre's ray at eye angle 0 passes through one of these points.
    points = np.array(
        [[-half + depth * np.tan(e1), 0.05, depth], [half - depth * np.tan(e2), -0.05, depth]]
    )
    fix = fixation_angles(head, points)
    assert fix.alpha1[0] == pytest.approx(0.0, abs=1e-12)
    assert fix.alpha2[1] == pytest.approx(0.0, abs=1e-12)
    assert abs(fix.alpha1[1]) > 1e-3 and abs(fix.alpha2[0]) > 1e-3
