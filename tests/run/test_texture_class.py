"""Each markerless target's texture class, from truth at placement, in a real scene: the
texture of the object it lies on, or ``occluded`` when a thing in front hides part of a
camera's template window from the other camera (and only then)."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from headsim.runs.landing import ray_direction_world
from headsim.runs.texture_class import patch_hidden, texture_class, texture_kinds
from headsim.scenario.surface_targets import camera_centre, visible
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.sim.textured_scene import RoomSpec, SceneObject
from headsim.sim.textures import TextureSpec
from headsim.vision.correspondence import MatchConfig

HALF_PX = MatchConfig().half_px
LOW_BOX = SceneObject("low_box", "box", (0.06, 0.06, 0.06), (0.15, 0.9, 0.05), TextureSpec("low"))
STRIPES = SceneObject(
    "stripes", "plane", (0.15, 0.1, 1.0), (0.3, 1.6, 0.2), TextureSpec("grating"),
    pitch_rad=math.pi / 2,
)  # fmt: skip
PANEL = SceneObject(
    "panel", "plane", (0.3, 0.3, 1.0), (-0.25, 1.6, 0.2), TextureSpec("pink", seed=2),
    pitch_rad=math.pi / 2,
)  # fmt: skip
#: A point on the pink panel, and where camera 1 sees a pixel 0.7 of the window's half-side
#: beside it at 0.35 m: a post there hides part of the window, not the point itself.
ON_PANEL = np.array([-0.2, 1.6, 0.2])


def _post(sim: HeadSim) -> SceneObject:
    u, v = sim.project(ON_PANEL[None, :], 1)[0]
    origin = camera_centre(sim, 1)
    centre = origin + 0.35 * ray_direction_world(sim, 1, (u + 0.7 * HALF_PX, v))
    to_point = (ON_PANEL - origin) / np.linalg.norm(ON_PANEL - origin)
    off = centre - origin
    clearance = float(np.linalg.norm(off - (off @ to_point) * to_point))
    return SceneObject(
        "post",
        "sphere",
        (0.5 * clearance, 0.0, 0.0),
        (float(centre[0]), float(centre[1]), float(centre[2])),
        TextureSpec("pink"),
    )


@pytest.fixture(scope="module")
def open_room() -> Iterator[HeadSim]:
    with HeadSim("default", HeadSettings(), room=RoomSpec(objects=(LOW_BOX, STRIPES, PANEL))) as s:
        yield s


def test_a_target_takes_the_class_of_the_texture_it_lies_on(open_room: HeadSim) -> None:
    room = RoomSpec(objects=(LOW_BOX, STRIPES, PANEL))
    kinds = texture_kinds(room)
    assert kinds["low_box"] == "low" and kinds["room_floor"] == "pink"
    points = {
        "low_box": np.array([0.15, 0.84, 0.05]),  # the box's front face
        "stripes": np.array([0.3, 1.6, 0.2]),
        "panel": ON_PANEL,
    }
    classes = {b: texture_class(open_room, kinds, b, p, HALF_PX) for b, p in points.items()}
    assert classes == {"low_box": "low", "stripes": "repetitive", "panel": "rich"}


def test_a_target_part_of_whose_window_one_eye_cannot_see_is_occluded(open_room: HeadSim) -> None:
    post = _post(open_room)
    room = RoomSpec(objects=(LOW_BOX, STRIPES, PANEL, post))
    with HeadSim("default", HeadSettings(), room=room) as sim:
        # The point itself is in sight of both: only its window is partly hidden.
        assert visible(sim, 1, ON_PANEL) and visible(sim, 2, ON_PANEL)
        assert patch_hidden(sim, ON_PANEL, HALF_PX)
        assert texture_class(sim, texture_kinds(room), "panel", ON_PANEL, HALF_PX) == "occluded"
    assert not patch_hidden(open_room, ON_PANEL, HALF_PX)
