"""Windowed rendering and renderer reuse, with real MuJoCo renders."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active import look
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge
from headsim.active.model1 import measure_model1
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.active.servo_types import ServoConfig
from headsim.head.sim_head import SimHead
from headsim.sim import gl_window, render
from headsim.sim.render import Window
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim
from headsim.studies import experiments
from headsim.studies.targets import random_targets_head

HEADS = {
    "ideal": HeadSettings(cameras=(CameraSettings(noise_std=2.0),) * 2, seed=3),
    "distorted": paper_head(),
}
WINDOWS = [
    Window(0, 0, 640, 480),
    Window(100, 50, 160, 120),
    Window(300, 200, 77, 61),
    Window(0, 0, 50, 40),
    Window(590, 430, 50, 50),
    Window(250, 180, 140, 100),
]


def _pose(sim: HeadSim) -> None:
    sim.set_body_pose("marker_red", [0.02, 0.6, 0.2])
    sim.move(eye=0.05, neck_yaw=0.03)


@pytest.mark.parametrize("head", sorted(HEADS))
def test_a_window_is_the_full_frames_crop_noise_included(head: str) -> None:
    settings = HEADS[head]
    with HeadSim("default", settings) as full_sim, HeadSim("default", settings) as window_sim:
        for sim in (full_sim, window_sim):
            _pose(sim)
        for window in WINDOWS:
            for camera in (1, 2):
                full = full_sim.render(camera)  # image k of this camera in both sims
                part = window_sim.render_window(camera, window)
                assert part.shape == (window.height, window.width, 3)
                crop = full[window.y0 : window.y1, window.x0 : window.x1]
                diff = np.abs(part.astype(int) - crop.astype(int))
                assert np.mean(diff <= 1) >= 0.999, (window, camera)
                assert diff.max() <= 8, (window, camera)
        # Pixels are counted in full frames: windows cost their share.
        expected = sum(w.width * w.height for w in WINDOWS) * 2 / (640 * 480)
        if head == "ideal":
            assert window_sim.rendered_frames == pytest.approx(expected)
        assert window_sim.render_count == full_sim.render_count == 2 * len(WINDOWS)


def test_a_retaken_window_is_of_the_instant_just_taken() -> None:
    """A window retaken (after a miss, where a preview places it) has the noise of the
    image just taken, not the next one's; it is a render, counted as a retake."""
    settings = HeadSettings(cameras=(CameraSettings(noise_std=3.0),) * 2, seed=4)
    taken: list[object] = []
    with HeadSim("default", settings) as sim, HeadSim("default", settings) as plain:
        sim.sink = type("Sink", (), {"emit": lambda self, e: taken.append(e)})()
        for s in (sim, plain):
            _pose(s)
        first, second = Window(300, 200, 77, 61), Window(250, 180, 140, 100)
        sim.render_window(1, first)
        again = sim.render_window(1, second, retake=True)
        nxt = sim.render_window(1, second)
        for full, part in ((plain.render(1), again), (plain.render(1), nxt)):
            crop = full[second.y0 : second.y1, second.x0 : second.x1].astype(int)
            assert np.mean(np.abs(part.astype(int) - crop) <= 1) >= 0.999
        assert not np.array_equal(again, nxt)  # the next image has noise of its own
        assert sim.render_count == 3
        kinds = [e.kind.value for e in taken]  # type: ignore[attr-defined]
        assert kinds == ["window", "retake", "window"]
        assert taken[1].window == second  # type: ignore[attr-defined]


def test_a_window_outside_the_image_is_refused() -> None:
    with HeadSim("default") as sim, pytest.raises(ValueError, match="not inside"):
        sim.render_window(1, Window(600, 0, 64, 48))


def test_window_around_stays_inside_the_image() -> None:
    assert Window.around((5.0, 470.0), 30, (640, 480)) == Window(0, 419, 61, 61)
    assert Window.around((320.0, 240.0), 1000, (640, 480)) == Window(0, 0, 640, 480)


