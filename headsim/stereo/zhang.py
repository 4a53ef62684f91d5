"""The calibrated-stereo baseline: Zhang calibration and triangulation at eye angle 0.

This is the traditional method the paper compares with (Sec. VI-B), run the
way practitioners run it on the simulator's rendered images:

1. :func:`chessboard_views`: the chessboard in seeded random poses, both eyes
   rendered at eye angle 0, inner corners detected with OpenCV.
2. :func:`calibrate_stereo`: ``cv2.calibrateCamera`` per camera (radial k1, k2;
   tangential and k3 fixed to 0, since the simulated lens is radial), then
   ``cv2.stereoCalibrate`` for the pair, beside the simulator's truth.
3. :func:`triangulate`: undistort detected pixels with the calibration,
   ``cv2.triangulatePoints`` in camera 1's frame, then map into the head frame H.

Frames (README "Frames"): Ci is camera i's OpenCV frame, H the head frame.
OpenCV's stereo extrinsics ``(R, T)`` map camera 1 to camera 2,
``x2 = R x1 + T``, i.e. ``cam2_from_cam1 = [[R, T], [0, 1]]``.  Units: m, rad, px.

**H from the calibration** (:func:`head_from_cam1_from_extrinsics`): the origin
is the midpoint of the two calibrated optical centres, x points from C1 to C2,
y is the mean of the two cameras' y axes made orthogonal to x, z = x cross y.
At eye angle 0 both cameras are turned only about the eye axes, which are
parallel to H's y, so with zero mount pitch and roll this is H exactly (up to
calibration error) for any mount yaws.  The paper's own construction, a
rotation by the eye's calibrated initial direction about y_c1 and a shift of
D/2 along x (:func:`head_from_cam1_from_eye`), is there for comparison.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import cv2
import mujoco
import numpy as np

from headsim.sim import names
from headsim.sim.optics import project_points, undistort_pixels
from headsim.sim.simulator import HeadSim, invert_transform
from headsim.vision.detect import Detection, find_chessboard, find_marker

#: Inner corners of the scene's chessboard (columns, rows): headsim/models/scene_chessboard.xml.
CHESSBOARD_PATTERN = (8, 6)
#: Side of one chessboard square, m (paper Sec. VI-A).
CHESSBOARD_SQUARE_M = 0.03
#: Fewest views (board found in both cameras) for a calibration with k1, k2.
MIN_VIEWS = 5

#: Calibration model: k1, k2 free; p1 = p2 = k3 = 0 (the simulated lens is radial).
CALIBRATION_FLAGS = cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3
_CALIB_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12)
#: Point undistortion: OpenCV's default 5 iterations are far too few for k1 = -0.39
#: (platform notes); 100 with a tight tolerance converge across the image.
UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-14)


class StereoError(ValueError):
    """The stereo baseline cannot proceed (too few views, a target not seen, ...)."""


def chessboard_object_points() -> np.ndarray:
    """Inner corners in the board frame (N, 3), m, row by row: (i, j) at (0.03 i, 0.03 j, 0)."""
    cols, rows = CHESSBOARD_PATTERN
    j, i = np.mgrid[0:rows, 0:cols]
    return np.column_stack(
        [i.ravel() * CHESSBOARD_SQUARE_M, j.ravel() * CHESSBOARD_SQUARE_M, np.zeros(i.size)]
    )


# -- views -------------------------------------------------------------------


@dataclass(frozen=True)
class ChessboardViews:
    """Chessboard corners seen by both cameras at eye angle 0.

    ``image_points1/2`` (V, N, 2) px are the detected corners of the V kept
    views, in the order of ``object_points`` (N, 3) m, board frame;
    ``true_points1/2`` the simulator's projections of the same corners (for
    scoring only); ``head_from_board`` (V, 4, 4) the true board poses.
    ``image_sizes`` are (width, height) px per camera.  ``poses_tried`` poses
    were rendered, costing ``renders`` images.
    """

    object_points: np.ndarray
    image_points1: np.ndarray
    image_points2: np.ndarray
    true_points1: np.ndarray
    true_points2: np.ndarray
    head_from_board: np.ndarray
    image_sizes: tuple[tuple[int, int], tuple[int, int]]
    poses_tried: int
    renders: int

    @property
    def count(self) -> int:
        """Number of views with the board found in both cameras."""
        return int(self.image_points1.shape[0])

    def corner_errors_px(self) -> np.ndarray:
        """Distance of each detected corner from its true projection (2, V, N), px."""
        return np.stack(
            [
                np.linalg.norm(self.image_points1 - self.true_points1, axis=-1),
                np.linalg.norm(self.image_points2 - self.true_points2, axis=-1),
            ]
        )


def _rotation(axis: int, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    rotation = np.eye(3)
    rotation[i, i] = rotation[j, j] = c
    rotation[i, j], rotation[j, i] = -s, s
    return rotation


def _board_outline() -> np.ndarray:
    """Points along the board's outer squares plus half a square of white, board frame (M, 3)."""
    cols, rows = CHESSBOARD_PATTERN
    s = CHESSBOARD_SQUARE_M
    x0, x1 = -1.5 * s, cols * s + 0.5 * s
    y0, y1 = -1.5 * s, rows * s + 0.5 * s
    t = np.linspace(0.0, 1.0, 9)
    edges = [
        np.column_stack([x0 + (x1 - x0) * t, np.full_like(t, y0)]),
        np.column_stack([x0 + (x1 - x0) * t, np.full_like(t, y1)]),
        np.column_stack([np.full_like(t, x0), y0 + (y1 - y0) * t]),
        np.column_stack([np.full_like(t, x1), y0 + (y1 - y0) * t]),
    ]
    xy = np.concatenate(edges)
    return np.column_stack([xy, np.zeros(len(xy))])


