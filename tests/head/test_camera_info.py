"""CameraInfo and OpenCV YAML: a head's calibration exported, a real camera imported as a
simulated one, and the round trip's pixels against OpenCV's projection."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from headsim.head.camera_info import (
    CameraInfo,
    CameraInfoError,
    camera_info_of,
    camera_settings_from,
    read_opencv_yaml,
    read_ros_yaml,
    write_opencv_yaml,
    write_ros_yaml,
)
from headsim.sim.optics import project_points
from headsim.sim.settings import realistic_head

pytestmark = pytest.mark.fast

#: A real camera's file as ROS's camera_calibration writes it (a 1280 x 720 webcam).
ROS_YAML = """\
image_width: 1280
image_height: 720
camera_name: usb_cam
camera_matrix:
  rows: 3
  cols: 3
  data: [912.3, 0, 641.7, 0, 910.8, 358.2, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.112, 0.0871, 0, 0, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [912.3, 0, 641.7, 0, 0, 910.8, 358.2, 0, 0, 0, 1, 0]
"""

#: Points in front of the camera, m, spread over its view.
POINTS_CAM_M = np.array(
    [[0.0, 0.0, 1.0], [0.21, -0.13, 0.8], [-0.3, 0.17, 1.4], [0.05, 0.26, 0.6], [-0.12, -0.2, 2.5]]
)


def _opencv_pixels(info: CameraInfo, points: np.ndarray) -> np.ndarray:
    uv, _ = cv2.projectPoints(
        points, np.zeros(3), np.zeros(3), info.camera_matrix, np.array(info.D, dtype=float)
    )
    return uv.reshape(-1, 2)


@pytest.mark.parametrize(
    "write, read", [(write_ros_yaml, read_ros_yaml), (write_opencv_yaml, read_opencv_yaml)]
)
def test_the_heads_calibration_round_trips_exactly(
    tmp_path: Path,
    write: Callable[[Path, CameraInfo], Path],
    read: Callable[[Path], CameraInfo],
) -> None:
    for camera in realistic_head().cameras:
        info = camera_info_of(camera.pinhole(), "cam1")
        back = read(write(tmp_path / "camera.yaml", info))
        assert (back.width, back.height, back.K, back.D) == (
            info.width,
            info.height,
            info.K,
            info.D,
        )


@pytest.mark.parametrize("form", ["ros", "opencv"])
def test_an_imported_camera_projects_as_opencv_does(tmp_path: Path, form: str) -> None:
    path = tmp_path / "usb_cam.yaml"
    path.write_text(ROS_YAML)
    info = read_ros_yaml(path)
    if form == "opencv":
        info = read_opencv_yaml(write_opencv_yaml(tmp_path / "cv.yaml", info))
    simulated = camera_settings_from(info)
    assert (simulated.width, simulated.height) == (1280, 720)
    ours = project_points(POINTS_CAM_M, simulated)
    theirs = _opencv_pixels(info, POINTS_CAM_M)
    assert np.abs(ours - theirs).max() < 1e-6
    # and exported again, the simulated camera is the file's camera
    again = camera_info_of(simulated.pinhole())
    assert again.K == info.K and again.D == info.D


def test_a_lens_headsim_cannot_hold_is_refused_by_field(tmp_path: Path) -> None:
    path = tmp_path / "tangential.yaml"
    path.write_text(ROS_YAML.replace("[-0.112, 0.0871, 0, 0, 0]", "[-0.112, 0.0871, 0.001, 0, 0]"))
    with pytest.raises(CameraInfoError, match="camera info D must be"):
        camera_settings_from(read_ros_yaml(path))
    path.write_text(ROS_YAML.replace("plumb_bob", "equidistant"))
    with pytest.raises(CameraInfoError, match="distortion_model"):
        camera_settings_from(read_ros_yaml(path))
    path.write_text(ROS_YAML.replace("image_width: 1280\n", ""))
    with pytest.raises(CameraInfoError, match="image_width"):
        read_ros_yaml(path)
    with pytest.raises(CameraInfoError, match="no OpenCV calibration file"):
        read_opencv_yaml(tmp_path / "missing.yaml")
