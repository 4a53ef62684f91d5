"""Triangulation with a stereo calibration, and measuring a target at eye angle 0.

Step 3 of the baseline (:func:`triangulate`): undistort detected pixels with
the calibration, ``cv2.triangulatePoints`` in camera 1's frame, then map into
the head frame H (:mod:`headsim.stereo.frames`).  :func:`measure_point_stereo`
runs it on a body of the scene: found in the head's images (:func:`detect_pair`), scored
against the simulator's truth (through the head's truth channel).
Units: m, px.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numpy as np

from headsim.head.servo_head import ServoHead
from headsim.sim import names
from headsim.stereo.calibration import StereoCalibration, undistort_normalized_points
from headsim.stereo.views import StereoError
from headsim.vision.detection import Detection
from headsim.vision.markers import find_marker


def triangulate_cam1(calib: StereoCalibration, uv1: np.ndarray, uv2: np.ndarray) -> np.ndarray:
    """Points (N, 3) m in camera 1's frame from detected (distorted) pixels (N, 2) in each image."""
    uv1 = np.atleast_2d(np.asarray(uv1, dtype=float))
    uv2 = np.atleast_2d(np.asarray(uv2, dtype=float))
    if uv1.shape != uv2.shape or uv1.shape[-1] != 2:
        raise StereoError(f"uv1 and uv2 must both be (N, 2), got {uv1.shape} and {uv2.shape}")
    xy1 = undistort_normalized_points(uv1, calib.cam1.K, calib.cam1.dist)
    xy2 = undistort_normalized_points(uv2, calib.cam2.K, calib.cam2.dist)
    P1 = np.hstack([np.eye(3), np.zeros((3, 1))])
    P2 = calib.cam2_from_cam1[:3, :]
    homogeneous = cv2.triangulatePoints(P1, P2, xy1.T, xy2.T)
    return (homogeneous[:3] / homogeneous[3]).T


def triangulate(
    calib: StereoCalibration,
    uv1: np.ndarray,
    uv2: np.ndarray,
    head_from_cam1: np.ndarray | None = None,
) -> np.ndarray:
    """Points (N, 3) m in H from detected pixels (N, 2) in each image at eye angle 0.

    ``head_from_cam1`` defaults to the one built from the calibration
    (:func:`head_from_cam1_from_extrinsics`).
    """
    transform = calib.head_from_cam1 if head_from_cam1 is None else head_from_cam1
    p_cam1 = triangulate_cam1(calib, uv1, uv2)
    return p_cam1 @ transform[:3, :3].T + transform[:3, 3]


@dataclass(frozen=True)
class StereoMeasurement:
    """A target measured by calibrated stereo at eye angle 0.

    ``uv1``, ``uv2`` px: its detections; ``p_head`` m: the estimate in H;
    ``true_p_head`` m: the simulator's; ``error_m`` = estimate - truth.
    """

    uv1: tuple[float, float]
    uv2: tuple[float, float]
    p_head: np.ndarray
    true_p_head: np.ndarray

    @property
    def error_m(self) -> np.ndarray:
        return self.p_head - self.true_p_head

    @property
    def error_norm_m(self) -> float:
        return float(np.linalg.norm(self.error_m))

    @property
    def error_rel_depth(self) -> float:
        """3-D error as a fraction of the true depth z_h."""
        return self.error_norm_m / float(self.true_p_head[2])


Detector = Callable[[np.ndarray], Detection]


def marker_detector(target: str) -> Detector:
    """``find_marker`` for a marker named ``marker_<colour>``."""
    colour = target.removeprefix("marker_")
    return lambda image: find_marker(image, colour)


#: How a camera's next image is detected in: ``look(head, camera, detector)``.
Look = Callable[[ServoHead, int, Detector], Detection]


def full_frame(head: ServoHead, camera: int, detector: Detector) -> Detection:
    """``detector`` on ``camera``'s next image, the full frame."""
    return detector(head.render(camera))


def detect_pair(
    head: ServoHead, target: str, detector: Detector | None = None, look: Look | None = None
) -> tuple[tuple[float, float], tuple[float, float]]:
    """The body ``target``'s pixel in each eye's next image (camera 1's, camera 2's) at
    eye angle 0, px: the head's images alone.

    ``detector`` defaults to :func:`marker_detector` of ``target``.  ``look(head,
    camera, detector)`` detects in the camera's next image (default: the full frame;
    ``headsim.active.look.look_once`` grabs only where a preview shows the target).
    :class:`StereoError` when either camera misses it.
    """
    detect = detector or marker_detector(target)
    look = look or full_frame
    head.move(eye=0.0)
    uvs = []
    for index in (1, 2):
        detection = look(head, index, detect)
        if not detection.found or detection.uv is None:
            raise StereoError(
                f"{target!r} not found in {names.CAMERAS[index - 1]}: {detection.status.value}"
            )
        uvs.append(detection.uv)
    return uvs[0], uvs[1]


def measure_point_stereo(
    head: ServoHead,
    calib: StereoCalibration,
    target: str,
    detector: Detector | None = None,
    head_from_cam1: np.ndarray | None = None,
    look: Look | None = None,
) -> StereoMeasurement:
    """Measure the body ``target`` in H (:func:`detect_pair`, then :func:`triangulate`),
    scored against its truth through ``head``'s truth channel."""
    uv1, uv2 = detect_pair(head, target, detector, look)
    p_head = triangulate(calib, np.array([uv1]), np.array([uv2]), head_from_cam1)[0]
    return StereoMeasurement(
        uv1=uv1, uv2=uv2, p_head=p_head, true_p_head=head.truth.position(target, "head")
    )