def _fully_visible(sim: HeadSim, points_head: np.ndarray, margin_px: float) -> bool:
    """True when both cameras image every point inside the image, on the lens's valid branch."""
    for index in (1, 2):
        cam = sim.camera_settings(index)
        p_cam = sim.transform_points(points_head, "head", names.CAMERAS[index - 1])
        if np.any(p_cam[:, 2] <= 0.05):
            return False
        uv = project_points(p_cam, cam)
        inside = (
            (uv[:, 0] >= margin_px)
            & (uv[:, 0] <= cam.width - 1 - margin_px)
            & (uv[:, 1] >= margin_px)
            & (uv[:, 1] <= cam.height - 1 - margin_px)
        )
        if not np.all(inside):
            return False
        # A point beyond the radius where the lens folds over can land inside
        # the image; it must map back to its own pinhole projection.
        back = undistort_pixels(uv, cam)
        pinhole = p_cam[:, :2] / p_cam[:, 2:3] * [cam.kx, cam.ky] + cam.principal
        if not np.all(np.linalg.norm(back - pinhole, axis=1) < 1e-3):
            return False
    return True


def sample_board_pose(
    sim: HeadSim,
    rng: np.random.Generator,
    distance_range_m: tuple[float, float] = (0.4, 1.0),
    max_tilt_rad: float = 0.6,
    max_roll_rad: float = 0.25,
    margin_px: float = 6.0,
    max_attempts: int = 2000,
) -> np.ndarray:
    """A random ``head_from_board`` (4, 4) with the whole board in both images.

    The board's centre is at a random distance along a random ray inside
    camera 1's field; the board is tilted about its x and y axes by up to
    ``max_tilt_rad`` each and rolled by up to ``max_roll_rad``.  Poses are
    drawn until the simulator's true projection puts the board (with a
    margin) in both images, as an operator would move it into view.
    """
    lo, hi = distance_range_m
    if not 0 < lo <= hi:
        raise StereoError(f"distance_range_m must satisfy 0 < low <= high, got {distance_range_m}")
    cols, rows = CHESSBOARD_PATTERN
    centre_board = np.array([(cols - 1) / 2, (rows - 1) / 2, 0.0]) * CHESSBOARD_SQUARE_M
    outline = _board_outline()
    cam = sim.camera_settings(1)
    half_u, half_v = cam.width / 2 / cam.kx, cam.height / 2 / cam.ky
    for _ in range(max_attempts):
        distance = rng.uniform(lo, hi)
        ray = np.array([rng.uniform(-half_u, half_u), rng.uniform(-half_v, half_v), 1.0])
        centre_head = distance * ray / np.linalg.norm(ray)
        # Board axes start parallel to H (x right, y down, z away from the head).
        rotation = (
            _rotation(2, rng.uniform(-max_roll_rad, max_roll_rad))
            @ _rotation(0, rng.uniform(-max_tilt_rad, max_tilt_rad))
            @ _rotation(1, rng.uniform(-max_tilt_rad, max_tilt_rad))
        )
        head_from_board = np.eye(4)
        head_from_board[:3, :3] = rotation
        head_from_board[:3, 3] = centre_head - rotation @ centre_board
        points_head = outline @ rotation.T + head_from_board[:3, 3]
        if _fully_visible(sim, points_head, margin_px):
            return head_from_board
    raise StereoError(
        f"no board pose within {distance_range_m} m is fully visible in both cameras "
        f"after {max_attempts} attempts; widen the distance range"
    )


