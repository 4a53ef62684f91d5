"""Where the eyes actually landed: the pure angles on exact synthetic geometry, and the
goal rays cast into a real model against the analytic intersection."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from headsim.runs.landing import (
    angle_deg,
    fixation_error,
    fixation_truth,
    landing,
    vergence_error_deg,
)
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.sim.textured_scene import RoomSpec, SceneObject
from headsim.sim.textures import TextureSpec

PANEL_Y_M = 1.5


def _rotate_z(v: np.ndarray, angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ v


def test_the_angle_between_directions_is_exact_near_zero_and_far_from_it() -> None:
    x = np.array([1.0, 0.0, 0.0])
    for degrees in (1e-7, 0.01, 1.0, 45.0, 179.0):
        turned = _rotate_z(x, math.radians(degrees)) * 3.0  # lengths do not matter
        assert angle_deg(x, turned) == pytest.approx(degrees, rel=1e-9)


def test_vergence_error_is_the_angle_off_the_point_eye_one_landed_on() -> None:
    o2 = np.array([0.075, 0.0, 0.0])
    landed1 = np.array([-0.01, 0.8, 0.0])  # in the plane of the rotation
    on_point = landed1 - o2
    assert vergence_error_deg(o2, on_point, landed1) == pytest.approx(0.0, abs=1e-12)
    assert vergence_error_deg(o2, _rotate_z(on_point, math.radians(0.3)), landed1) == (
        pytest.approx(0.3, rel=1e-9)
    )


def test_fixation_error_is_an_angle_and_a_distance_from_the_target() -> None:
    origin = np.zeros(3)
    target = np.array([0.0, 1.0, 0.0])
    direction = _rotate_z(target, math.radians(0.5))
    landed = origin + 2.0 * direction  # a surface 2 m along the ray
    error = fixation_error(origin, direction, landed, target)
    assert error.angle_deg == pytest.approx(0.5, rel=1e-9)
    assert error.distance_m == pytest.approx(float(np.linalg.norm(landed - target)), rel=1e-12)
    assert math.isnan(fixation_error(origin, direction, None, target).distance_m)


@pytest.fixture(scope="module")
def sim() -> Iterator[HeadSim]:
    """The ideal head facing a large textured panel at y = PANEL_Y_M (its normal -y)."""
    panel = SceneObject(
        "panel", "plane", (1.5, 1.0, 1.0), (0.0, PANEL_Y_M, 0.2), TextureSpec("pink", seed=1),
        pitch_rad=math.pi / 2,
    )  # fmt: skip
    with HeadSim("default", HeadSettings(), room=RoomSpec(objects=(panel,))) as s:
        yield s


def _analytic(sim: HeadSim, camera: int, uv: tuple[float, float]) -> np.ndarray:
    """The ideal camera's ray through ``uv`` met with the plane y = PANEL_Y_M, W."""
    cam = sim.camera_settings(camera)
    cx, cy = cam.principal
    world_from_cam = sim.world_from_camera(camera)
    ray = world_from_cam[:3, :3] @ np.array([(uv[0] - cx) / cam.kx, (uv[1] - cy) / cam.ky, 1.0])
    origin = world_from_cam[:3, 3]
    return origin + (PANEL_Y_M - origin[1]) / ray[1] * ray


@pytest.mark.parametrize("uv", [(319.5, 239.5), (100.0, 400.0), (600.25, 20.75)])
@pytest.mark.parametrize("camera", [1, 2])
def test_a_goal_ray_lands_where_it_meets_the_plane(
    sim: HeadSim, camera: int, uv: tuple[float, float]
) -> None:
    found = landing(sim, camera, uv)
    assert found.hit and found.body == "panel" and found.geom == "panel"
    assert found.point_world_m is not None
    np.testing.assert_allclose(found.point_world_m, _analytic(sim, camera, uv), atol=1e-9)
    np.testing.assert_allclose(found.origin_world_m, sim.world_from_camera(camera)[:3, 3])


def test_parallel_eyes_at_the_start_miss_each_others_point_by_the_baseline_angle(
    sim: HeadSim,
) -> None:
    centres = [sim.camera_settings(c).principal for c in (1, 2)]
    truth = fixation_truth(sim, (centres[0], centres[1]), np.array([0.0, PANEL_Y_M, 0.2]))
    one, two = truth.landings
    assert one.point_world_m is not None
    offset = one.point_world_m - two.origin_world_m
    expected = math.degrees(math.atan2(math.hypot(offset[0], offset[2]), offset[1]))
    assert truth.vergence_error_deg == pytest.approx(expected, rel=1e-9)
    assert expected > 2.0  # 150 mm at about 1.4 m
    for landed, error in zip(truth.landings, truth.errors, strict=True):
        assert landed.point_world_m is not None
        target = np.array([0.0, PANEL_Y_M, 0.2])
        assert error.distance_m == pytest.approx(np.linalg.norm(landed.point_world_m - target))
