"""Feature detection on real renders, scored against the true projection.

Every accuracy figure here compares a detector's sub-pixel position with
``HeadSim.project`` of the target's true world position (which includes the
lens distortion).  MuJoCo's 4x multisampling quantises edge coverage to
quarter pixels: an edge parallel to the pixel grid is placed only to
+-0.125 px, which sets the floor of corner accuracy (see headsim.vision.detect).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest

from headsim.geometry.transforms import rotation_x, rotation_y, rotation_z
from headsim.sim import names
from headsim.sim.model import MODELS_DIR
from headsim.sim.settings import (
    CameraSettings,
    HeadSettings,
    RenderFidelity,
    ideal_head,
    paper_head,
)
from headsim.sim.simulator import HeadSim
from headsim.vision.detect import (
    DetectionStatus,
    find_chessboard,
    find_cross_point,
    find_marker,
    find_markers,
    orient_grid,
)

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


def _quat(rotation: np.ndarray) -> np.ndarray:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(rotation).reshape(9))
    return quat


def _facing_head(sim: HeadSim, body: str) -> np.ndarray:
    """World rotation of a target body as the scene places it: facing the head at home."""
    return sim.data.body(body).xmat.reshape(3, 3).copy()


def _place(sim: HeadSim, body: str, rotation: np.ndarray, point_world: np.ndarray, point_body):
    """Pose ``body`` so that its point ``point_body`` lies at ``point_world``."""
    sim.set_body_pose(body, point_world - rotation @ np.asarray(point_body), _quat(rotation))


def _board_corners_world(sim: HeadSim, indices: np.ndarray) -> np.ndarray:
    """World positions (N, 3) of the board's inner corners (i, j), m."""
    body = sim.data.body(names.CHESSBOARD)
    local = np.column_stack([SQUARE_M * indices, np.zeros(len(indices))])
    return local @ body.xmat.reshape(3, 3).T + body.xpos


def _point_at_pixel(sim: HeadSim, camera: int, uv, depth_m: float) -> np.ndarray:
    """World point at ``depth_m`` on the pinhole ray through pixel ``uv`` of an undistorted camera."""
    k = sim.camera_matrix(camera)
    p_cam = np.array([(uv[0] - k[0, 2]) / k[0, 0], (uv[1] - k[1, 2]) / k[1, 1], 1.0]) * depth_m
    return sim.transform_points(p_cam, names.CAMERAS[camera - 1], "world")[0]


def _error_px(detected, truth: np.ndarray) -> float:
    return float(np.linalg.norm(np.asarray(detected) - truth))


# -- markers --------------------------------------------------------------------


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_marker_centroid_holds_in_noisy_images(preset: str, rng) -> None:
    base = PRESETS[preset]()
    noisy = replace(base, cameras=tuple(replace(c, noise_std=2.0) for c in base.cameras))
    errors = []
    with HeadSim("default", noisy) as sim:
        marker = names.MARKERS[0]
        for _ in range(6):
            target = [rng.uniform(-0.08, 0.08), rng.uniform(0.45, 0.9), rng.uniform(0.15, 0.27)]
            sim.set_body_pose(marker, target)
            sim.move(eye=float(rng.uniform(-0.04, 0.12)), neck_yaw=float(rng.uniform(-0.05, 0.05)))
            for camera in (1, 2):
                detection = find_marker(sim.render(camera), "red")
                assert detection.found
                errors.append(_error_px(detection.uv, sim.project(sim.position(marker), camera)[0]))
    # Measured here: RMS 0.05 px, max 0.10 px (ideal); RMS 0.04, max 0.07 (paper).
    assert max(errors) < 0.15, f"errors px: {np.round(errors, 3)}"


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_six_labelled_objects_are_found_in_one_image(preset: str) -> None:
    with HeadSim("blocks", PRESETS[preset]()) as sim:
        for eye, neck_yaw in ((0.0, 0.0), (0.1, -0.03)):
            sim.move(eye=eye, neck_yaw=neck_yaw)
            for camera in (1, 2):
                detections = find_markers(sim.render(camera), OBJECT_COLOURS)
                assert set(detections) == set(OBJECT_COLOURS)
                for label, detection in detections.items():
                    assert detection.found, f"{label}: {detection}"
                    truth = sim.project(sim.position(label), camera)[0]
                    assert _error_px(detection.uv, truth) < 0.15, label


