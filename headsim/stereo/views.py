"""Chessboard views for the stereo baseline: seeded board poses, both eyes at eye angle 0.

Step 1 of the baseline (:func:`chessboard_views`): the scene's chessboard in
seeded random poses (:func:`sample_board_pose`, every pose fully in both
images), both eyes rendered at eye angle 0, inner corners detected with
OpenCV (:func:`detect_chessboard`).  Poses in the head frame H, m; pixels px.
The board is placed, and its true corners projected, through the head's truth
channel (the simulator's job); the corners are measured in the head's images alone
(:func:`board_view`).
:class:`StereoError` is what every step of the baseline raises when it
cannot proceed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

from headsim.geometry.transforms import rotation_x, rotation_y, rotation_z
from headsim.head.servo_head import ServoHead
from headsim.sim import names
from headsim.sim.optics import project_points, undistort_pixels
from headsim.sim.simulator import HeadSim
from headsim.vision.chessboard import find_chessboard


class StereoError(ValueError):
    """The stereo baseline cannot proceed (too few views, a target not seen, ...)."""


#: Inner corners of the scene's chessboard (columns, rows): models/scene_chessboard.xml.
CHESSBOARD_PATTERN = (8, 6)


#: Side of one chessboard square, m (paper Sec. VI-A).
CHESSBOARD_SQUARE_M = 0.03


def chessboard_object_points() -> np.ndarray:
    """Inner corners in the board frame (N, 3), m, row by row: (i, j) at (0.03 i, 0.03 j, 0)."""
    cols, rows = CHESSBOARD_PATTERN
    j, i = np.mgrid[0:rows, 0:cols]
    return np.column_stack(
        [i.ravel() * CHESSBOARD_SQUARE_M, j.ravel() * CHESSBOARD_SQUARE_M, np.zeros(i.size)]
    )


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
        cam = sim.truth.camera_settings(index)
        p_cam = sim.truth.transform_points(points_head, "head", names.CAMERAS[index - 1])
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
    cam = sim.truth.camera_settings(1)
    half_u, half_v = cam.width / 2 / cam.kx, cam.height / 2 / cam.ky
    for _ in range(max_attempts):
        distance = rng.uniform(lo, hi)
        ray = np.array([rng.uniform(-half_u, half_u), rng.uniform(-half_v, half_v), 1.0])
        centre_head = distance * ray / np.linalg.norm(ray)
        # Board axes start parallel to H (x right, y down, z away from the head).
        rotation = (
            rotation_z(rng.uniform(-max_roll_rad, max_roll_rad))
            @ rotation_x(rng.uniform(-max_tilt_rad, max_tilt_rad))
            @ rotation_y(rng.uniform(-max_tilt_rad, max_tilt_rad))
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
    world_from_board = sim.truth.world_from_head() @ head_from_board
    sim.set_body_pose(
        names.CHESSBOARD, world_from_board[:3, 3], _quat_from_rotation(world_from_board[:3, :3])
    )


def detect_chessboard(image: np.ndarray) -> np.ndarray | None:
    """Inner corners (N, 2) px of the scene's chessboard in board order, or None.

    :func:`headsim.vision.chessboard.find_chessboard`: corner k is board point
    (k % 8, k // 8) * 30 mm, the first one top-left in the image.
    """
    detection = find_chessboard(image, CHESSBOARD_PATTERN)
    if not detection.found or detection.corners is None:  # FOUND carries corners
        return None
    return detection.corners.astype(float)


#: How a camera's next image gives the board's corners: ``look(head, camera)``, (N, 2)
#: px in board order, or None.
BoardLook = Callable[[ServoHead, int], "np.ndarray | None"]


def full_frame_board(head: ServoHead, camera: int) -> np.ndarray | None:
    """:func:`detect_chessboard` on ``camera``'s next image, the full frame."""
    return detect_chessboard(head.render(camera))


def board_view(head: ServoHead, look: BoardLook) -> tuple[np.ndarray, np.ndarray] | None:
    """The board's corners (N, 2) px in each eye's next image (camera 1's, camera 2's),
    through ``look``; None when either misses it."""
    detected = [look(head, camera) for camera in (1, 2)]
    if detected[0] is None or detected[1] is None:
        return None
    return detected[0], detected[1]


def chessboard_views(
    head: ServoHead,
    n_poses: int,
    rng: np.random.Generator,
    distance_range_m: tuple[float, float] = (0.4, 1.0),
    max_tilt_rad: float = 0.6,
    look: BoardLook | None = None,
) -> ChessboardViews:
    """Show ``head`` the chessboard in ``n_poses`` random poses at eye angle 0 and detect
    its corners.

    ``head`` must see the chessboard scene.  The neck and eyes are moved to 0.  Each pose
    is drawn and the board placed through the head's truth channel; the corners come from
    the head's images (:func:`board_view`).  Views where either camera misses the board
    are dropped.  ``look(head, camera)`` gives the corners of the camera's next image
    (default: :func:`detect_chessboard` on the full frame;
    ``headsim.active.chessboard.look_for_board`` renders less).
    """
    look = look or full_frame_board
    if n_poses < 1:
        raise StereoError(f"n_poses must be >= 1, got {n_poses}")
    head.move(eye=0.0, neck_yaw=0.0, neck_pitch=0.0)
    world = head.truth  # placing the board and scoring its corners only
    world_from_head = world.world_from_head()
    object_points = chessboard_object_points()
    renders_before = head.render_count
    kept: list[tuple[np.ndarray, ...]] = []
    for _ in range(n_poses):
        head_from_board = sample_board_pose(world, rng, distance_range_m, max_tilt_rad)
        world_from_board = world_from_head @ head_from_board
        world.set_body_pose(
            names.CHESSBOARD, world_from_board[:3, 3], _quat_from_rotation(world_from_board[:3, :3])
        )
        detected = board_view(head, look)
        if detected is None:
            continue
        points_world = object_points @ world_from_board[:3, :3].T + world_from_board[:3, 3]
        truth = [world.project(points_world, camera) for camera in (1, 2)]
        kept.append((detected[0], detected[1], truth[0], truth[1], head_from_board))
    sizes = tuple((c.width, c.height) for c in head.settings.cameras)
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
        renders=head.render_count - renders_before,
    )
