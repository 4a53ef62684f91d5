"""Markerless detectors on real renders: camera 1's fovea tracked through the eye
servo's looks (foveal windows only), and camera 2's point of the same 3-D point found
by correlation in the believed epipolar band, against exact projection."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import cv2
import mujoco
import numpy as np
import pytest

from headsim.active.eye_servo import EyeServo
from headsim.active.look import foveal_detector
from headsim.active.markerless import CorrespondenceFinder, MarkerlessPair, TemplateTracker
from headsim.active.measurement import Target, body_target
from headsim.active.model1 import measure_model1
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.sim.events import ImageKind, ImageTaken
from headsim.sim.simulator import HeadSim
from headsim.vision.correspondence import MatchConfig, epipolar_band, row_band
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import MarkerDetector

SOURCE = Path(__file__).resolve().parents[2] / "headsim"
WIDTH, HEIGHT, FOVY_DEG = 320, 240, 45.0

SCENE = """
<mujoco model="textured_plane">
  <visual><quality offsamples="4"/><headlight ambient="0.6 0.6 0.6" diffuse="0.3 0.3 0.3"
    specular="0 0 0"/></visual>
  <asset>
    <texture name="pink" type="2d" file="pink.png"/>
    <material name="pink" texture="pink" specular="0" shininess="0" reflectance="0"/>
  </asset>
  <worldbody>
    <geom name="wall" type="plane" size="0.4 0.3 0.01" material="pink"/>
    <camera name="cam1" pos="-0.03 0 0.5" fovy="45"/>
    <camera name="cam2" pos="0.03 0.01 0.5" euler="0.03 -0.07 0.02" fovy="45"/>
  </worldbody>
</mujoco>
"""


def _pink_png(path: Path, size: int = 256, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    f = np.fft.fftfreq(size)
    radius = np.hypot(*np.meshgrid(f, f))
    radius[0, 0] = 1.0
    spectrum = (rng.normal(size=(size, size)) + 1j * rng.normal(size=(size, size))) / radius
    spectrum[0, 0] = 0.0
    texture = np.real(np.fft.ifft2(spectrum))
    grey = np.clip(128 + 45 * (texture - texture.mean()) / texture.std(), 0, 255).astype(np.uint8)
    cv2.imwrite(str(path), cv2.merge([grey, grey, grey]))


class Pinhole:
    """A MuJoCo camera's pinhole (OpenCV pixels: pixel centres at whole numbers), from
    the compiled model: the optical axis meets the image at ((W - 1) / 2, (H - 1) / 2)."""

    def __init__(self, data: mujoco.MjData, camera: int) -> None:
        self.position_world = data.cam_xpos[camera].copy()
        self.world_from_cam = data.cam_xmat[camera].reshape(3, 3).copy()
        self.focal_px = 0.5 * HEIGHT / math.tan(math.radians(FOVY_DEG) / 2)
        self.centre = ((WIDTH - 1) / 2.0, (HEIGHT - 1) / 2.0)

    def ray_world(self, uv: tuple[float, float]) -> np.ndarray:
        d_cam = np.array([(uv[0] - self.centre[0]) / self.focal_px,
                          -(uv[1] - self.centre[1]) / self.focal_px, -1.0])  # fmt: skip
        return self.world_from_cam @ d_cam

    def project(self, points_world: np.ndarray) -> np.ndarray:
        cam = (np.atleast_2d(points_world) - self.position_world) @ self.world_from_cam
        depth = -cam[:, 2]
        return np.stack([self.centre[0] + self.focal_px * cam[:, 0] / depth,
                         self.centre[1] - self.focal_px * cam[:, 1] / depth], axis=1)  # fmt: skip


def _grating_png(path: Path, size: int = 256) -> None:
    """Stripes of 8 texels across u on weaker rows of 11 (a 2-D repetitive texture)."""
    v, u = np.mgrid[0:size, 0:size].astype(np.float64)
    grey = 128 + 70 * np.sin(2 * np.pi * u / 8) + 30 * np.sin(2 * np.pi * v / 11)
    grey = np.clip(grey, 0, 255).astype(np.uint8)
    cv2.imwrite(str(path), cv2.merge([grey, grey, grey]))


def _render(folder: Path, texture) -> tuple[list[np.ndarray], Pinhole, Pinhole]:
    texture(folder / "pink.png")
    (folder / "scene.xml").write_text(SCENE)
    model = mujoco.MjModel.from_xml_path(str(folder / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    with mujoco.Renderer(model, HEIGHT, WIDTH) as renderer:
        images = []
        for camera in (0, 1):
            renderer.update_scene(data, camera=camera)
            images.append(renderer.render().copy())
    return images, Pinhole(data, 0), Pinhole(data, 1)


@pytest.fixture(scope="module")
def views(tmp_path_factory: pytest.TempPathFactory):
    return _render(tmp_path_factory.mktemp("textured_plane"), _pink_png)


def _belief_band(cam1: Pinhole, cam2: Pinhole, uv1: tuple[float, float]):
    """The believed geometry (here exact): camera 1's ray, 0.2 to 3 m, into camera 2."""
    ray_cam1 = cam1.world_from_cam.T @ cam1.ray_world(uv1)

    def project(points_cam1: np.ndarray) -> np.ndarray:
        return cam2.project(cam1.position_world + points_cam1 @ cam1.world_from_cam.T)

    return lambda: epipolar_band(project, ray_cam1, np.geomspace(0.2, 3.0, 8), 2.0)


