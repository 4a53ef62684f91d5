"""The outward normal at a point on a surface (where the marker twin puts its marker):
exact for a plane stood up, a sphere, a box's face and a cylinder's side and cap."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.scenario.room import RoomGeometry
from headsim.scenario.surface_targets import surface_normal
from headsim.sim.textured_scene import RoomSpec, SceneObject
from headsim.sim.textures import TextureSpec

PINK = TextureSpec("pink")
OBJECTS = (
    SceneObject("board", "plane", (0.2, 0.1, 1.0), (0.5, 1.5, 0.2), PINK, pitch_rad=math.pi / 2),
    SceneObject("ball", "sphere", (0.05, 0.0, 0.0), (-0.5, 1.0, 0.2), PINK),
    SceneObject("crate", "box", (0.1, 0.05, 0.08), (0.0, 1.0, 0.1), PINK, yaw_rad=0.4),
    SceneObject("tin", "cylinder", (0.05, 0.1, 0.0), (0.3, 0.8, 0.1), PINK),
)


@pytest.fixture(scope="module")
def room() -> RoomGeometry:
    return RoomGeometry.of(RoomSpec(objects=OBJECTS))


def test_the_normal_points_out_of_each_shape(room: RoomGeometry) -> None:
    crate = OBJECTS[2].world_from_object
    cases = [
        (np.array([0.55, 1.5, 0.25]), np.array([0.0, -1.0, 0.0])),  # the board faces the head
        (
            np.array([-0.5, 1.0, 0.2]) + 0.05 * np.array([0.6, -0.8, 0.0]),
            np.array([0.6, -0.8, 0.0]),
        ),
        (np.array([0.0, 1.0, 0.1]) + crate @ np.array([0.02, -0.05, 0.03]), crate[:, 1] * -1),
        (np.array([0.3, 0.75, 0.12]), np.array([0.0, -1.0, 0.0])),  # the tin's side
        (np.array([0.31, 0.8, 0.2]), np.array([0.0, 0.0, 1.0])),  # its lid
    ]
    for point, normal in cases:
        np.testing.assert_allclose(surface_normal(room, point), normal, atol=1e-9)