def test_each_label_has_its_own_status() -> None:
    with HeadSim("blocks") as sim:
        sim.set_body_pose("object_3", [0.0, -1.0, 0.2])  # behind the head
        detections = find_markers(sim.render(1), OBJECT_COLOURS)
        assert detections["object_3"].status is DetectionStatus.LOST
        assert all(d.found for label, d in detections.items() if label != "object_3")
        # A sequence of colours labels the detections by colour.
        assert set(find_markers(sim.render(1), ["red", "cyan"])) == {"red", "cyan"}


def test_marker_partly_behind_the_plate_is_occluded_given_its_expected_area() -> None:
    with HeadSim("blocks") as sim:
        sim.move(eye=0.05)
        eye = sim.world_from_camera(1)[:3, 3]  # Ca1's optical centre
        plate_edge = sim.position(names.BLOCKS) + np.array(
            [0.05, 0.0, 0.0]
        )  # the plate's right edge
        ray = plate_edge - eye
        half_hidden = (
            eye + ray * (plate_edge[1] + 0.03 - eye[1]) / ray[1]
        )  # 3 cm behind the plate, on its edge
        marker = names.RELATIVE_OBJECTS[0]
        sim.set_body_pose(
            marker, half_hidden + np.array([0.04, 0.0, 0.0])
        )  # in the clear beside it
        clear = find_marker(sim.render(1), "red")
        assert clear.found

        sim.set_body_pose(marker, half_hidden)
        image = sim.render(1)
        hidden = find_marker(image, "red", expected_area_px=clear.area_px)
        assert hidden.status is DetectionStatus.OCCLUDED
        assert hidden.uv is None
        assert 0.3 * clear.area_px < hidden.area_px < 0.7 * clear.area_px
        # Without an expected area the half disc is a smaller, plausible blob:
        # FOUND, with the biased centroid that the area check exists to catch.
        unchecked = find_marker(image, "red")
        assert unchecked.found
        assert _error_px(unchecked.uv, sim.project(sim.position(marker), 1)[0]) > 1.0

        sim.set_body_pose(marker, sim.position(names.BLOCKS) + np.array([0.0, 0.05, 0.0]))
        assert find_marker(sim.render(1), "red").status is DetectionStatus.LOST


def test_marker_split_by_a_thin_bar_is_occluded(tmp_path: Path) -> None:
    scene = tmp_path / "scene_bar.xml"
    scene.write_text(
        f"""<mujoco model="bar_in_front">
  <include file="{MODELS_DIR / names.SCENES["default"]}"/>
  <worldbody>
    <body name="bar" mocap="true" pos="0 -1 0">
      <geom name="bar" type="box" size="0.001 0.001 0.05" rgba="0.5 0.5 0.5 1"
            contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>
"""
    )
    with HeadSim(scene) as sim:
        marker = names.MARKERS[0]
        assert find_marker(sim.render(1), "red").found
        eye = sim.world_from_camera(1)[:3, 3]  # Ca1's optical centre
        # On the line of sight, 5 cm in front of the marker: cuts it in two.
        sim.set_body_pose("bar", eye + 0.9 * (sim.position(marker) - eye))
        detection = find_marker(sim.render(1), "red")
        assert detection.status is DetectionStatus.OCCLUDED
        assert detection.uv is None