def test_correspondence_finds_the_same_3d_point_in_camera_2_within_03_px(views) -> None:
    (image1, image2), cam1, cam2 = views
    assert image1.std() > 20  # the texture is there
    errors = []
    for uv1 in [(160.0, 120.0), (110.3, 90.6), (205.7, 150.2), (140.5, 170.4), (190.2, 80.9)]:
        ray = cam1.ray_world(uv1)
        point = cam1.position_world + ray * (-cam1.position_world[2] / ray[2])  # on z = 0
        truth_uv2 = cam2.project(point)[0]

        band = _belief_band(cam1, cam2, uv1)
        finder = CorrespondenceFinder.from_view(image1, uv1, band)
        detection = finder(image2)
        assert detection.status is DetectionStatus.FOUND, finder.matches[-1]
        assert detection.uv is not None and detection.score is not None
        assert detection.score > 0.9
        errors.append(math.dist(detection.uv, truth_uv2))
    assert np.median(errors) < 0.1
    assert max(errors) < 0.3, errors


def test_a_rendered_grating_is_ambiguous_along_the_band(tmp_path: Path) -> None:
    # The other eye's classic trap: along the epipolar band every stripe matches.
    (image1, image2), cam1, cam2 = _render(tmp_path, _grating_png)
    finder = CorrespondenceFinder.from_view(
        image1, (160.0, 120.0), _belief_band(cam1, cam2, (160.0, 120.0))
    )
    detection = finder(image2)
    assert detection.status is DetectionStatus.AMBIGUOUS
    assert detection.uv is None and detection.score is not None and detection.score > 0.9
    assert detection.ambiguity is not None and detection.ambiguity > 0.9
    assert finder.matches[-1].uv is not None  # where it would have gone: kept


def test_the_tracker_follows_a_rendered_view_it_was_not_cut_from(views) -> None:
    # Camera 2's view of camera 1's point, tracked from a click in camera 1: a
    # template, not a blob; the window searched is the fovea, not the frame.
    (image1, image2), cam1, cam2 = views
    uv1 = (160.0, 120.0)
    ray = cam1.ray_world(uv1)
    point = cam1.position_world + ray * (-cam1.position_world[2] / ray[2])
    truth_uv2 = cam2.project(point)[0]
    tracker = TemplateTracker(image1, uv1, reacquire_radius_px=40.0)
    window = tracker.search_window(1, (WIDTH, HEIGHT), None)
    assert window.width * window.height < 0.25 * WIDTH * HEIGHT
    detection = tracker(image2)
    assert detection.found and detection.uv is not None
    assert math.dist(detection.uv, truth_uv2) < 0.3


