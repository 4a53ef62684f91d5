"""Where a servo looks (active/windows.py): window sizes exactly, detections in real windows."""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest

from headsim.active.events import Detected
from headsim.active.servo_types import ServoConfig
from headsim.active.windows import (
    expected_window,
    look_in_window,
    pattern_window,
    pattern_windowed,
    preview_window,
    reporting,
    windowed,
)
from headsim.sim.gl_window import Window
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import find_marker

RED = partial(find_marker, colour="red")


@pytest.fixture(scope="module")
def sim():
    with HeadSim("default") as sim:
        yield sim


def test_only_blob_detectors_look_at_windows_and_patterns_by_their_key() -> None:
    assert windowed(find_marker) and windowed(RED) and windowed(partial(RED, threshold=0.3))
    assert not windowed(lambda image: find_marker(image, "red"))

    def board(image):
        return find_marker(image, "red")

    assert not pattern_windowed(board) and not pattern_windowed(RED)
    board.window_key = ("chessboard", (8, 6), 0.03)  # type: ignore[attr-defined]
    assert pattern_windowed(board) and pattern_windowed(partial(board))


def test_a_blobs_window_is_three_radii_the_margin_and_a_quarter_of_the_motion(sim) -> None:
    # Radius 4 px: half-side 12 + 8 + 0.25 * 8 = 22 px, a 45 px square around (320, 240).
    window = expected_window(sim, 1, (320.0, 240.0), math.pi * 16, -8.0, 8.0)
    assert window == Window(298, 218, 45, 45)
    # At the image's corner it is moved inside; as large as half the frame it is refused.
    assert expected_window(sim, 1, (0.0, 0.0), math.pi * 16, 8.0, 8.0) == Window(0, 0, 45, 45)
    assert expected_window(sim, 1, (320.0, 240.0), math.pi * 100**2, 0.0, 8.0) is None


def test_a_patterns_window_is_its_extent_grown_and_clipped_to_the_image(sim) -> None:
    # Grown by 2 + 0.25 * 8 = 4 px on every side.
    extent = (-10.0, -5.0, 20.0, 15.0)
    assert pattern_window(sim, 2, (100.0, 100.0), extent, 8.0, 2.0) == Window(86, 91, 39, 29)
    assert pattern_window(sim, 2, (2.0, 3.0), extent, 8.0, 2.0) == Window(0, 0, 27, 23)
    assert pattern_window(sim, 2, (320.0, 240.0), (-300, -200, 300, 200), 0.0, 2.0) is None


def test_a_detection_in_a_window_is_the_full_frames_and_is_reported(sim) -> None:
    full = RED(sim.render(1))
    assert full.found
    window = Window.around(full.uv, 30, (640, 480))
    seen = look_in_window(sim, 1, RED, window)
    assert seen is not None and seen.found
    np.testing.assert_allclose(seen.uv, full.uv, atol=0.02)
    events: list[object] = []

    class Sink:
        def emit(self, event: object) -> None:
            events.append(event)

    detected = reporting(RED, Sink(), 1, window)(sim.render_window(1, window))
    assert detected.found and len(events) == 1
    event = events[0]
    assert isinstance(event, Detected) and event.camera == 1
    assert event.status is DetectionStatus.FOUND
    assert event.uv_px == (detected.uv[0] + window.x0, detected.uv[1] + window.y0)
    # With the blob near the window's edge the window's answer does not count.
    edge = Window(round(full.uv[0]) - 3, round(full.uv[1]) - 20, 40, 40)
    assert look_in_window(sim, 1, RED, edge) is None


def test_a_binned_preview_places_a_window_around_the_blob(sim) -> None:
    full = RED(sim.render(1))
    window = preview_window(sim, 1, RED, ServoConfig(preview_binning=4))
    assert window is not None
    assert window.x0 < full.uv[0] < window.x1 - 1 and window.y0 < full.uv[1] < window.y1 - 1
    assert window.width * window.height < 0.1 * 640 * 480
    assert preview_window(sim, 1, partial(find_marker, colour="yellow"), ServoConfig()) is None


def test_a_camera_that_looks_once_sees_what_the_full_frame_shows_in_fewer_pixels() -> None:
    # Calibrated stereo's marker images and the chessboard views of Zhang's calibration:
    # a binned preview places a window; its detection is the full frame's.
    from headsim.active.chessboard import look_for_board
    from headsim.active.windows import look_once
    from headsim.sim.settings import paper_head
    from headsim.stereo.views import full_frame_board, place_chessboard, sample_board_pose
    from headsim.studies.targets import place_in_head

    rng = np.random.default_rng(2)
    with HeadSim("chessboard", paper_head()) as full, HeadSim("chessboard", paper_head()) as seen:
        for sim in (full, seen):
            sim.move(eye=0.0, neck_yaw=0.0, neck_pitch=0.0)
        for _ in range(3):
            pose = sample_board_pose(full, rng, (0.4, 1.0), 0.6)  # tilted up to 0.6 rad
            for sim in (full, seen):
                place_chessboard(sim, pose)
            for camera in (1, 2):
                corners, looked = full_frame_board(full, camera), look_for_board(seen, camera)
                assert corners is not None and looked is not None
                # 48 such views: within 0.0103 px (a window is the frame's crop to 1 grey
                # level on all but about 3e-5 of its pixel values).
                np.testing.assert_allclose(looked, corners, rtol=0, atol=0.02)
        assert seen.rendered_frames < 0.75 * full.rendered_frames
    with HeadSim("default", paper_head()) as full, HeadSim("default", paper_head()) as seen:
        for p_head in ([0.05, -0.02, 0.6], [-0.15, 0.04, 1.1]):
            for sim in (full, seen):
                place_in_head(sim, "marker_red", np.array(p_head))
            for camera in (1, 2):
                a = RED(full.render(camera))
                b = look_once(seen, camera, RED)
                assert a.found and b.found and a.uv is not None and b.uv is not None
                assert np.max(np.abs(np.subtract(a.uv, b.uv))) < 1e-9
        # A 4x4 preview and a window each, against full frames.
        assert seen.render_count == 2 * full.render_count
        assert seen.rendered_frames < 0.2 * full.rendered_frames
