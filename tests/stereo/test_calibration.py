"""Zhang calibration of rendered chessboard views beside the simulator's truth."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from headsim.geometry.transforms import frame_deviation
from headsim.head.sim_head import SimHead
from headsim.sim.optics import camera_matrix, dist_coeffs
from headsim.sim.settings import ideal_head, paper_head
from headsim.sim.simulator import HeadSim
from headsim.stereo.calibration import (
    calibrate_stereo,
    undistort_normalized_points,
)
from headsim.stereo.calibration_file import (
    StereoCalibrationFileError,
    read_stereo_calibration,
    write_stereo_calibration,
)
from headsim.stereo.triangulation import triangulate
from headsim.stereo.views import StereoError, chessboard_views


def test_calibration_reaches_the_reprojection_and_focal_length_bounds(calibrated) -> None:
    name, _, calib = calibrated
    assert calib.mono1.rms_px <= 0.2 and calib.mono2.rms_px <= 0.2
    assert calib.stereo_rms_px <= 0.2
    for cam in (calib.cam1, calib.cam2, calib.mono1, calib.mono2):
        assert max(abs(e) for e in cam.focal_rel_errors) < 0.005, (name, cam.focal_rel_errors)
        assert max(abs(e) for e in cam.principal_errors_px) < 3.0, (name, cam.principal_errors_px)
        assert abs(cam.k1_error) < 0.02, (name, cam.dist)
    assert abs(calib.baseline_m - calib.true_baseline_m) < 1e-3
    assert calib.rotation_error_rad < 3e-3
    rotation, translation = frame_deviation(calib.head_from_cam1, calib.true_head_from_cam1)
    assert rotation < 5e-3 and translation < 1e-3


@pytest.mark.render
def test_too_few_views_is_a_clear_error() -> None:
    with HeadSim("chessboard", ideal_head()) as sim:
        views = chessboard_views(SimHead(sim), 3, np.random.default_rng(0))
        assert views.renders == 6
        with pytest.raises(StereoError, match=r"need at least 5 views .* got 3 of 3 poses"):
            calibrate_stereo(SimHead(sim), views)


def test_undistortion_converges_over_the_whole_image_where_opencv_defaults_do_not() -> None:
    cam = paper_head().cameras[0]  # k1 = -0.387
    K, dist = camera_matrix(cam), dist_coeffs(cam)
    us, vs = np.meshgrid(np.arange(0.0, cam.width, 8.0), np.arange(0.0, cam.height, 8.0))
    uv = np.column_stack([us.ravel(), vs.ravel()])
    reference = cam.pinhole().normalise(uv)  # raises if any pixel has no ray
    ours = undistort_normalized_points(uv, K, dist)
    assert np.abs(ours - reference).max() * cam.kx < 1e-6  # px
    default = cv2.undistortPoints(uv.reshape(-1, 1, 2), K, dist).reshape(-1, 2)
    assert np.abs(default - reference).max() * cam.kx > 0.3  # px, in the image corners


def test_a_calibration_written_and_read_back_triangulates_exactly_as_before(
    calibrated, tmp_path
) -> None:
    _, _, calib = calibrated
    back = read_stereo_calibration(write_stereo_calibration(tmp_path / "zhang.json", calib))
    for key in ("mono1", "mono2", "cam1", "cam2"):
        a, b = getattr(calib, key), getattr(back, key)
        assert np.array_equal(a.K, b.K) and np.array_equal(a.dist, b.dist)
        assert a.rms_px == b.rms_px and a.image_size == b.image_size
        assert np.array_equal(a.true_K, b.true_K) and np.array_equal(a.true_dist, b.true_dist)
    for key in ("cam2_from_cam1", "true_cam2_from_cam1", "true_head_from_cam1"):
        assert np.array_equal(getattr(calib, key), getattr(back, key))
    assert (back.stereo_rms_px, back.views, back.refined) == (
        calib.stereo_rms_px,
        calib.views,
        calib.refined,
    )
    uv1, uv2 = np.array([[300.0, 200.0]]), np.array([[280.0, 201.0]])
    assert np.array_equal(triangulate(calib, uv1, uv2), triangulate(back, uv1, uv2))
    # What was read back writes the same bytes.
    again = write_stereo_calibration(tmp_path / "again.json", back)
    assert again.read_bytes() == (tmp_path / "zhang.json").read_bytes()


def test_a_malformed_stereo_calibration_file_says_what_is_wrong(calibrated, tmp_path) -> None:
    _, _, calib = calibrated
    path = write_stereo_calibration(tmp_path / "zhang.json", calib)
    doc = json.loads(path.read_text())
    doc["cam1"]["K"] = [[1.0, 0.0]]
    path.write_text(json.dumps(doc))
    with pytest.raises(
        StereoCalibrationFileError, match=r"zhang.json is malformed: cam1.K: not 3 x 3"
    ):
        read_stereo_calibration(path)
    path.write_text(json.dumps({**doc, "version": 9}))
    with pytest.raises(StereoCalibrationFileError, match="has version 9; this headsim reads 1"):
        read_stereo_calibration(path)
