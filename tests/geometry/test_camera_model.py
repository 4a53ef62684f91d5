"""The pinhole camera with radial distortion, against OpenCV."""

from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np
import pytest

from headsim.geometry.camera_model import (
    PinholeCamera,
    UndistortionError,
    ideal,
    paper_cam1,
    paper_cam2,
)

PAPER = [paper_cam1(), paper_cam2()]


def _pixel_grid(cam: PinholeCamera) -> np.ndarray:
    u, v = np.meshgrid(np.arange(cam.width, dtype=float), np.arange(cam.height, dtype=float))
    return np.stack([u, v], axis=-1)


def test_presets():
    cam = ideal()
    assert 2 * math.atan(240 / cam.ky) == pytest.approx(math.radians(45), abs=1e-15)
    assert cam.image_centre == (319.5, 239.5) == (cam.cx, cam.cy)
    assert not cam.is_distorted and cam.fold_radius == math.inf
    assert paper_cam1().K[0, 0] == 834.83 and paper_cam2().K[1, 2] == 197.3
    np.testing.assert_array_equal(paper_cam1().dist_coeffs, [-0.38741, 0, 0, 0, 0])


@pytest.mark.parametrize("cam", PAPER, ids=["cam1", "cam2"])
def test_projection_matches_opencv(cam):
    rng = np.random.default_rng(71)
    points = np.c_[rng.uniform(-0.6, 0.6, (5000, 2)), np.ones(5000)] * rng.uniform(
        0.2, 3, (5000, 1)
    )
    ours = cam.project(points)
    ref, _ = cv2.projectPoints(
        points.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), cam.K, cam.dist_coeffs
    )
    inside = np.hypot(points[:, 0], points[:, 1]) / points[:, 2] < cam.fold_radius
    np.testing.assert_allclose(ours[inside], ref.reshape(-1, 2)[inside], rtol=0, atol=1e-9)
    assert np.isnan(ours[~inside]).all()


def test_points_behind_the_camera_are_not_imaged():
    uv = ideal().project([[0.0, 0.0, -1.0], [0.1, 0.0, 0.0], [0.1, 0.2, 1.0]])
    assert np.isnan(uv[:2]).all() and np.isfinite(uv[2]).all()


@pytest.mark.parametrize("k1", [-0.39, -0.30938, 0.2])
def test_undistort_inverts_the_lens_on_every_pixel_to_1e_12_px(k1):
    # Realistic lens: k1 ~ -0.39 at f ~ 835 px, the whole 640 x 480 image.
    cam = PinholeCamera(640, 480, 834.83, 815.42, 303.8, 306.3, k1=k1, k2=0.01)
    grid = _pixel_grid(cam)
    xy = cam.normalise(grid)
    again = cam.project(np.concatenate([xy, np.ones((*xy.shape[:-1], 1))], axis=-1))
    assert np.abs(again - grid).max() < 1e-12
    undist = cam.undistort(grid)
    np.testing.assert_allclose(undist, xy * [cam.kx, cam.ky] + [cam.cx, cam.cy], atol=1e-12)


def test_undistort_agrees_with_opencv_given_enough_iterations():
    cam = paper_cam1()
    grid = _pixel_grid(cam)[::7, ::7].reshape(-1, 1, 2)
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 500, 1e-15)
    ref = cv2.undistortPoints(grid, cam.K, cam.dist_coeffs, None, None, None, criteria)
    np.testing.assert_allclose(cam.normalise(grid.reshape(-1, 2)), ref.reshape(-1, 2), atol=1e-9)


def test_pixels_beyond_the_fold_are_reported():
    # k1 = -0.39 at f = 579 px folds over before the image corners.
    cam = dataclasses.replace(ideal(), k1=-0.39)
    grid = _pixel_grid(cam).reshape(-1, 2)
    with pytest.raises(UndistortionError, match=r"pixels have no undistorted ray .* folds over"):
        cam.undistort(grid)
    out = cam.undistort(grid, strict=False)
    bad = np.isnan(out).any(axis=1)
    assert 0 < bad.mean() < 0.1
    r_d = np.hypot(*((grid - [cam.cx, cam.cy]) / [cam.kx, cam.ky]).T)
    r_f = cam.fold_radius
    assert np.all(r_d[bad] > r_f * (1 + cam.k1 * r_f**2) - 1e-12)  # only past the fold's image
    with pytest.raises(UndistortionError):
        cam.normalise([[np.nan, 1.0]])


def test_column_angle():
    cam = paper_cam2()
    pinhole = dataclasses.replace(cam, k1=0.0)
    assert pinhole.column_angle(319.5) == pytest.approx(math.atan((319.5 - 345.1) / 850.46))
    # With distortion the ray of a column depends on the row, and at the principal
    # row it is atan of the undistorted x.
    x_n = cam.normalise([[319.5, cam.cy]])[0, 0]
    assert cam.column_angle(319.5, cam.cy) == pytest.approx(math.atan(x_n), abs=1e-15)
    assert cam.column_angle(319.5, 0.0) != pytest.approx(cam.column_angle(319.5, cam.cy))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"kx": 0.0}, "kx must be a positive focal length"),
        ({"width": 64.5}, "width must be"),
        ({"cy": math.nan}, "cy must be finite"),
    ],
)
def test_bad_intrinsics_raise(kwargs, message):
    with pytest.raises(ValueError, match=message):
        dataclasses.replace(ideal(), **kwargs)