def test_simulators_of_one_head_share_one_renderer_and_render_alike() -> None:
    settings = HeadSettings(seed=11)
    with HeadSim("default", settings) as sim:
        _pose(sim)
        first = sim.render(1)
    before = render.created
    with HeadSim("default", settings) as sim:
        _pose(sim)
        np.testing.assert_array_equal(sim.render(1), first)
    assert render.created == before
    # Another head of the same scene shares it too, and renders as with a context of its own.
    other = HeadSettings(
        seed=11, baseline_m=0.12, cameras=(CameraSettings(kx=700.0, ky=690.0, cx=330.0),) * 2
    )
    with HeadSim("default", other) as sim:
        _pose(sim)
        shared = sim.render(1)
        own = render.EyeRenderer(
            sim.model,
            other.cameras,
            sim.built.canvases,
            seed=11,
            supersample=other.render.supersample,
        )
        try:
            np.testing.assert_array_equal(own.render(sim.data, 0), shared)
        finally:
            own.close()
    assert render.created == before + 1  # the one of its own only


def _windows_drawn(settings: HeadSettings) -> list[np.ndarray]:
    """Windows inside one another, the largest first, in both cameras."""
    render.release_renderers()  # a fresh context: no window buffer kept
    with HeadSim("default", settings) as sim:
        _pose(sim)
        return [
            sim.render_window(camera, window)
            for window in (
                Window(100, 50, 400, 300),
                Window(110, 60, 380, 280),
                Window(130, 80, 330, 240),
            )
            for camera in (1, 2)
        ]


