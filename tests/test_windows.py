"""Windowed rendering and renderer reuse, with real MuJoCo renders."""

from __future__ import annotations

import numpy as np
import pytest

from headsim import render
from headsim.render import Window
from headsim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim import HeadSim

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
    # Another head gets a context of its own.
    with HeadSim("default", HeadSettings(seed=11, baseline_m=0.12)) as sim:
        sim.render(1)
    assert render.created == before + 1
