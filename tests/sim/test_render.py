"""Rendering against the true camera model: the intrinsics proved by pictures."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.sim.optics import undistort_pixels
from headsim.sim.render import release_renderers
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import find_marker

MARKER = "marker_red"

CAMERA_VARIANTS = {
    "ideal": CameraSettings(),
    "principal_shifted": CameraSettings(cx=289.0, cy=271.5),
    "long_focal": CameraSettings(kx=900.0, ky=900.0),
    "kx_ne_ky_and_shifted": CameraSettings(kx=760.0, ky=690.0, cx=350.25, cy=205.0),
    "small_image": CameraSettings(width=320, height=240, kx=300.0, ky=320.0, cx=150.0, cy=130.0),
}


def _marker_residuals(sim: HeadSim, rng: np.random.Generator, trials: int) -> list[float]:
    residuals = []
    for _ in range(trials):
        target = [rng.uniform(-0.08, 0.08), rng.uniform(0.45, 0.9), 0.21 + rng.uniform(-0.06, 0.06)]
        sim.set_body_pose(MARKER, target)
        sim.move(eye=float(rng.uniform(-0.04, 0.12)), neck_yaw=float(rng.uniform(-0.05, 0.05)))
        for camera in (1, 2):
            detection = find_marker(sim.render(camera), "red")
            truth = sim.project(sim.position(MARKER), camera)[0]
            assert detection.found, f"marker not found at {target}"
            residuals.append(float(np.linalg.norm(np.array(detection.uv) - truth)))
    return residuals


@pytest.mark.parametrize("variant", sorted(CAMERA_VARIANTS))
def test_marker_centroid_lands_on_its_projection_with_the_true_K(variant: str, rng) -> None:
    camera = CAMERA_VARIANTS[variant]
    with HeadSim("default", HeadSettings(cameras=(camera, camera))) as sim:
        residuals = _marker_residuals(sim, rng, trials=4)
    assert max(residuals) < 0.15, f"residuals px: {residuals}"


def test_undistorted_centroid_returns_the_pinhole_projection(rng) -> None:
    settings = paper_head()
    with HeadSim("default", settings) as sim:
        worst = 0.0
        for _ in range(6):
            target = [
                rng.uniform(-0.12, 0.12),
                rng.uniform(0.5, 0.9),
                0.21 + rng.uniform(-0.1, 0.1),
            ]
            sim.set_body_pose(MARKER, target)
            sim.move(eye=float(rng.uniform(0.0, 0.1)))
            for camera in (1, 2):
                cam = sim.camera_settings(camera)
                detection = find_marker(sim.render(camera), "red")
                assert detection.found
                p_cam = sim.position(MARKER, f"cam{camera}")
                pinhole = sim.camera_matrix(camera) @ (p_cam / p_cam[2])
                undistorted = undistort_pixels(np.array(detection.uv), cam)[0]
                worst = max(worst, float(np.linalg.norm(undistorted - pinhole[:2])))
        assert worst < 0.3


def test_distortion_moves_off_centre_points() -> None:
    bent = CameraSettings(k1=-0.35)
    with HeadSim("default", HeadSettings(cameras=(bent, CameraSettings()))) as sim:
        sim.set_body_pose(MARKER, [0.14, 0.55, 0.32])
        sim.move(eye=0.0)
        p_cam = sim.position(MARKER, "cam1")
        pinhole = (sim.camera_matrix(1) @ (p_cam / p_cam[2]))[:2]
        detection = find_marker(sim.render(1), "red")
        shift = np.linalg.norm(np.array(detection.uv) - pinhole)
        assert shift > 5.0  # barrel distortion pulls it towards the centre
        assert (
            np.linalg.norm(np.array(detection.uv) - sim.project(sim.position(MARKER), 1)[0]) < 0.15
        )


def test_images_have_the_configured_size_and_renders_are_counted() -> None:
    small = CameraSettings(width=320, height=240, kx=290.0, ky=290.0)
    with HeadSim("default", HeadSettings(cameras=(small, CameraSettings()))) as sim:
        assert sim.render(1).shape == (240, 320, 3)
        assert sim.render("cam2").shape == (480, 640, 3)
        assert sim.render(1).dtype == np.uint8
        assert sim.render_count == 3


def test_noise_has_the_set_spread_and_follows_the_seed() -> None:
    noisy = CameraSettings(noise_std=4.0)
    images = []
    for seed in (7, 7, 8):
        with HeadSim("default", HeadSettings(cameras=(noisy, noisy), seed=seed)) as sim:
            images.append(sim.render(1).astype(float))
    with HeadSim("default") as sim:
        clean = sim.render(1).astype(float)
    np.testing.assert_array_equal(images[0], images[1])
    assert np.any(images[0] != images[2])
    residual = (images[0] - clean)[(clean > 20) & (clean < 235)]
    assert abs(residual.std() - 4.0) < 0.2
    assert abs(residual.mean()) < 0.1


def test_repeated_renders_are_identical() -> None:
    with HeadSim("default", paper_head()) as sim:
        sim.move(eye=0.05)
        first = sim.render(2)
        np.testing.assert_array_equal(first, sim.render(2))


def test_an_image_does_not_depend_on_what_the_process_drew_before() -> None:
    """A model whose multisampling is set after it is built (as the Gym env's) gets a
    context made with it, not a pooled one another head made with the default."""
    small = HeadSettings(cameras=(CAMERA_VARIANTS["small_image"],) * 2)

    def draw(offsamples: int | None) -> np.ndarray:
        with HeadSim(settings=small) as sim:
            if offsamples is not None:
                sim.model.vis.quality.offsamples = offsamples
            sim.set_body_pose(MARKER, [0.02, 0.6, 0.23])
            sim.move(eye=0.05)
            return sim.render(1)

    release_renderers()
    fresh = draw(0)
    release_renderers()
    default = draw(None)  # a context with the default multisampling, pooled
    assert default.tobytes() != fresh.tobytes()
    assert draw(0).tobytes() == fresh.tobytes()


def test_heads_whose_canvases_differ_share_one_context_grown_once_and_render_alike() -> None:
    """A lens that needs a larger pinhole canvas grows the pooled context's buffer once;
    a smaller head drawn after it, in the corner of that buffer, gets the pixels of a
    context of its own size."""
    from headsim.sim import render

    plain = HeadSettings(seed=5, cameras=(CameraSettings(noise_std=2.0),) * 2)
    barrel = HeadSettings(seed=5, cameras=(CameraSettings(k1=-0.4, noise_std=2.0),) * 2)

    def draw(settings: HeadSettings) -> tuple[np.ndarray, tuple[int, int]]:
        with HeadSim(settings=settings) as sim:
            sim.set_body_pose(MARKER, [0.02, 0.6, 0.23])
            sim.move(eye=0.05)
            size = (int(sim.model.vis.global_.offwidth), int(sim.model.vis.global_.offheight))
            return sim.render(1), size

    release_renderers()
    alone, plain_size = draw(plain)
    before = render.created
    bent, barrel_size = draw(barrel)
    assert barrel_size[0] > plain_size[0] and barrel_size[1] > plain_size[1]
    assert render.created == before + 1  # grown to the barrel lens's canvas
    again, _ = draw(plain)
    assert render.created == before + 1  # drawn in the grown buffer's corner
    assert len(render._POOL) == 1  # one context serves both heads
    np.testing.assert_array_equal(again, alone)
    release_renderers()
    assert np.array_equal(draw(barrel)[0], bent)


def test_a_marker_out_of_view_is_reported_lost_and_one_on_the_border_cut() -> None:
    with HeadSim("default") as sim:
        sim.set_body_pose(MARKER, [0.0, -1.0, 0.21])  # behind the head
        assert find_marker(sim.render(1), "red").status is DetectionStatus.LOST
        # Put the marker on Ca1's left image border (u = 0) at 0.6 m.
        p_cam = np.array([-319.5 / sim.camera_matrix(1)[0, 0] * 0.6, 0.0, 0.6])
        sim.set_body_pose(MARKER, sim.transform_points(p_cam, "cam1", "world")[0])
        assert find_marker(sim.render(1), "red").status is DetectionStatus.CUT