def test_a_window_buffer_without_stencil_changes_no_pixel(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    # Depth without stencil (the default for a scene without reflections), against the
    # context's depth and stencil (none of these scenes uses it): the same pixels, bit for bit.
    settings = paper_head()
    plain = _windows_drawn(settings)
    monkeypatch.setattr(gl_window, "_WITHOUT_STENCIL", {})
    with_stencil = _windows_drawn(settings)
    render.release_renderers()
    assert len(plain) == len(with_stencil) == 6
    for a, b in zip(plain, with_stencil, strict=True):
        np.testing.assert_array_equal(a, b)


class LoggingServo(EyeServo):
    """An eye servo that keeps every detection it made (full-frame pixels)."""

    seen: list[tuple[float, float] | None]
    steps: list[int]

    def observe(self, camera: int, detector, key: object = None, preview: bool = True):  # type: ignore[no-untyped-def]
        detection = super().observe(camera, detector, key, preview)
        self.seen = [*getattr(self, "seen", []), detection.uv]
        self.steps = [*getattr(self, "steps", []), self.sim.eye_encoder_steps()]
        return detection


@pytest.mark.parametrize("head", ["ideal", "distorted"])
def test_windows_change_no_measurement(head: str) -> None:
    settings = HeadSettings() if head == "ideal" else paper_head()
    rng = np.random.default_rng(5)
    points = np.concatenate(
        [
            random_targets_head(rng, 2, band, vertical=(-0.1, 0.1))
            for band in experiments.DEPTH_BANDS_M
        ]
    )
    runs = {}
    for windows in (False, True):
        with HeadSim("default", settings) as sim:
            servo = LoggingServo(sim, ServoConfig(windows=windows))
            measured = []
            for p in points:
                sim.set_body_pose("marker_red", sim.transform_points(p, "head", "world")[0])
                measured.append(measure_model2(sim, servo, experiments.RED, HeadKnowledge()))
            runs[windows] = (measured, sim.rendered_frames, sim.render_count, servo)
    (plain, plain_frames, plain_renders, plain_servo), (windowed, frames, renders, servo) = (
        runs[False],
        runs[True],
    )
    assert all(m.ok for m in plain) and all(m.ok for m in windowed)
    for a, b in zip(plain, windowed, strict=True):
        np.testing.assert_allclose(b.estimate_head_m, a.estimate_head_m, rtol=0, atol=1e-6)
    # Every detection the servo made, in order: the same place to 0.01 px, on the
    # distorted head too (windows are drawn with the frame's own projection).
    assert len(servo.seen) == len(plain_servo.seen)
    # (Compared at the same eye pose, as a change may turn the next move by a step.)
    changes = []
    for a_uv, b_uv, a_steps, b_steps in zip(
        plain_servo.seen, servo.seen, plain_servo.steps, servo.steps, strict=True
    ):
        assert (a_uv is None) == (b_uv is None)
        if a_uv is not None and b_uv is not None and a_steps == b_steps:
            changes.append(float(np.max(np.abs(np.subtract(a_uv, b_uv)))))
    assert len(changes) >= 0.9 * len(servo.seen)
    assert max(changes) <= 0.01
    # Same images taken, plus a binned preview where no detection placed the window
    # (a new target), and where the last sight's window missed (the target was moved:
    # at most once per point and camera) a preview and the image it places, of the same
    # instant; far fewer pixels rendered.
    counts = servo.looker.counts
    assert renders == plain_renders + counts.previews + counts.window_misses
    assert 0 < counts.window_misses <= 2 * len(points)
    assert 0 < counts.previews <= counts.window_renders
    assert counts.window_renders > renders / 2
    assert frames < 0.5 * plain_frames


class LoggingNeckServo(NeckServo):
    """A neck servo that keeps every detection it made (full-frame pixels)."""

    seen: list[tuple[float, float] | None]

    def _look(self, camera: int, detector):  # type: ignore[no-untyped-def]
        detection = super()._look(camera, detector)
        self.seen = [*getattr(self, "seen", []), detection.uv]
        return detection


def test_windows_change_no_fixation_with_the_neck() -> None:
    settings = paper_head()
    rng = np.random.default_rng(8)
    points = random_targets_head(rng, 4, (0.5, 1.2), vertical=(-0.1, 0.1))
    runs = {}
    for windows in (False, True):
        with HeadSim("default", settings) as sim:
            servo = LoggingNeckServo(sim, ServoConfig(windows=windows))
            measured = []
            for p in points:
                sim.set_body_pose("marker_red", sim.transform_points(p, "head", "world")[0])
                measured.append(measure_model1(sim, servo, experiments.RED, HeadKnowledge()))
            runs[windows] = (measured, sim.rendered_frames, sim.render_count, servo)
    plain, plain_frames, plain_renders, plain_servo = runs[False]
    windowed, frames, renders, servo = runs[True]
    assert all(m.ok for m in plain) and all(m.ok for m in windowed)
    for a, b in zip(plain, windowed, strict=True):
        np.testing.assert_allclose(b.estimate_head_m, a.estimate_head_m, rtol=0, atol=1e-6)
    assert len(servo.seen) == len(plain_servo.seen)
    for a_uv, b_uv in zip(plain_servo.seen, servo.seen, strict=True):
        assert (a_uv is None) == (b_uv is None)
        if a_uv is not None and b_uv is not None:
            assert np.max(np.abs(np.subtract(a_uv, b_uv))) <= 0.01
    counts = servo.looker.counts
    assert renders == plain_renders + counts.previews + counts.window_misses
    # A miss where the last fixation's window no longer holds the moved target: at
    # most once per point and camera.
    assert counts.window_renders > 0 and counts.window_misses <= 2 * len(points)
    assert frames < 0.7 * plain_frames


def test_a_missed_window_costs_a_frame_of_the_same_instant(monkeypatch) -> None:
    """Every window misses (it is put where the target is not): the full frames that
    follow are the same images, noise included, so nothing changes but the cost."""
    settings = HeadSettings(cameras=(CameraSettings(noise_std=3.0),) * 2, seed=4)
    rng = np.random.default_rng(9)
    points = random_targets_head(rng, 3, (0.5, 1.0), vertical=(-0.1, 0.1))

    def far_away(image_size_px, expected_uv_px, area_px, motion_px, margin_px):  # type: ignore[no-untyped-def]
        return Window(0, 0, 24, 24) if expected_uv_px[0] > 100 else Window(600, 440, 24, 24)

    def band_far_away(image_size_px, seen_uv_px, area_px, margin_px):  # type: ignore[no-untyped-def]
        return far_away(image_size_px, seen_uv_px, area_px, 0.0, margin_px)

    runs = {}
    for windows in (False, True):
        if windows:
            monkeypatch.setattr(look, "expected_window", far_away)
            monkeypatch.setattr(look, "band_window", band_far_away)
        with HeadSim("default", settings) as sim:
            servo = LoggingServo(sim, ServoConfig(windows=windows))
            measured = []
            for p in points:
                sim.set_body_pose("marker_red", sim.transform_points(p, "head", "world")[0])
                measured.append(measure_model2(sim, servo, experiments.RED, HeadKnowledge()))
            runs[windows] = (measured, sim.render_count, servo)
    (plain, plain_renders, plain_servo), (missed, renders, servo) = runs[False], runs[True]
    counts = servo.looker.counts
    assert counts.window_misses == counts.window_renders > 0
    assert renders == plain_renders + counts.window_misses + counts.previews
    assert servo.seen == plain_servo.seen
    for a, b in zip(plain, missed, strict=True):
        np.testing.assert_array_equal(a.estimate_head_m, b.estimate_head_m)


def test_windows_change_no_chessboard_corner() -> None:
    # The corners of one board share windows that hold the whole board (its extent):
    # every detection and estimate as with full frames, on the distorted paper head.
    from headsim.procedures.chessboard import measure_chessboard
    from headsim.sim import names

    corners = [0, 1, 8, 27, 46, 47]
    runs = {}
    for windows in (False, True):
        with HeadSim("chessboard", paper_head()) as sim:
            sim.set_body_pose(
                names.CHESSBOARD, sim.transform_points([-0.105, -0.075, 0.85], "head", "world")[0]
            )
            servo = LoggingServo(sim, ServoConfig(windows=windows))
            run = measure_chessboard(SimHead(sim), servo, HeadKnowledge(), corners=corners)
            runs[windows] = (run, sim.rendered_frames, sim.render_count, servo)
    (plain, plain_frames, plain_renders, plain_servo) = runs[False]
    (windowed, frames, renders, servo) = runs[True]
    assert all(m.ok for m in plain.measurements) and all(m.ok for m in windowed.measurements)
    for a, b in zip(plain.measurements, windowed.measurements, strict=True):
        np.testing.assert_allclose(b.estimate_head_m, a.estimate_head_m, rtol=0, atol=1e-6)
    assert len(servo.seen) == len(plain_servo.seen)
    for a_uv, b_uv in zip(plain_servo.seen, servo.seen, strict=True):
        assert (a_uv is None) == (b_uv is None)
        if a_uv is not None and b_uv is not None:
            assert np.max(np.abs(np.subtract(a_uv, b_uv))) <= 0.01
    # Each corner is looked for in the board's window: no preview, no miss, no extra render.
    counts = servo.looker.counts
    assert counts.previews == 0 and renders == plain_renders
    assert counts.window_misses == 0
    assert counts.window_renders > plain_renders / 2
    assert frames < 0.7 * plain_frames


@pytest.mark.parametrize("head", sorted(HEADS))
def test_a_preview_is_the_binned_view_and_leaves_the_cameras_noise_alone(head: str) -> None:
    import cv2

    from headsim.vision.markers import find_marker

    settings = HEADS[head]
    with HeadSim("default", settings) as sim, HeadSim("default", settings) as plain:
        for s in (sim, plain):
            _pose(s)
        preview = sim.render_preview(1, 4)
        assert preview.shape == (120, 160, 3)
        assert sim.render_count == 1 and sim.rendered_frames == pytest.approx(1 / 16, rel=0.02)
        full = sim.render(1)
        # The camera's images get the same noise as without the preview.
        np.testing.assert_array_equal(full, plain.render(1))
        binned = cv2.resize(full, (160, 120), interpolation=cv2.INTER_AREA)
        diff = np.abs(preview.astype(int) - binned.astype(int))
        assert np.mean(diff) < 2.0
        # It finds the marker within a binned pixel of where the full frame does.
        small, whole = find_marker(preview, "red"), find_marker(full, "red")
        assert small.found and whole.found
        assert np.max(np.abs(4 * np.array(small.uv) + 1.5 - np.array(whole.uv))) < 2.0
