"""Zhang calibration of each camera and of the pair, beside the simulator's truth.

Step 2 of the baseline (:func:`calibrate_stereo`): ``cv2.calibrateCamera`` per
camera (radial k1, k2; tangential and k3 fixed to 0, since the simulated lens
is radial), then ``cv2.stereoCalibrate`` for the pair.  OpenCV's stereo
extrinsics ``(R, T)`` map camera 1 to camera 2: ``cam2_from_cam1``
(:mod:`headsim.stereo.frames`).  Units: m, rad, px.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from headsim.codec import declared, doc
from headsim.geometry.transforms import invert_transform, rotation_angle
from headsim.head.servo_head import ServoHead
from headsim.stereo.frames import head_from_cam1_from_extrinsics
from headsim.stereo.views import ChessboardViews, StereoError

#: Fewest views (board found in both cameras) for a calibration with k1, k2.
MIN_VIEWS = 5


#: Calibration model: k1, k2 free; p1 = p2 = k3 = 0 (the simulated lens is radial).
CALIBRATION_FLAGS = cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3


_CALIB_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12)


#: Point undistortion: OpenCV's default 5 iterations are far too few for k1 = -0.39
#: (platform notes); 100 with a tight tolerance converge across the image.
UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-14)


def undistort_normalized_points(uv: np.ndarray, K: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """Distorted pixels (N, 2) -> undistorted normalised coordinates (N, 2) with OpenCV."""
    uv = np.atleast_2d(np.asarray(uv, dtype=float)).reshape(-1, 1, 2)
    xy = cv2.undistortPoints(uv, K, dist, criteria=UNDISTORT_CRITERIA)
    return xy.reshape(-1, 2)


@declared
class CameraCalibration:
    """One camera's Zhang calibration beside the simulator's truth.

    ``K`` (3, 3) px and ``dist`` (k1, k2, p1, p2, k3) as OpenCV returns them;
    ``rms_px`` the reprojection RMS of the fit that gave them
    (``calibrateCamera``, or ``stereoCalibrate`` over both cameras when it
    refined them); ``true_K``, ``true_dist`` the simulator's;
    ``image_size`` (width, height) px.
    """

    K: np.ndarray = doc("the fitted camera matrix, px", shape=(3, 3))
    dist: np.ndarray = doc("the fitted k1, k2, p1, p2, k3", shape=(5,))
    rms_px: float = doc("the fit's reprojection RMS, px")
    true_K: np.ndarray = doc("the simulator's camera matrix, px", shape=(3, 3))
    true_dist: np.ndarray = doc("the simulator's distortion", shape=(5,))
    image_size: tuple[int, int] = doc("width, height, px")

    @property
    def focal_rel_errors(self) -> tuple[float, float]:
        """Relative errors of (kx, ky): estimate / truth - 1."""
        return (
            float(self.K[0, 0] / self.true_K[0, 0] - 1.0),
            float(self.K[1, 1] / self.true_K[1, 1] - 1.0),
        )

    @property
    def principal_errors_px(self) -> tuple[float, float]:
        """Errors of (cx, cy), estimate - truth, px."""
        return (
            float(self.K[0, 2] - self.true_K[0, 2]),
            float(self.K[1, 2] - self.true_K[1, 2]),
        )

    @property
    def k1_error(self) -> float:
        """Error of k1, estimate - truth."""
        return float(self.dist[0] - self.true_dist[0])

    @property
    def centre_ray_yaw_rad(self) -> float:
        """Horizontal angle of the image centre's ray off the optical axis, rad, + towards x.

        From the calibrated K and distortion; the image centre is
        ((W - 1) / 2, (H - 1) / 2).  What separates the paper's effective
        initial direction (Sec. V) from the camera's mount yaw.
        """
        width, height = self.image_size
        centre = np.array([[(width - 1) / 2, (height - 1) / 2]])
        return math.atan(float(undistort_normalized_points(centre, self.K, self.dist)[0, 0]))


@declared
class StereoCalibration:
    """The pair's calibration at eye angle 0 beside the simulator's truth.

    ``mono1``/``mono2``: each camera's ``calibrateCamera`` result;
    ``cam1``/``cam2``: the intrinsics used for measuring (refined by
    ``stereoCalibrate`` when ``refined``, else the mono ones);
    ``cam2_from_cam1`` (4, 4) from ``stereoCalibrate`` (OpenCV's R, T) and
    ``stereo_rms_px`` its reprojection RMS over both cameras;
    ``true_cam2_from_cam1`` and ``true_head_from_cam1`` from the simulator.
    """

    mono1: CameraCalibration = doc("camera 1's calibrateCamera result")
    mono2: CameraCalibration = doc("camera 2's calibrateCamera result")
    cam1: CameraCalibration = doc("camera 1's intrinsics used for measuring")
    cam2: CameraCalibration = doc("camera 2's intrinsics used for measuring")
    stereo_rms_px: float = doc("stereoCalibrate's reprojection RMS over both cameras, px")
    cam2_from_cam1: np.ndarray = doc("OpenCV's R, T as a transform", shape=(4, 4))
    true_cam2_from_cam1: np.ndarray = doc("the simulator's", shape=(4, 4))
    true_head_from_cam1: np.ndarray = doc("camera 1 in H, the simulator's", shape=(4, 4))
    views: int = doc("chessboard views used")
    refined: bool = doc("whether stereoCalibrate refined the intrinsics")

    @property
    def R(self) -> np.ndarray:
        """OpenCV's R: rotation of camera 1's frame into camera 2's (3, 3)."""
        return self.cam2_from_cam1[:3, :3]

    @property
    def T(self) -> np.ndarray:
        """OpenCV's T: camera 1's origin in camera 2's frame (3,), m."""
        return self.cam2_from_cam1[:3, 3]

    @property
    def baseline_m(self) -> float:
        """Calibrated distance between the optical centres, m."""
        return float(np.linalg.norm(self.T))

    @property
    def true_baseline_m(self) -> float:
        return float(np.linalg.norm(self.true_cam2_from_cam1[:3, 3]))

    @property
    def rotation_error_rad(self) -> float:
        """Angle of the rotation between the calibrated and the true R, rad."""
        return rotation_angle(self.R @ self.true_cam2_from_cam1[:3, :3].T)

    @property
    def head_from_cam1(self) -> np.ndarray:
        """Camera 1's pose in H built from the calibrated extrinsics (module docstring)."""
        return head_from_cam1_from_extrinsics(self.cam2_from_cam1)


def _calibrate_camera(
    views: ChessboardViews, index: int, true_K: np.ndarray, true_dist: np.ndarray
) -> CameraCalibration:
    image_points = views.image_points1 if index == 1 else views.image_points2
    object_list = [views.object_points.astype(np.float32)] * views.count
    image_list = [p.astype(np.float32) for p in image_points]
    rms, K, dist, _, _ = cv2.calibrateCamera(
        object_list,
        image_list,
        views.image_sizes[index - 1],
        None,
        None,
        flags=CALIBRATION_FLAGS,
        criteria=_CALIB_CRITERIA,
    )
    return CameraCalibration(
        K=np.asarray(K, dtype=float),
        dist=np.asarray(dist, dtype=float).ravel()[:5],
        rms_px=float(rms),
        true_K=np.asarray(true_K, dtype=float),
        true_dist=np.asarray(true_dist, dtype=float),
        image_size=views.image_sizes[index - 1],
    )


def calibrate_stereo(
    head: ServoHead, views: ChessboardViews, refine_intrinsics: bool = True
) -> StereoCalibration:
    """Calibrate each camera, then the pair, from ``views``; the truth beside it read
    through ``head``'s truth channel.

    With ``refine_intrinsics`` (default, as OpenCV's stereo sample does),
    ``stereoCalibrate`` starts from the per-camera K, k1, k2 and refines them
    with the extrinsics; otherwise it keeps them fixed.  Same distortion model
    throughout (``CALIBRATION_FLAGS``).  The truth is the simulator's at eye
    angle 0 (``head``'s eyes are moved there).
    """
    if views.count < MIN_VIEWS:
        raise StereoError(
            f"need at least {MIN_VIEWS} views with the board found in both cameras, got "
            f"{views.count} of {views.poses_tried} poses; render more poses"
        )
    head.move(eye=0.0)
    truth = head.truth  # scoring only
    mono = [
        _calibrate_camera(views, index, truth.camera_matrix(index), truth.dist_coeffs(index))
        for index in (1, 2)
    ]
    flags = CALIBRATION_FLAGS | (
        cv2.CALIB_USE_INTRINSIC_GUESS if refine_intrinsics else cv2.CALIB_FIX_INTRINSIC
    )
    object_list = [views.object_points.astype(np.float32)] * views.count
    rms, K1, d1, K2, d2, R, T, _, _ = cv2.stereoCalibrate(
        object_list,
        [p.astype(np.float32) for p in views.image_points1],
        [p.astype(np.float32) for p in views.image_points2],
        mono[0].K.copy(),
        mono[0].dist.copy(),
        mono[1].K.copy(),
        mono[1].dist.copy(),
        views.image_sizes[0],
        flags=flags,
        criteria=_CALIB_CRITERIA,
    )
    final = [
        CameraCalibration(
            K=np.asarray(K, dtype=float),
            dist=np.asarray(d, dtype=float).ravel()[:5],
            rms_px=float(rms),
            true_K=m.true_K,
            true_dist=m.true_dist,
            image_size=m.image_size,
        )
        for K, d, m in ((K1, d1, mono[0]), (K2, d2, mono[1]))
    ]
    cam2_from_cam1 = np.eye(4)
    cam2_from_cam1[:3, :3] = R
    cam2_from_cam1[:3, 3] = np.asarray(T, dtype=float).ravel()
    true_cam2_from_cam1 = invert_transform(truth.world_from_camera(2)) @ truth.world_from_camera(1)
    return StereoCalibration(
        mono1=mono[0],
        mono2=mono[1],
        cam1=final[0] if refine_intrinsics else mono[0],
        cam2=final[1] if refine_intrinsics else mono[1],
        stereo_rms_px=float(rms),
        cam2_from_cam1=cam2_from_cam1,
        true_cam2_from_cam1=true_cam2_from_cam1,
        true_head_from_cam1=truth.head_from_camera(1),
        views=views.count,
        refined=refine_intrinsics,
    )
