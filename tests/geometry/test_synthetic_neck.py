"""Model 1's exact forward model with the paper's distorted cameras: the fixation puts the
point on the principal row at both target columns; quantising moves only the eye angle."""

from __future__ import annotations

import numpy as np

from headsim.geometry.camera_model import paper_cam1, paper_cam2
from headsim.geometry.kinematics import head_to_world, world_to_head
from headsim.geometry.synthetic import StereoHead, image_points
from headsim.geometry.synthetic_neck import neck_fixation

D, D1, A2 = 0.15, 0.12, 0.09
HEAD = StereoHead(D, paper_cam1(), paper_cam2(), alpha_e1=0.0578, alpha_e2=-0.0254)


def _points_w(count: int) -> np.ndarray:
    rng = np.random.default_rng(4)
    z = rng.uniform(0.4, 2.0, count)
    points_h = np.column_stack(
        [rng.uniform(-0.3, 0.3, count) * z, rng.uniform(-0.2, 0.2, count) * z, z]
    )
    return head_to_world(points_h, 0.2, -0.1, D1, A2)


def test_distorted_fixation_lands_on_the_principal_row_at_the_target_columns() -> None:
    points_w = _points_w(300)
    fix = neck_fixation(HEAD, points_w, D1, A2)
    assert fix.valid.all()
    np.testing.assert_allclose(
        world_to_head(points_w, fix.theta1, fix.theta2, D1, A2), fix.points_h, atol=1e-12
    )
    for camera, u0 in zip((1, 2), HEAD.target_columns, strict=True):
        uv = image_points(HEAD, fix.points_h, camera, fix.alpha)
        np.testing.assert_allclose(uv[:, 0], u0, atol=1e-9)
        np.testing.assert_allclose(uv[:, 1], HEAD.camera(camera).cy, atol=1e-9)


def test_quantised_moves_only_the_eye_angle_to_a_whole_step() -> None:
    points_w = _points_w(50)
    exact = neck_fixation(HEAD, points_w, D1, A2)
    rounded = neck_fixation(HEAD, points_w, D1, A2, quantised=True)
    steps = rounded.alpha / HEAD.encoder_resolution
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-9)
    assert np.abs(rounded.alpha - exact.alpha).max() <= HEAD.encoder_resolution / 2 + 1e-15
    np.testing.assert_array_equal(rounded.theta1, exact.theta1)
    np.testing.assert_array_equal(rounded.points_h, exact.points_h)


def test_a_point_inside_the_eyes_offset_from_the_pitch_axis_is_invalid() -> None:
    inside = np.array(
        [[0.0, 0.05, D1], [0.0, 1.0, 0.3]]
    )  # 0.05 m < a2 from the axis; then a fine one
    fix = neck_fixation(HEAD, inside, D1, A2)
    assert fix.valid.tolist() == [False, True]
    assert np.isnan(fix.alpha[0]) and np.isnan(fix.points_h[0]).all()
