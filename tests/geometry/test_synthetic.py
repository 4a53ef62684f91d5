"""The forward model: exact fixations, quantisation, effective initial directions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from headsim.geometry.camera_model import ideal, paper_cam1, paper_cam2
from headsim.geometry.synthetic import (
    ENCODER_RESOLUTION,
    StereoHead,
    effective_initial_direction,
    fixation_angles,
    image_points,
    observe,
    quantise,
)

D = 0.15
HEADS = {
    "ideal": StereoHead(D),
    "paper-offsets": StereoHead(D, alpha_e1=0.0578, alpha_e2=-0.0254),
    "paper-cameras": StereoHead(D, paper_cam1(), paper_cam2(), alpha_e1=0.0578, alpha_e2=-0.0254),
}


def _points(rng: np.random.Generator, n: int) -> np.ndarray:
    z = rng.uniform(0.2, 3.0, n)
    return np.stack([z * rng.uniform(-0.3, 0.3, n), z * rng.uniform(-0.2, 0.2, n), z], -1)


@pytest.mark.parametrize("name", HEADS)
def test_fixation_puts_the_point_on_the_target_columns(name):
    head = HEADS[name]
    points = _points(np.random.default_rng(81), 3000)
    fix = fixation_angles(head, points)
    assert fix.valid.all()
    u10, u20 = head.target_columns
    np.testing.assert_allclose(image_points(head, points, 1, fix.alpha1)[:, 0], u10, atol=1e-9)
    np.testing.assert_allclose(image_points(head, points, 2, fix.alpha2)[:, 0], u20, atol=1e-9)


def test_pinhole_fixation_is_the_closed_form():
    head = HEADS["paper-offsets"]
    points = _points(np.random.default_rng(82), 100)
    fix = fixation_angles(head, points)
    phi1 = np.arctan2(points[:, 0] + D / 2, points[:, 2])
    phi2 = np.arctan2(points[:, 0] - D / 2, points[:, 2])
    np.testing.assert_allclose(fix.alpha1, phi1 - 0.0578, atol=1e-15)
    np.testing.assert_allclose(fix.alpha2, -phi2 + 0.0254, atol=1e-15)


def test_effective_direction_is_what_the_servo_sees_on_each_row():
    # For any point, phi1 - alpha1 is the effective initial direction of Ca1 at
    # the row where the fixated point images (with distortion it varies by row).
    head = HEADS["paper-cameras"]
    points = _points(np.random.default_rng(83), 300)
    fix = fixation_angles(head, points)
    u10, u20 = head.target_columns
    rows1 = image_points(head, points, 1, fix.alpha1)[:, 1]
    rows2 = image_points(head, points, 2, fix.alpha2)[:, 1]
    phi1 = np.arctan2(points[:, 0] + D / 2, points[:, 2])
    phi2 = np.arctan2(points[:, 0] - D / 2, points[:, 2])
    for i in range(0, 300, 10):
        e1 = effective_initial_direction(1, 0.0578, head.cam1, u10, rows1[i])
        e2 = effective_initial_direction(2, -0.0254, head.cam2, u20, rows2[i])
        assert phi1[i] - fix.alpha1[i] == pytest.approx(e1, abs=1e-12)
        assert -phi2[i] - fix.alpha2[i] == pytest.approx(e2, abs=1e-12)


def test_effective_direction_without_distortion():
    cam = paper_cam1()
    pin = StereoHead(D, ideal(), ideal(), 0.01, 0.02, u10=300.0, u20=330.0)
    e1, e2 = pin.effective_initial_directions()
    assert e1 == pytest.approx(0.01 + math.atan((300.0 - 319.5) / ideal().kx), abs=1e-15)
    assert e2 == pytest.approx(0.02 - math.atan((330.0 - 319.5) / ideal().kx), abs=1e-15)
    with pytest.raises(ValueError, match="camera must be 1 or 2"):
        effective_initial_direction(0, 0.0, cam, 319.5)


@settings(derandomize=True, max_examples=300, deadline=None)
@given(st.floats(-1.5, 1.5, allow_nan=False), st.floats(1e-6, 1e-2))
def test_quantise_rounds_to_the_nearest_whole_step(angle, resolution):
    q = float(quantise(angle, resolution))
    steps = q / resolution
    assert steps == pytest.approx(round(steps), abs=1e-6)
    assert abs(q - angle) <= resolution / 2 * (1 + 1e-9)


def test_quantised_observation():
    head = HEADS["ideal"]
    points = _points(np.random.default_rng(84), 500)
    exact, obs = observe(head, points), observe(head, points, quantised=True)
    np.testing.assert_allclose(obs.alpha1, quantise(exact.alpha1), atol=0)
    np.testing.assert_allclose(obs.gamma1, obs.alpha2, atol=0)
    # P is off its target column by at most half a step's worth of pixels.
    u1 = image_points(head, points, 1, obs.alpha1)[:, 0]
    half_step_px = head.cam1.kx * math.tan(ENCODER_RESOLUTION / 2) * (1 + 1e-9)
    assert np.abs(u1 - 319.5).max() <= half_step_px
    assert np.abs(u1 - 319.5).max() > 0.1 * half_step_px


def test_points_that_cannot_be_fixated_are_invalid():
    head = HEADS["paper-cameras"]
    points = np.array(
        [[0.0, 0.0, -1.0], [0.0, 0.0, 0.0], [np.nan, 0, 1], [5.0, 0.0, 0.2], [0.1, 0.0, 1.0]]
    )
    obs = observe(head, points)
    assert obs.valid.tolist() == [False, False, False, False, True]
    assert np.isnan(obs.alpha1[:3]).all() and np.isnan(obs.uv1[:3]).all()
    # Far to the side: both fixations exist, but Ca1's image at alpha2 lies beyond the fold.
    assert np.isfinite([obs.alpha1[3], obs.alpha2[3]]).all() and np.isnan(obs.uv1[3]).all()


def test_in_view_tracks_the_image_border():
    head = HEADS["ideal"]
    points = np.array([[0.05, 0.0, 1.0], [0.05, 0.6, 1.0]])  # the second far below the view
    obs = observe(head, points)
    assert obs.valid.all() and obs.in_view.tolist() == [True, False]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"baseline": 150.0}, "baseline must be in metres"),
        ({"baseline": D, "alpha_e1": 3.3}, "alpha_e1 must be a yaw in radians"),
    ],
)
def test_bad_head_raises(kwargs, message):
    with pytest.raises(ValueError, match=message):
        StereoHead(**kwargs)