def _quat_from_rotation(rotation: np.ndarray) -> np.ndarray:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(rotation).reshape(9))
    return quat


def place_chessboard(sim: HeadSim, head_from_board: np.ndarray) -> None:
    """Put the scene's chessboard at ``head_from_board`` (4, 4), a pose in H."""
    world_from_board = sim.world_from_head() @ head_from_board
    sim.set_body_pose(
        names.CHESSBOARD, world_from_board[:3, 3], _quat_from_rotation(world_from_board[:3, :3])
    )


def detect_chessboard(image: np.ndarray) -> np.ndarray | None:
    """Inner corners (N, 2) px of the scene's chessboard in board order, or None.

    :func:`headsim.vision.detect.find_chessboard`: corner k is board point
    (k % 8, k // 8) * 30 mm, the first one top-left in the image.
    """
    detection = find_chessboard(image, CHESSBOARD_PATTERN)
    if not detection.found or detection.corners is None:  # FOUND carries corners
        return None
    return detection.corners.astype(float)


def chessboard_views(
    sim: HeadSim,
    n_poses: int,
    rng: np.random.Generator,
    distance_range_m: tuple[float, float] = (0.4, 1.0),
    max_tilt_rad: float = 0.6,
) -> ChessboardViews:
    """Render the chessboard in ``n_poses`` random poses at eye angle 0 and detect its corners.

    ``sim`` must hold the chessboard scene.  The neck and eyes are moved to 0.
    Views where either camera misses the board are dropped.
    """
    if n_poses < 1:
        raise StereoError(f"n_poses must be >= 1, got {n_poses}")
    sim.move(eye=0.0, neck_yaw=0.0, neck_pitch=0.0)
    world_from_head = sim.world_from_head()
    object_points = chessboard_object_points()
    renders_before = sim.render_count
    kept: list[tuple[np.ndarray, ...]] = []
    for _ in range(n_poses):
        head_from_board = sample_board_pose(sim, rng, distance_range_m, max_tilt_rad)
        world_from_board = world_from_head @ head_from_board
        sim.set_body_pose(
            names.CHESSBOARD, world_from_board[:3, 3], _quat_from_rotation(world_from_board[:3, :3])
        )
        detected = [detect_chessboard(sim.render(camera)) for camera in (1, 2)]
        if detected[0] is None or detected[1] is None:
            continue
        points_world = object_points @ world_from_board[:3, :3].T + world_from_board[:3, 3]
        truth = [sim.project(points_world, camera) for camera in (1, 2)]
        kept.append((detected[0], detected[1], truth[0], truth[1], head_from_board))
    sizes = tuple((c.width, c.height) for c in sim.settings.cameras)
    empty = np.zeros((0, len(object_points), 2))
    stacked = [np.array([k[i] for k in kept]) if kept else empty for i in range(4)]
    return ChessboardViews(
        object_points=object_points,
        image_points1=stacked[0],
        image_points2=stacked[1],
        true_points1=stacked[2],
        true_points2=stacked[3],
        head_from_board=np.array([k[4] for k in kept]) if kept else np.zeros((0, 4, 4)),
        image_sizes=(sizes[0], sizes[1]),
        poses_tried=n_poses,
        renders=sim.render_count - renders_before,
    )


