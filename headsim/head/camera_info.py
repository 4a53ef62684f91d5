"""A camera as ROS describes it (``sensor_msgs/CameraInfo``), and the two file formats
calibrations travel in: ROS's camera-info YAML and OpenCV's ``FileStorage`` YAML.

headsim's lens is OpenCV's radial k1, k2 (:class:`~headsim.geometry.camera_model.PinholeCamera`),
so a camera reads in only as ``plumb_bob`` with p1 = p2 = k3 = 0 and a K without skew;
anything else is refused with the field named.  R is the identity and P = [K | 0]:
a verged head's eyes are not a rectified pair (their poses come from the joints).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml

from headsim.errors import BadInput
from headsim.geometry.camera_model import PinholeCamera
from headsim.sim.settings import CameraSettings

PLUMB_BOB = "plumb_bob"


class CameraInfoError(BadInput, ValueError):
    """A camera description headsim cannot use: the message names the field, in one line."""


@dataclass(frozen=True)
class CameraInfo:
    """``sensor_msgs/CameraInfo``'s calibration fields: image size, px; K (3 x 3),
    D (k1, k2, p1, p2, k3), R (3 x 3), P (3 x 4), row-major as ROS keeps them."""

    width: int
    height: int
    K: tuple[float, ...]
    D: tuple[float, ...]
    R: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    P: tuple[float, ...] = ()
    distortion_model: str = PLUMB_BOB
    frame_id: str = ""

    def __post_init__(self) -> None:
        for name, size in (("K", 9), ("R", 9), ("P", 12)):
            value = getattr(self, name)
            if name == "P" and not value:
                k = self.K
                object.__setattr__(
                    self, "P", (k[0], k[1], k[2], 0.0, k[3], k[4], k[5], 0.0, 0.0, 0.0, 1.0, 0.0)
                )
                continue
            if len(value) != size or not all(math.isfinite(v) for v in value):
                raise CameraInfoError(
                    f"camera info {name} must be {size} finite numbers, got {value!r}"
                )
        for name in ("width", "height"):
            if int(getattr(self, name)) <= 0:
                raise CameraInfoError(f"camera info {name} must be a positive number of pixels")

    @property
    def camera_matrix(self) -> np.ndarray:
        """K as a 3 x 3 array, px."""
        return np.array(self.K, dtype=float).reshape(3, 3)


def camera_info_of(camera: PinholeCamera, frame_id: str = "") -> CameraInfo:
    """The CameraInfo of a headsim camera (exact: every value carried as it is)."""
    return CameraInfo(
        width=camera.width,
        height=camera.height,
        K=tuple(float(v) for v in camera.K.reshape(-1)),
        D=tuple(float(v) for v in camera.dist_coeffs),
        frame_id=frame_id,
    )


def pinhole_of(info: CameraInfo) -> PinholeCamera:
    """The headsim camera a CameraInfo describes; refuses what its lens model cannot hold."""
    if info.distortion_model != PLUMB_BOB:
        raise CameraInfoError(
            f"camera info distortion_model must be {PLUMB_BOB!r}, got {info.distortion_model!r}"
        )
    d = tuple(info.D) + (0.0,) * (5 - len(info.D))
    if len(info.D) > 5 or any(d[i] != 0.0 for i in (2, 3, 4)):
        raise CameraInfoError(
            f"camera info D must be (k1, k2[, 0, 0, 0]): headsim's lens has no tangential "
            f"or k3 terms, got {list(info.D)}"
        )
    k = info.K
    if k[1] != 0.0 or k[3] != 0.0 or k[6:] != (0.0, 0.0, 1.0):
        raise CameraInfoError(
            f"camera info K must be [fx, 0, cx, 0, fy, cy, 0, 0, 1], got {list(k)}"
        )
    try:
        return PinholeCamera(info.width, info.height, k[0], k[4], k[2], k[5], d[0], d[1])
    except ValueError as err:
        raise CameraInfoError(f"camera info: {err}") from None


def camera_settings_from(info: CameraInfo, base: CameraSettings | None = None) -> CameraSettings:
    """A simulated camera with ``info``'s intrinsics and lens, the rest (mount, noise) as
    ``base``'s (default: the default camera)."""
    lens = pinhole_of(info)
    try:
        return replace(
            base or CameraSettings(),
            width=lens.width,
            height=lens.height,
            kx=lens.kx,
            ky=lens.ky,
            cx=lens.cx,
            cy=lens.cy,
            k1=lens.k1,
            k2=lens.k2,
        )
    except ValueError as err:
        raise CameraInfoError(f"camera info: {err}") from None


# -- ROS camera-info YAML (camera_calibration_parsers) ---------------------------------


def _matrix_block(rows: int, cols: int, data: Sequence[float]) -> dict[str, Any]:
    return {"rows": rows, "cols": cols, "data": [float(v) for v in data]}