def test_bad_input_names_the_problem() -> None:
    image = np.zeros((48, 64, 3), np.uint8)
    with pytest.raises(ValueError, match="unknown marker colour 'pink'"):
        find_marker(image, "pink")
    with pytest.raises(ValueError, match="unknown marker colour 'pink'"):
        find_markers(image, {"thing": "pink"})
    with pytest.raises(ValueError, match="colours must be a mapping or a sequence"):
        find_markers(image, "red")
    with pytest.raises(ValueError, match=r"expected an RGB uint8 image \(H, W, 3\)"):
        find_marker(image[..., 0], "red")
    with pytest.raises(ValueError, match="pattern must be at least"):
        find_chessboard(image, (1, 6))


# -- chessboards ----------------------------------------------------------------


def _board_errors(
    sim: HeadSim, rng: np.random.Generator, trials: int, roll_rad: tuple[float, float]
) -> list[tuple[float, float]]:
    """(RMS, max) corner error px per image, board 0.5-1.0 m ahead, both eyes verged on it."""
    facing = _facing_head(sim, names.CHESSBOARD)
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
        _place(sim, names.CHESSBOARD, rotation, centre, BOARD_CENTRE)
        sim.move(eye=float(np.arctan2(0.075, depth) + rng.uniform(-0.02, 0.02)))
        for camera in (1, 2):
            detection = find_chessboard(sim.render(camera), PATTERN)
            assert detection.found, f"board not found at depth {depth:.2f} m, camera {camera}"
            assert detection.corners.shape == (48, 2)
            truth = sim.project(_board_corners_world(sim, detection.indices), camera)
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
        facing = _facing_head(sim, names.CHESSBOARD)
        centre = sim.transform_points([0.0, 0.0, 0.8], "head", "world")[0]
        # Upside down: the image's top-left inner corner is the board's (7, 5).
        _place(sim, names.CHESSBOARD, facing @ rotation_z(np.pi), centre, BOARD_CENTRE)
        sim.move(eye=float(np.arctan2(0.075, 0.8)))
        detection = find_chessboard(sim.render(1))
        assert detection.found
        flipped = (np.array(PATTERN) - 1) - detection.indices
        truth = sim.project(_board_corners_world(sim, flipped), 1)
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
        facing = _facing_head(sim, names.CHESSBOARD)
        _place(sim, names.CHESSBOARD, facing, np.array([0.3, 0.7, 0.21]), BOARD_CENTRE)
        detection = find_chessboard(sim.render(1))
        assert detection.status is DetectionStatus.CUT
        assert detection.corners is None
        sim.set_body_pose(names.CHESSBOARD, [0.0, -2.0, 0.0])  # behind the head
        assert find_chessboard(sim.render(1)).status is DetectionStatus.LOST
    with HeadSim("blocks") as sim:  # one X-junction is no board
        assert find_chessboard(sim.render(1)).status is DetectionStatus.LOST


# -- the cross point of two blocks --------------------------------------------------


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_cross_point_lands_on_its_projection_anywhere_in_the_image(preset: str) -> None:
    rng = np.random.default_rng(4)
    pixels = [(60, 60), (580, 420), (320, 240), (90, 400), (560, 90), (250, 150)]
    errors = []
    with HeadSim("blocks", PRESETS[preset]()) as sim:
        facing = _facing_head(sim, names.BLOCKS)
        for index, uv in enumerate(pixels):
            sim.move(eye=float(rng.uniform(0.0, 0.1)), neck_yaw=float(rng.uniform(-0.1, 0.1)))
            camera = 1 + index % 2
            rotation = (
                facing
                @ rotation_x(rng.uniform(-0.4, 0.4))
                @ rotation_y(rng.uniform(-0.4, 0.4))
                @ rotation_z(rng.uniform(-0.5, 0.5))
            )
            point = _point_at_pixel(sim, camera, uv, rng.uniform(0.5, 1.1))
            _place(sim, names.BLOCKS, rotation, point, np.zeros(3))
            detection = find_cross_point(sim.render(camera))
            assert detection.found, f"{detection} at {uv}"
            errors.append(
                _error_px(detection.uv, sim.project(sim.position(names.BLOCKS), camera)[0])
            )
    # Measured here over 160 random poses: RMS 0.065 px; ~2 % of poses above
    # 0.15 px (max 0.18 px), those with an edge within a few degrees of the
    # pixel grid, where multisampling quantises it to 1/4 px.
    assert max(errors) <= 0.15, np.round(errors, 3)


