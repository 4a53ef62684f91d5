"""Chessboard corners on real renders, scored against the true projection.

Every accuracy figure compares a corner with ``HeadSim.project`` of its true
world position (which includes the lens distortion).  MuJoCo's 4x multisampling quantises edge coverage to
quarter pixels: an edge parallel to the pixel grid is placed only to
+-0.125 px, which sets the floor of corner accuracy (see headsim.vision.detection).
"""

from __future__ import annotations

import numpy as np
import pytest

from headsim.geometry.transforms import rotation_x, rotation_y, rotation_z
from headsim.sim import names
from headsim.sim.settings import (
    paper_head,
)
from headsim.sim.simulator import HeadSim
from headsim.vision.chessboard import (
    find_chessboard,
    orient_grid,
)
from headsim.vision.detection import DetectionStatus

from .helpers import (
    BOARD_CENTRE,
    PATTERN,
    PRESETS,
    board_corners_world,
    facing_head,
    place,
)


def _board_errors(
    sim: HeadSim, rng: np.random.Generator, trials: int, roll_rad: tuple[float, float]
) -> list[tuple[float, float]]:
    """(RMS, max) corner error px per image, board 0.5-1.0 m ahead, both eyes verged on it."""
    facing = facing_head(sim, names.CHESSBOARD)
    figures = []
    for _ in range(trials):
        depth = rng.uniform(0.5, 1.0)
        roll = rng.choice([-1.0, 1.0]) * rng.uniform(*roll_rad)
        rotation = (
            facing
            @ rotation_x(rng.uniform(-0.3, 0.3))
            @ rotation_y(rng.uniform(-0.3, 0.3))
            @ rotation_z(roll)
        )
        centre_head = [rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02), depth]
        centre = sim.transform_points(centre_head, "head", "world")[0]
        place(sim, names.CHESSBOARD, rotation, centre, BOARD_CENTRE)
        sim.move(eye=float(np.arctan2(0.075, depth) + rng.uniform(-0.02, 0.02)))
        for camera in (1, 2):
            detection = find_chessboard(sim.render(camera), PATTERN)
            assert detection.found, f"board not found at depth {depth:.2f} m, camera {camera}"
            assert detection.corners.shape == (48, 2)
            truth = sim.project(board_corners_world(sim, detection.indices), camera)
            errors = np.linalg.norm(detection.corners - truth, axis=1)
            figures.append((float(np.sqrt(np.mean(errors**2))), float(errors.max())))
    return figures


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_chessboard_corners_land_on_their_projections(preset: str) -> None:
    rng = np.random.default_rng(2)
    with HeadSim("chessboard", PRESETS[preset]()) as sim:
        # A board turned 0.1-0.3 rad in the image, as a hand-held one is.
        figures = _board_errors(sim, rng, trials=4, roll_rad=(0.1, 0.3))
    rms, worst = np.max(figures, axis=0)
    # Measured here over 40 images: worst RMS 0.07 px, max 0.16 px.
    assert rms <= 0.1, figures
    assert worst <= 0.25, figures


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_chessboard_square_to_the_pixel_grid_meets_the_multisampling_floor(preset: str) -> None:
    rng = np.random.default_rng(3)
    with HeadSim("chessboard", PRESETS[preset]()) as sim:
        figures = _board_errors(sim, rng, trials=3, roll_rad=(0.0, 0.0))
    rms, worst = np.max(figures, axis=0)
    # Edges parallel to pixel rows/columns are quantised to 1/4 px by 4x MSAA:
    # +-0.125 px per axis, uniform, i.e. 0.072 px RMS per axis and 0.10 px RMS
    # for a corner.  Measured here: worst RMS 0.105 px, max 0.21 px -- the
    # 0.1 px RMS target is not reachable for such boards with this renderer.
    assert rms <= 0.11, figures
    assert worst <= 0.25, figures


def test_chessboard_order_starts_top_left_in_the_image() -> None:
    with HeadSim("chessboard") as sim:
        facing = facing_head(sim, names.CHESSBOARD)
        centre = sim.transform_points([0.0, 0.0, 0.8], "head", "world")[0]
        # Upside down: the image's top-left inner corner is the board's (7, 5).
        place(sim, names.CHESSBOARD, facing @ rotation_z(np.pi), centre, BOARD_CENTRE)
        sim.move(eye=float(np.arctan2(0.075, 0.8)))
        detection = find_chessboard(sim.render(1))
        assert detection.found
        flipped = (np.array(PATTERN) - 1) - detection.indices
        truth = sim.project(board_corners_world(sim, flipped), 1)
        assert np.max(np.linalg.norm(detection.corners - truth, axis=1)) < 0.25
        assert detection.corners[0, 0] < detection.corners[1, 0]  # rows run left to right
        assert detection.corners[0, 1] < detection.corners[PATTERN[0], 1]  # rows run downwards


def test_orient_grid_undoes_every_order_opencv_may_return() -> None:
    columns, rows = PATTERN
    j, i = np.divmod(np.arange(columns * rows), columns)
    grid = np.column_stack([100.0 + 20 * i + 2 * j, 50.0 + 18 * j - i])  # a slightly turned grid
    cube = grid.reshape(rows, columns, 2)
    for variant in (cube, cube[::-1], cube[:, ::-1], cube[::-1, ::-1]):
        np.testing.assert_array_equal(orient_grid(variant.reshape(-1, 2), PATTERN), grid)
    square = grid.reshape(rows, columns, 2)[:, :rows].reshape(-1, 2)
    transposed = square.reshape(rows, rows, 2).transpose(1, 0, 2).reshape(-1, 2)
    np.testing.assert_array_equal(orient_grid(transposed, (rows, rows)), square)


def test_a_board_half_out_of_view_is_cut_and_a_missing_one_lost() -> None:
    with HeadSim("chessboard", paper_head()) as sim:
        facing = facing_head(sim, names.CHESSBOARD)
        place(sim, names.CHESSBOARD, facing, np.array([0.3, 0.7, 0.21]), BOARD_CENTRE)
        detection = find_chessboard(sim.render(1))
        assert detection.status is DetectionStatus.CUT
        assert detection.corners is None
        sim.set_body_pose(names.CHESSBOARD, [0.0, -2.0, 0.0])  # behind the head
        assert find_chessboard(sim.render(1)).status is DetectionStatus.LOST
    with HeadSim("blocks") as sim:  # one X-junction is no board
        assert find_chessboard(sim.render(1)).status is DetectionStatus.LOST


def test_a_pattern_too_small_names_the_problem() -> None:
    with pytest.raises(ValueError, match="pattern must be at least"):
        find_chessboard(np.zeros((48, 64, 3), np.uint8), (1, 6))
