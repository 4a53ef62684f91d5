"""Eq. (1) and the eye poses: frames and signs as docs/equations.md fixes them."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from headsim.geometry.kinematics import (
    camera_centre,
    head_from_camera,
    head_to_camera,
    head_to_world,
    world_from_head,
    world_to_head,
)

ANGLE = st.floats(-3.0, 3.0, allow_nan=False)
LENGTH = st.floats(0.0, 0.5, allow_nan=False)
SETTINGS = settings(derandomize=True, max_examples=200, deadline=None)


def test_home_pose_matches_the_frame_table():
    t = world_from_head(0.0, 0.0, d1=0.3, a2=0.1)
    np.testing.assert_allclose(t[:3, 2], [0.0, 1.0, 0.0])  # H's z is W's y (forward)
    np.testing.assert_allclose(t[:3, 1], [0.0, 0.0, -1.0])  # H's y is W's -z (down)
    np.testing.assert_allclose(t[:3, 0], [1.0, 0.0, 0.0])  # H's x is W's x (right)
    np.testing.assert_allclose(t[:3, 3], [0.0, 0.0, 0.4])  # origin at height d1 + a2


def test_positive_pitch_looks_up_and_positive_yaw_turns_left():
    up = world_from_head(0.0, 0.3, 0.3, 0.1)
    assert up[2, 2] > 0  # forward axis gains +z in W
    left = world_from_head(0.3, 0.0, 0.3, 0.1)
    assert left[0, 2] < 0  # forward axis turns towards -x (yaw about +z)


@SETTINGS
@given(ANGLE, ANGLE, LENGTH, LENGTH, st.floats(0.1, 3.0))
def test_eq3_is_the_transform_of_a_point_on_the_z_axis(theta1, theta2, d1, a2, z):
    c1, s1, c2, s2 = np.cos(theta1), np.sin(theta1), np.cos(theta2), np.sin(theta2)
    eq3 = [-z * s1 * c2 + a2 * s1 * s2, z * c1 * c2 - a2 * c1 * s2, z * s2 + a2 * c2 + d1]
    np.testing.assert_allclose(
        head_to_world([0.0, 0.0, z], theta1, theta2, d1, a2), eq3, atol=1e-14
    )


@SETTINGS
@given(ANGLE, ANGLE, LENGTH, LENGTH)
def test_rotation_is_proper_and_round_trip_is_identity(theta1, theta2, d1, a2):
    t = world_from_head(theta1, theta2, d1, a2)
    r = t[:3, :3]
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-14)
    p = np.array([[0.1, -0.2, 1.5], [-1.0, 0.3, 0.2]])
    back = world_to_head(head_to_world(p, theta1, theta2, d1, a2), theta1, theta2, d1, a2)
    np.testing.assert_allclose(back, p, atol=1e-14)


def test_broadcasting_over_many_poses():
    rng = np.random.default_rng(1)
    theta1, theta2 = rng.uniform(-1, 1, (4, 5)), rng.uniform(-1, 1, 5)
    t = world_from_head(theta1, theta2, 0.3, 0.1)
    assert t.shape == (4, 5, 4, 4)
    np.testing.assert_allclose(t[2, 3], world_from_head(theta1[2, 3], theta2[3], 0.3, 0.1))
    p = rng.normal(size=(4, 5, 3))
    assert head_to_world(p, theta1, theta2, 0.3, 0.1).shape == (4, 5, 3)
    with pytest.raises(ValueError, match=r"points_h must have shape \(\.\.\., 3\)"):
        head_to_world(np.zeros((4, 2)), 0.0, 0.0, 0.3, 0.1)


@SETTINGS
@given(st.floats(-1.2, 1.2), st.floats(0.05, 0.3))
def test_eye_poses_follow_the_sign_convention(yaw, baseline):
    np.testing.assert_allclose(camera_centre(1, baseline), [-baseline / 2, 0, 0])
    t1, t2 = head_from_camera(1, yaw, baseline), head_from_camera(2, yaw, baseline)
    np.testing.assert_allclose(t1[:3, 2], [np.sin(yaw), 0, np.cos(yaw)], atol=1e-15)
    np.testing.assert_allclose(t2[:3, 2], [-np.sin(yaw), 0, np.cos(yaw)], atol=1e-15)
    np.testing.assert_allclose(t1[:3, 1], [0, 1, 0], atol=1e-15)  # image y is H's y (down)
    # x_c / z_c = tan(phi1 - a1) in Ca1 and tan(phi2 + a2) in Ca2.
    p = np.array([[0.2, -0.1, 1.1], [-0.4, 0.3, 0.6]])
    for cam, t, sign in ((1, t1, -1.0), (2, t2, 1.0)):
        pc = head_to_camera(p, cam, yaw, baseline)
        np.testing.assert_allclose(pc, (np.linalg.inv(t) @ np.c_[p, np.ones(2)].T).T[:, :3])
        phi = np.arctan2(p[:, 0] - sign * baseline / 2, p[:, 2])
        np.testing.assert_allclose(pc[:, 0] / pc[:, 2], np.tan(phi + sign * yaw), atol=1e-14)


def test_unknown_camera_raises():
    with pytest.raises(ValueError, match="camera must be 1 or 2"):
        head_from_camera(3, 0.0, 0.15)