def test_cross_point_at_the_border_is_cut_and_outside_lost() -> None:
    with HeadSim("blocks") as sim:
        sim.move(eye=0.05)
        statuses = {}
        for u in (-40.0, 5.0, 634.0, 40.0):
            sim.set_body_pose(names.BLOCKS, _point_at_pixel(sim, 1, (u, 200.0), 0.7))
            statuses[u] = find_cross_point(sim.render(1)).status
    assert statuses == {
        -40.0: DetectionStatus.LOST,
        5.0: DetectionStatus.CUT,
        634.0: DetectionStatus.CUT,
        40.0: DetectionStatus.FOUND,
    }


def test_cross_point_behind_a_marker_is_occluded_or_lost() -> None:
    with HeadSim("blocks") as sim:
        sim.set_body_pose(names.BLOCKS, [0.0, 0.70, 0.21])  # near: the blocks 30 px a side
        sim.move(eye=0.05)
        cross = sim.position(names.BLOCKS)
        marker = names.RELATIVE_OBJECTS[0]
        assert find_cross_point(sim.render(1)).found
        # A 6 mm marker just in front of the plate, 10 mm to the side: it
        # covers part of the pattern around the junction, not the junction.
        sim.set_body_pose(marker, cross + np.array([0.01, -0.007, 0.0]))
        partly = find_cross_point(sim.render(1))
        assert partly.status is DetectionStatus.OCCLUDED
        assert partly.uv is None
        # Right on it: no junction is left to see.
        sim.set_body_pose(marker, cross + np.array([0.0, -0.007, 0.0]))
        assert find_cross_point(sim.render(1)).status is DetectionStatus.LOST


@pytest.mark.parametrize("fidelity", [(4, 1), (4, 2), (0, 2), (0, 3)])
@pytest.mark.parametrize("depth_m", [0.5, 0.7])
def test_a_partly_covered_cross_point_is_occluded_at_every_fidelity(
    fidelity: tuple[int, int], depth_m: float
) -> None:
    # The symmetry check must not depend on where a ChESS score happens to
    # cross its threshold: a 6 mm marker 10 mm from the junction, in front
    # of the plate, in any of 16 directions, is seen at every rendering.
    settings = replace(HeadSettings(), render=RenderFidelity(*fidelity))
    with HeadSim("blocks", settings) as sim:
        for name in names.RELATIVE_OBJECTS:  # nothing between the head and the plate
            sim.set_body_pose(name, [0.0, -2.0, 0.0])
        sim.set_body_pose(names.BLOCKS, [0.0, depth_m, 0.21])
        sim.move(eye=0.05)
        cross = sim.position(names.BLOCKS)
        clean = find_cross_point(sim.render(1))
        assert clean.found
        truth = sim.project(cross, 1)[0]
        assert _error_px(clean.uv, truth) < 0.25  # (0, 3): corner floor 0.2 px p95
        marker = names.RELATIVE_OBJECTS[0]
        statuses = []
        for angle in 2 * np.pi * np.arange(16) / 16:
            offset = 0.01 * np.array([np.cos(angle), 0.0, np.sin(angle)])
            sim.set_body_pose(marker, cross + offset + np.array([0.0, -0.007, 0.0]))
            statuses.append(find_cross_point(sim.render(1)).status)
        assert DetectionStatus.FOUND not in statuses, statuses
        sim.set_body_pose(marker, cross + np.array([0.0, -0.007, 0.0]))
        assert find_cross_point(sim.render(1)).status is DetectionStatus.LOST


def test_no_cross_point_in_a_scene_without_one() -> None:
    with HeadSim("default", HeadSettings(cameras=(CameraSettings(noise_std=2.0),) * 2)) as sim:
        detection = find_cross_point(sim.render(1))
    assert detection.status is DetectionStatus.LOST
    assert detection.uv is None