# -- calibration ---------------------------------------------------------------


@dataclass(frozen=True)
class CameraCalibration:
    """One camera's Zhang calibration beside the simulator's truth.

    ``K`` (3, 3) px and ``dist`` (k1, k2, p1, p2, k3) as OpenCV returns them;
    ``rms_px`` the reprojection RMS of the fit that gave them
    (``calibrateCamera``, or ``stereoCalibrate`` over both cameras when it
    refined them); ``true_K``, ``true_dist`` the simulator's;
    ``image_size`` (width, height) px.
    """

    K: np.ndarray
    dist: np.ndarray
    rms_px: float
    true_K: np.ndarray
    true_dist: np.ndarray
    image_size: tuple[int, int]

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


@dataclass(frozen=True)
class StereoCalibration:
    """The pair's calibration at eye angle 0 beside the simulator's truth.

    ``mono1``/``mono2``: each camera's ``calibrateCamera`` result;
    ``cam1``/``cam2``: the intrinsics used for measuring (refined by
    ``stereoCalibrate`` when ``refined``, else the mono ones);
    ``cam2_from_cam1`` (4, 4) from ``stereoCalibrate`` (OpenCV's R, T) and
    ``stereo_rms_px`` its reprojection RMS over both cameras;
    ``true_cam2_from_cam1`` and ``true_head_from_cam1`` from the simulator.
    """

    mono1: CameraCalibration
    mono2: CameraCalibration
    cam1: CameraCalibration
    cam2: CameraCalibration
    stereo_rms_px: float
    cam2_from_cam1: np.ndarray
    true_cam2_from_cam1: np.ndarray
    true_head_from_cam1: np.ndarray
    views: int
    refined: bool

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