def ros_yaml_document(info: CameraInfo, camera_name: str = "") -> dict[str, Any]:
    """The document ``camera_calibration_parsers`` writes for ``info``."""
    return {
        "image_width": info.width,
        "image_height": info.height,
        "camera_name": camera_name or info.frame_id,
        "camera_matrix": _matrix_block(3, 3, info.K),
        "distortion_model": info.distortion_model,
        "distortion_coefficients": _matrix_block(1, len(info.D), info.D),
        "rectification_matrix": _matrix_block(3, 3, info.R),
        "projection_matrix": _matrix_block(3, 4, info.P),
    }


def _floats(document: Mapping[str, Any], key: str, size: int | None) -> tuple[float, ...]:
    try:
        data = tuple(float(v) for v in document[key]["data"])
    except (KeyError, TypeError, ValueError):
        raise CameraInfoError(f"camera info YAML needs {key}.data, a list of numbers") from None
    if size is not None and len(data) != size:
        raise CameraInfoError(
            f"camera info YAML {key}.data must hold {size} numbers, got {len(data)}"
        )
    return data


def camera_info_from_ros_yaml(document: Mapping[str, Any], frame_id: str = "") -> CameraInfo:
    """A CameraInfo from a ROS camera-info YAML document (parsed)."""
    try:
        width, height = int(document["image_width"]), int(document["image_height"])
    except (KeyError, TypeError, ValueError):
        raise CameraInfoError(
            "camera info YAML needs image_width and image_height, integers"
        ) from None
    return CameraInfo(
        width=width,
        height=height,
        K=_floats(document, "camera_matrix", 9),
        D=_floats(document, "distortion_coefficients", None),
        R=_floats(document, "rectification_matrix", 9),
        P=_floats(document, "projection_matrix", 12),
        distortion_model=str(document.get("distortion_model", PLUMB_BOB)),
        frame_id=frame_id or str(document.get("camera_name", "")),
    )


def write_ros_yaml(path: Path, info: CameraInfo, camera_name: str = "") -> Path:
    """Write ``info`` as ROS camera-info YAML (floats written by ``repr``: exact)."""
    path.write_text(yaml.safe_dump(ros_yaml_document(info, camera_name), sort_keys=False))
    return path


def read_ros_yaml(path: str | Path) -> CameraInfo:
    """A ROS camera-info YAML file's CameraInfo."""
    try:
        document = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as err:
        raise CameraInfoError(
            f"cannot read camera info YAML {path}: {err}".splitlines()[0]
        ) from None
    if not isinstance(document, dict):
        raise CameraInfoError(f"camera info YAML {path} must be a mapping")
    return camera_info_from_ros_yaml(document)


# -- OpenCV FileStorage YAML -------------------------------------------------------------


def write_opencv_yaml(path: Path, info: CameraInfo) -> Path:
    """Write ``info`` as OpenCV ``FileStorage`` YAML: image_width, image_height,
    camera_matrix, distortion_coefficients (what ``cv::calibrateCamera`` users keep)."""
    storage = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    storage.write("image_width", info.width)
    storage.write("image_height", info.height)
    storage.write("camera_matrix", info.camera_matrix)
    storage.write("distortion_coefficients", np.array(info.D, dtype=float).reshape(1, -1))
    storage.release()
    return path


def read_opencv_yaml(path: str | Path, frame_id: str = "") -> CameraInfo:
    """A CameraInfo from OpenCV ``FileStorage`` YAML (keys as :func:`write_opencv_yaml`)."""
    if not Path(path).is_file():
        raise CameraInfoError(f"no OpenCV calibration file {path}")
    try:
        storage = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    except cv2.error as err:
        raise CameraInfoError(f"cannot read OpenCV YAML {path}: {err}".splitlines()[0]) from None
    try:
        fields = {
            key: storage.getNode(key)
            for key in ("image_width", "image_height", "camera_matrix", "distortion_coefficients")
        }
        missing = [key for key, node in fields.items() if node.empty()]
        if missing:
            raise CameraInfoError(f"OpenCV YAML {path} lacks {', '.join(missing)}")
        k = fields["camera_matrix"].mat()
        d = fields["distortion_coefficients"].mat()
        if k is None or k.shape != (3, 3) or d is None:
            raise CameraInfoError(f"OpenCV YAML {path}: camera_matrix must be 3 x 3")
        return CameraInfo(
            width=int(fields["image_width"].real()),
            height=int(fields["image_height"].real()),
            K=tuple(float(v) for v in k.reshape(-1)),
            D=tuple(float(v) for v in d.reshape(-1)),
            frame_id=frame_id,
        )
    finally:
        storage.release()


__all__ = [
    "PLUMB_BOB",
    "CameraInfo",
    "CameraInfoError",
    "camera_info_from_ros_yaml",
    "camera_info_of",
    "camera_settings_from",
    "pinhole_of",
    "read_opencv_yaml",
    "read_ros_yaml",
    "ros_yaml_document",
    "write_opencv_yaml",
    "write_ros_yaml",
]
