"""Rigid transforms: exact inverses, rotations by their axes, and pose comparisons."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.geometry.transforms import (
    frame_deviation,
    homogeneous,
    invert_transform,
    rotation_angle,
    rotation_x,
    rotation_y,
    rotation_z,
)


def test_rotations_turn_the_axes_right_handed() -> None:
    quarter = math.pi / 2
    np.testing.assert_allclose(rotation_x(quarter) @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(rotation_y(quarter) @ [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(rotation_z(quarter) @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-15)
    for rotation in (rotation_x(0.3), rotation_y(-0.7), rotation_z(1.1)):
        np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-15)
        assert abs(np.linalg.det(rotation) - 1.0) < 1e-15


def test_invert_transform_undoes_a_pose() -> None:
    pose = homogeneous(rotation_z(0.4) @ rotation_y(-0.2), np.array([0.1, -0.3, 0.7]))
    np.testing.assert_allclose(invert_transform(pose) @ pose, np.eye(4), atol=1e-15)
    point = np.array([0.2, 0.5, -1.0, 1.0])
    np.testing.assert_allclose(invert_transform(pose) @ (pose @ point), point, atol=1e-15)


def test_frame_deviation_and_rotation_angle() -> None:
    truth = homogeneous(rotation_x(0.1), np.array([0.0, 0.0, 1.0]))
    estimate = truth @ homogeneous(rotation_y(0.002), np.array([0.003, -0.004, 0.0]))
    angle, distance = frame_deviation(estimate, truth)
    assert abs(angle - 0.002) < 1e-12
    assert abs(distance - 0.005) < 1e-15
    assert rotation_angle(np.eye(3)) == 0.0
    assert abs(rotation_angle(rotation_z(math.pi)) - math.pi) < 1e-12


AXIS_ROTATIONS = (rotation_x, rotation_y, rotation_z)


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_axis_rotations_are_right_handed_and_their_angle_comes_back(axis: int) -> None:
    for angle in (-2.5, -0.3, 0.0, 0.7, math.pi):
        rotation = AXIS_ROTATIONS[axis](angle)
        np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-15)
        assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-15)
        np.testing.assert_allclose(rotation[:, axis], np.eye(3)[axis], atol=0)  # the axis stays
        assert rotation_angle(rotation) == pytest.approx(abs(angle), abs=1e-7)
    # A quarter turn about each axis takes the next axis to the one after it (x -> y -> z -> x).
    quarter = AXIS_ROTATIONS[axis](math.pi / 2)
    np.testing.assert_allclose(
        quarter @ np.eye(3)[(axis + 1) % 3], np.eye(3)[(axis + 2) % 3], atol=1e-15
    )


def test_frame_deviation_of_a_known_offset() -> None:
    truth = np.eye(4)
    truth[:3, 3] = [0.1, -0.2, 0.3]
    estimate = truth.copy()
    estimate[:3, :3] = rotation_y(0.01)
    estimate[:3, 3] += [0.0, 0.003, -0.004]
    rotation, translation = frame_deviation(estimate, truth)
    assert rotation == pytest.approx(0.01, abs=1e-9)
    assert translation == pytest.approx(0.005, abs=1e-15)