def test_the_eye_servo_fixates_a_clicked_point_through_foveal_windows() -> None:
    # The default scene's red marker, clicked in camera 1's first image (the marker
    # detector stands for the user), then tracked by its template only.
    with HeadSim("default") as sim:
        first = sim.render(1)
        click = MarkerDetector("red")(first).uv
        assert click is not None
        tracker = TemplateTracker(first, click, MatchConfig(half_px=15))
        assert foveal_detector(tracker) is tracker
        assert foveal_detector(MarkerDetector("red")) is None  # blobs keep their looks
        kinds: list[ImageKind] = []

        class Kinds:
            def emit(self, event: object) -> None:
                if isinstance(event, ImageTaken):
                    kinds.append(event.kind)

        sim.sink = Kinds()
        servo = EyeServo(sim)
        result = servo.run(1, tracker)
        assert result.converged, result
        marker = MarkerDetector("red")(sim.render(1)).uv
        assert marker is not None and result.uv is not None
        # The template's point is the marker's centroid where the click was: still so.
        assert abs(result.uv[0] - marker[0]) < 0.15 and abs(result.uv[1] - marker[1]) < 0.15
        assert abs(marker[0] - (sim.settings.cameras[0].width - 1) / 2) < 1.0
        assert len(kinds) > 3 and set(kinds[:-1]) == {ImageKind.WINDOW}  # no frame in the loop
        assert servo.looker.counts.window_renders == len(kinds) - 1
        assert all(m.score > 0.9 for m in tracker.matches)


FORBIDDEN_IMPORTS = {"mujoco", "headsim.sim.simulator", "headsim.scenario"}
FORBIDDEN_NAMES = {"position", "placements", "truth_world", "mocap_pos", "xpos", "sim"}


def _reads_truth(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] == "mujoco"]
        elif isinstance(node, ast.ImportFrom) and node.module:
            if any(node.module.startswith(f) for f in FORBIDDEN_IMPORTS):
                found.append(node.module)
        elif isinstance(node, ast.Attribute) and node.attr in FORBIDDEN_NAMES:
            found.append(node.attr)
        elif isinstance(node, ast.Name) and node.id in FORBIDDEN_NAMES:
            found.append(node.id)
    return found


def test_the_markerless_detectors_see_only_images_and_belief() -> None:
    for path in (SOURCE / "active" / "markerless.py", SOURCE / "vision" / "correspondence.py"):
        assert _reads_truth(path) == [], path
    assert _reads_truth(SOURCE / "active" / "look.py")  # the check can see a read (sim)


def test_model2_measures_a_clicked_point_without_its_marker() -> None:
    # The red marker clicked in camera 1's first image, then fixated by its template
    # alone: camera 2 finds it along its row (a head that knows no focal length), each
    # step's other camera by the same correspondence.  Same estimate as the marker's.
    with HeadSim("default") as sim:
        truth = sim.position("marker_red")
        first = sim.render(1)
        click = MarkerDetector("red")(first).uv
        assert click is not None
        width = sim.settings.cameras[1].width
        v_shift = sim.settings.cameras[1].image_centre[1] - sim.settings.cameras[0].image_centre[1]

        def band_for(uv1: tuple[float, float]):
            return lambda: row_band(uv1[1] + v_shift, width, 6.0)

        pair = MarkerlessPair(first, click, band_for, MatchConfig(half_px=15))
        markerless = measure_model2(sim, EyeServo(sim), Target("clicked", pair, lambda s: truth))
    with HeadSim("default") as sim:
        marker = measure_model2(
            sim, EyeServo(sim), body_target("marker_red", MarkerDetector("red"))
        )
    assert markerless.ok and marker.ok, markerless.detail
    np.testing.assert_allclose(markerless.estimate_head_m, marker.estimate_head_m, atol=1e-4)
    assert all(m.score > 0.9 for m in pair.finder.matches + pair.tracker.matches)
    assert pair.finder.matches and pair.tracker.matches


def test_model1_fixates_a_clicked_point_with_neck_and_eyes_without_its_marker() -> None:
    # The neck servo's looks (its own predictions) through the same pair.
    with HeadSim("default") as sim:
        truth = sim.position("marker_red")
        first = sim.render(1)
        click = MarkerDetector("red")(first).uv
        assert click is not None
        width = sim.settings.cameras[1].width
        pair = MarkerlessPair(
            first, click, lambda uv1: lambda: row_band(uv1[1], width, 6.0), MatchConfig(half_px=15)
        )
        markerless = measure_model1(sim, NeckServo(sim), Target("clicked", pair, lambda s: truth))
    with HeadSim("default") as sim:
        marker = measure_model1(
            sim, NeckServo(sim), body_target("marker_red", MarkerDetector("red"))
        )
    assert markerless.ok and marker.ok, markerless.detail
    np.testing.assert_allclose(markerless.estimate_head_m, marker.estimate_head_m, atol=1e-4)
    assert len(pair.tracker.matches) > 2 and len(pair.finder.matches) > 2
    assert all(m.ok for m in pair.finder.matches + pair.tracker.matches)