def rotation_angle(rotation: np.ndarray) -> float:
    """Angle of a rotation matrix, rad."""
    cos = (float(np.trace(rotation)) - 1.0) / 2.0
    return math.acos(min(1.0, max(-1.0, cos)))


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
    sim: HeadSim, views: ChessboardViews, refine_intrinsics: bool = True
) -> StereoCalibration:
    """Calibrate each camera, then the pair, from ``views``; truth read from ``sim``.

    With ``refine_intrinsics`` (default, as OpenCV's stereo sample does),
    ``stereoCalibrate`` starts from the per-camera K, k1, k2 and refines them
    with the extrinsics; otherwise it keeps them fixed.  Same distortion model
    throughout (``CALIBRATION_FLAGS``).  The truth is the simulator's at eye
    angle 0 (``sim``'s eyes are moved there).
    """
    if views.count < MIN_VIEWS:
        raise StereoError(
            f"need at least {MIN_VIEWS} views with the board found in both cameras, got "
            f"{views.count} of {views.poses_tried} poses; render more poses"
        )
    sim.move(eye=0.0)
    mono = [
        _calibrate_camera(views, index, sim.camera_matrix(index), sim.dist_coeffs(index))
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
    true_cam2_from_cam1 = invert_transform(sim.world_from_camera(2)) @ sim.world_from_camera(1)
    return StereoCalibration(
        mono1=mono[0],
        mono2=mono[1],
        cam1=final[0] if refine_intrinsics else mono[0],
        cam2=final[1] if refine_intrinsics else mono[1],
        stereo_rms_px=float(rms),
        cam2_from_cam1=cam2_from_cam1,
        true_cam2_from_cam1=true_cam2_from_cam1,
        true_head_from_cam1=sim.head_from_camera(1),
        views=views.count,
        refined=refine_intrinsics,
    )


# -- head frame ----------------------------------------------------------------


def head_from_cam1_from_extrinsics(cam2_from_cam1: np.ndarray) -> np.ndarray:
    """H built from the stereo extrinsics: camera 1's pose in it (4, 4).

    Origin: midpoint of C1 and C2.  x: from C1 to C2.  y: the mean of the two
    cameras' y axes, made orthogonal to x.  z = x cross y.  Exact at eye angle
    0 when the mounts are turned only about the eye axes (H's y).
    """
    cam1_from_cam2 = invert_transform(cam2_from_cam1)
    c2 = cam1_from_cam2[:3, 3]  # C2 in camera 1's frame; C1 is the origin
    x_axis = c2 / np.linalg.norm(c2)
    y_mean = np.array([0.0, 1.0, 0.0]) + cam1_from_cam2[:3, 1]
    y_axis = y_mean - (y_mean @ x_axis) * x_axis
    y_axis /= np.linalg.norm(y_axis)
    z_axis = np.cross(x_axis, y_axis)
    cam1_from_head = np.eye(4)
    cam1_from_head[:3, :3] = np.column_stack([x_axis, y_axis, z_axis])
    cam1_from_head[:3, 3] = c2 / 2
    return invert_transform(cam1_from_head)


def head_from_cam1_from_eye(initial_direction_rad: float, baseline_m: float) -> np.ndarray:
    """The paper's H (Sec. VI-B): turn by camera 1's initial direction about y_c1, shift D/2.

    Camera 1 sits at (-D/2, 0, 0) in H, turned inward (towards +x) by
    ``initial_direction_rad`` about H's y.  That angle must be the optical
    axis's, i.e. the mount yaw: the Sec. V calibration measures the image
    centre's ray instead; subtract :attr:`CameraCalibration.centre_ray_yaw_rad`
    from it first.
    """
    head_from_cam1 = np.eye(4)
    head_from_cam1[:3, :3] = _rotation(1, initial_direction_rad)
    head_from_cam1[:3, 3] = [-baseline_m / 2, 0.0, 0.0]
    return head_from_cam1


def frame_deviation(estimate: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """(rotation angle rad, translation distance m) between two poses of one frame (4, 4)."""
    delta = invert_transform(truth) @ estimate
    return rotation_angle(delta[:3, :3]), float(np.linalg.norm(delta[:3, 3]))


# -- triangulation -------------------------------------------------------------


def undistort_normalized_points(uv: np.ndarray, K: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """Distorted pixels (N, 2) -> undistorted normalised coordinates (N, 2) with OpenCV."""
    uv = np.atleast_2d(np.asarray(uv, dtype=float)).reshape(-1, 1, 2)
    xy = cv2.undistortPoints(uv, K, dist, criteria=UNDISTORT_CRITERIA)
    return xy.reshape(-1, 2)


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


# -- measuring a target ----------------------------------------------------------


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


def measure_point_stereo(
    sim: HeadSim,
    calib: StereoCalibration,
    target: str,
    detector: Detector | None = None,
    head_from_cam1: np.ndarray | None = None,
) -> StereoMeasurement:
    """Measure the body ``target`` in H: eye angle 0, render both cameras, detect, triangulate.

    ``detector`` defaults to :func:`marker_detector` of ``target``.
    """
    detect = detector or marker_detector(target)
    sim.move(eye=0.0)
    uvs = []
    for index in (1, 2):
        detection = detect(sim.render(index))
        if not detection.found or detection.uv is None:
            raise StereoError(
                f"{target!r} not found in {names.CAMERAS[index - 1]}: {detection.status.value}"
            )
        uvs.append(detection.uv)
    p_head = triangulate(calib, np.array([uvs[0]]), np.array([uvs[1]]), head_from_cam1)[0]
    return StereoMeasurement(
        uv1=uvs[0], uv2=uvs[1], p_head=p_head, true_p_head=sim.position(target, "head")
    )
