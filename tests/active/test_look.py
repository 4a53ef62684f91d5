"""One way to look (active/look.py): capabilities by protocol, window sizes exactly,
detections in real windows and previews."""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest

from headsim.active.chessboard import ChessboardCorner
from headsim.active.events import Detected
from headsim.active.look import (
    Anew,
    Around,
    Looker,
    Since,
    Whole,
    band_window,
    expected_window,
    finds_blob,
    pattern_feature,
    pattern_window,
    reporting,
    stands_for_frame,
)
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.gl_window import Window
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import MarkerDetector, find_marker

RED = MarkerDetector("red")
SIZE = (640, 480)


class Collect:
    def __init__(self) -> None:
        self.events: list[object] = []

    def emit(self, event: object) -> None:
        self.events.append(event)


@pytest.fixture(scope="module")
def sim():
    with HeadSim("default") as sim:
        yield sim


def test_only_declared_blob_detectors_look_at_windows_and_patterns_by_their_protocol() -> None:
    assert finds_blob(RED) and finds_blob(MarkerDetector("yellow"))
    # A plain function, a lambda or a partial declares nothing: whole frames.
    assert not finds_blob(find_marker) and not finds_blob(partial(find_marker, colour="red"))
    assert not finds_blob(lambda image: find_marker(image, "red"))
    corner = ChessboardCorner(3, (8, 6), 0.03)
    assert pattern_feature(corner) is corner and not finds_blob(corner)
    assert pattern_feature(RED) is None and pattern_feature(find_marker) is None
    # Every corner of one board shares its windows; detectors compare by identity.
    assert corner.window_key == ChessboardCorner(5, (8, 6), 0.03).window_key
    assert corner.window_key != ChessboardCorner(5, (7, 6), 0.03).window_key
    assert MarkerDetector("red") != RED


def test_a_blobs_window_is_three_radii_the_margin_and_a_quarter_of_the_motion() -> None:
    # Radius 4 px: half-side 12 + 8 + 0.25 * 8 = 22 px, a 45 px square around (320, 240).
    window = expected_window(SIZE, (320.0, 240.0), math.pi * 16, -8.0, 8.0)
    assert window == Window(298, 218, 45, 45)
    # At the image's corner it is moved inside; as large as half the frame it is refused.
    assert expected_window(SIZE, (0.0, 0.0), math.pi * 16, 8.0, 8.0) == Window(0, 0, 45, 45)
    assert expected_window(SIZE, (320.0, 240.0), math.pi * 100**2, 0.0, 8.0) is None


def test_a_blobs_band_is_every_column_of_the_rows_around_its_last_sight() -> None:
    # Radius 4 px: half-height 12 + 8 + 0.05 * 640 = 52 px, 105 rows around row 240.
    assert band_window(SIZE, (320.0, 240.0), math.pi * 16, 8.0) == Window(0, 188, 640, 105)
    # Wherever the blob was along the row, and moved inside the image at its top.
    assert band_window(SIZE, (5.0, 240.0), math.pi * 16, 8.0) == Window(0, 188, 640, 105)
    assert band_window(SIZE, (320.0, 3.0), math.pi * 16, 8.0) == Window(0, 0, 640, 105)
    # A band of half the frame or more is no saving: the full frame.
    assert band_window(SIZE, (320.0, 240.0), math.pi * 80**2, 8.0) is None


def test_after_an_eye_move_of_unknown_gain_a_band_gives_the_full_frames_answer() -> None:
    taken = Collect()
    with HeadSim("default", sink=taken) as sim:
        looker = Looker(sim)
        first = looker.look(1, RED, Since(None))  # no sight yet: a preview, then its window
        sim.command_eye_steps(sim.eye_encoder_steps() + 16)  # the servo's probe
        sim.settle()
        band = looker.look(1, RED, Since(None))
        full = RED(sim.retake(1))
    assert first.found and band.found and full.found and band.uv is not None
    np.testing.assert_allclose(band.uv, full.uv, rtol=0, atol=0.02)
    assert band.uv != first.uv  # the eyes moved the blob
    images = [e for e in taken.events if isinstance(e, ImageTaken)]
    kinds = [e.kind for e in images]
    assert kinds == [ImageKind.PREVIEW, ImageKind.WINDOW, ImageKind.WINDOW, ImageKind.RETAKE]
    window = images[2].window
    assert window is not None and (window.x0, window.width) == (0, SIZE[0])
    assert window.y0 <= first.uv[1] < window.y1 and window.height < SIZE[1] / 2


