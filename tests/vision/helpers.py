"""Scenes, placements and the true projection shared by the vision tests."""

from __future__ import annotations

import mujoco
import numpy as np

from headsim.sim import names
from headsim.sim.settings import ideal_head, paper_head
from headsim.sim.simulator import HeadSim

PRESETS = {"ideal": ideal_head, "paper": paper_head}
#: The six objects of scene_blocks.xml and their materials' colours.
OBJECT_COLOURS = dict(
    zip(names.RELATIVE_OBJECTS, ("red", "green", "blue", "yellow", "magenta", "cyan"), strict=True)
)
#: Inner-corner spacing of scene_chessboard.xml, m.
SQUARE_M = 0.03
PATTERN = (8, 6)
#: Board centre in the board body frame (the middle inner corner), m.
BOARD_CENTRE = np.array([3.5 * SQUARE_M, 2.5 * SQUARE_M, 0.0])


def quat(rotation: np.ndarray) -> np.ndarray:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(rotation).reshape(9))
    return quat


def facing_head(sim: HeadSim, body: str) -> np.ndarray:
    """World rotation of a target body as the scene places it: facing the head at home."""
    return sim.data.body(body).xmat.reshape(3, 3).copy()


def place(sim: HeadSim, body: str, rotation: np.ndarray, point_world: np.ndarray, point_body):
    """Pose ``body`` so that its point ``point_body`` lies at ``point_world``."""
    sim.set_body_pose(body, point_world - rotation @ np.asarray(point_body), quat(rotation))


def board_corners_world(sim: HeadSim, indices: np.ndarray) -> np.ndarray:
    """World positions (N, 3) of the board's inner corners (i, j), m."""
    body = sim.data.body(names.CHESSBOARD)
    local = np.column_stack([SQUARE_M * indices, np.zeros(len(indices))])
    return local @ body.xmat.reshape(3, 3).T + body.xpos


def point_at_pixel(sim: HeadSim, camera: int, uv, depth_m: float) -> np.ndarray:
    """World point at ``depth_m`` on the pinhole ray through pixel ``uv`` of an undistorted camera."""
    k = sim.camera_matrix(camera)
    p_cam = np.array([(uv[0] - k[0, 2]) / k[0, 0], (uv[1] - k[1, 2]) / k[1, 1], 1.0]) * depth_m
    return sim.transform_points(p_cam, names.CAMERAS[camera - 1], "world")[0]


def error_px(detected, truth: np.ndarray) -> float:
    return float(np.linalg.norm(np.asarray(detected) - truth))