def test_a_patterns_window_is_its_extent_grown_and_clipped_to_the_image() -> None:
    # Grown by 2 + 0.25 * 8 = 4 px on every side.
    extent = (-10.0, -5.0, 20.0, 15.0)
    assert pattern_window(SIZE, (100.0, 100.0), extent, 8.0, 2.0) == Window(86, 91, 39, 29)
    assert pattern_window(SIZE, (2.0, 3.0), extent, 8.0, 2.0) == Window(0, 0, 27, 23)
    assert pattern_window(SIZE, (320.0, 240.0), (-300, -200, 300, 200), 0.0, 2.0) is None


def test_a_detection_in_a_window_is_the_full_frames_and_is_reported(sim) -> None:
    full = RED(sim.render(1))
    assert full.found and full.uv is not None
    window = Window.around(full.uv, 30, SIZE)
    seen = stands_for_frame(RED(sim.render_window(1, window)), window, SIZE)
    assert seen is not None and seen.found
    np.testing.assert_allclose(seen.uv, full.uv, atol=0.02)
    sink = Collect()
    detected = reporting(RED, sink, 1, window)(sim.render_window(1, window))
    assert detected.found and detected.uv is not None and len(sink.events) == 1
    event = sink.events[0]
    assert isinstance(event, Detected) and event.camera == 1
    assert event.status is DetectionStatus.FOUND
    assert event.uv_px == (detected.uv[0] + window.x0, detected.uv[1] + window.y0)
    # With the blob near the window's edge the window's answer does not count.
    edge = Window(round(full.uv[0]) - 3, round(full.uv[1]) - 20, 40, 40)
    assert stands_for_frame(RED(sim.render_window(1, edge)), edge, SIZE) is None
    # Nor does a blob of another size than the one the window was placed for.
    assert (
        stands_for_frame(RED(sim.render_window(1, window)), window, SIZE, 3 * full.area_px) is None
    )


def test_a_look_renders_what_its_hint_calls_for() -> None:
    taken = Collect()
    with HeadSim("default", sink=taken) as sim:
        full = RED(sim.render(1))
        assert full.found and full.uv is not None
        looker, detected = Looker(sim), Collect()
        looker.sink = detected
        # Where a servo's own prediction puts the blob: one window, the frame's answer.
        seen = looker.look(1, RED, Around(RED, full.uv, full.area_px, 0.0))
        np.testing.assert_allclose(seen.uv, full.uv, atol=0.02)
        # A new target: a binned preview places the window.
        again = looker.look(1, RED, Anew(RED))
        np.testing.assert_allclose(again.uv, full.uv, atol=0.02)
        # A prediction far off misses: a preview places the window of the same instant.
        off = looker.look(1, RED, Around(RED, (40.0, 40.0), full.area_px, 0.0))
        np.testing.assert_allclose(off.uv, full.uv, atol=0.02)
        assert looker.look(1, RED, Whole()).found
        # Yellow is nowhere: the preview shows nothing and the full frame says so.
        assert looker.look(1, MarkerDetector("yellow"), Anew(MarkerDetector("yellow"))).status is (
            DetectionStatus.LOST
        )
    kinds = [e.kind for e in taken.events if isinstance(e, ImageTaken)]
    assert kinds == [
        ImageKind.FULL,
        ImageKind.WINDOW,
        ImageKind.PREVIEW,
        ImageKind.WINDOW,
        ImageKind.WINDOW,
        ImageKind.PREVIEW,
        ImageKind.RETAKE,
        ImageKind.FULL,
        ImageKind.PREVIEW,
        ImageKind.FULL,
    ]
    assert (looker.counts.previews, looker.counts.window_renders) == (3, 4)
    assert looker.counts.window_misses == 1
    # Every detection a look made is reported, the preview's not.
    assert sum(isinstance(e, Detected) for e in detected.events) == 6


def test_a_camera_that_looks_once_sees_what_the_full_frame_shows_in_fewer_pixels() -> None:
    # Calibrated stereo's marker images and the chessboard views of Zhang's calibration:
    # a binned preview places a window; its detection is the full frame's.
    from headsim.active.chessboard import look_for_board
    from headsim.active.look import look_once
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
