"""Targets on textured surfaces, the truth side: where a point on an object is, whether it
lies on a surface, whether camera 1 sees it, the click that tells the head, and random
targets on the surfaces the start pose sees.  A real model; exact geometry."""

from __future__ import annotations

import math
from collections.abc import Iterator

import mujoco
import numpy as np
import pytest

from headsim.scenario.surface_targets import (
    ON_SURFACE_M,
    SURFACE_REFUSALS,
    NotOnSurface,
    click,
    draw_targets,
    on_object,
    on_surface,
    surface_distance_m,
    surface_of,
    visible,
)
from headsim.sim.settings import HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.sim.textured_scene import RoomSpec, SceneObject
from headsim.sim.textures import TextureSpec

G = mujoco.mjtGeom


@pytest.mark.parametrize(
    ("geom", "size", "point", "distance"),
    [
        (G.mjGEOM_SPHERE, (0.1, 0, 0), (0.0, 0.3, 0.0), 0.2),
        (G.mjGEOM_SPHERE, (0.1, 0, 0), (0.0, 0.0, 0.04), 0.06),  # inside
        (G.mjGEOM_BOX, (0.1, 0.2, 0.3), (0.15, 0.0, 0.0), 0.05),  # off a face
        (G.mjGEOM_BOX, (0.1, 0.2, 0.3), (0.13, 0.24, 0.0), 0.05),  # off an edge: 3-4-5
        (G.mjGEOM_BOX, (0.1, 0.2, 0.3), (0.0, 0.0, 0.25), 0.05),  # inside, nearest the top
        (G.mjGEOM_CYLINDER, (0.1, 0.2, 0), (0.0, 0.3, 0.0), 0.2),  # off the side
        (G.mjGEOM_CYLINDER, (0.1, 0.2, 0), (0.03, 0.04, 0.3), 0.1),  # above the cap
        (G.mjGEOM_PLANE, (0.5, 0.5, 1), (0.2, -0.1, 0.004), 0.004),
        (G.mjGEOM_PLANE, (0.5, 0.5, 1), (0.53, 0.0, 0.04), 0.05),  # beyond its edge
    ],
)
def test_the_distance_from_a_surface_is_exact(geom, size, point, distance) -> None:
    assert surface_distance_m(int(geom), size, np.array(point)) == pytest.approx(
        distance, abs=1e-15
    )


BOX = SceneObject("crate", "box", (0.1, 0.05, 0.08), (0.2, 1.0, 0.1), TextureSpec("grating"),
                  yaw_rad=0.4)  # fmt: skip
PANEL = SceneObject(
    "panel", "plane", (0.6, 0.4, 1.0), (0.0, 1.8, 0.2), TextureSpec("pink", seed=2),
    pitch_rad=math.pi / 2,
)  # fmt: skip


@pytest.fixture(scope="module")
def sim() -> Iterator[HeadSim]:
    with HeadSim("default", HeadSettings(), room=RoomSpec(objects=(BOX, PANEL))) as s:
        yield s


def test_a_point_on_an_object_is_where_its_pose_puts_it(sim: HeadSim) -> None:
    target = on_object(sim, "corner", "crate", (0.1, -0.02, 0.03))  # on its +x face
    rotation = BOX.world_from_object
    expected = np.array(BOX.pos_world_m) + rotation @ np.array([0.1, -0.02, 0.03])
    np.testing.assert_allclose(target.point_world_m, expected, atol=1e-12)
    with pytest.raises(NotOnSurface, match=r"5\.0 mm from 'crate'"):
        on_object(sim, "off", "crate", (0.105, -0.02, 0.03))
    with pytest.raises(NotOnSurface, match="no object named 'mug'"):
        on_object(sim, "gone", "mug", (0.0, 0.0, 0.0))


def test_a_world_point_is_a_target_only_on_a_surface(sim: HeadSim) -> None:
    on_panel = np.array([0.1, 1.8 + 0.4 * ON_SURFACE_M, 0.25])
    target = on_surface(sim, "t", on_panel)
    assert target.body == "panel"
    np.testing.assert_allclose(target.point_world_m, on_panel)
    with pytest.raises(NotOnSurface, match="mm from the nearest surface"):
        on_surface(sim, "air", np.array([0.0, 1.2, 0.2]))


def test_a_point_behind_the_panel_is_hidden_and_one_on_it_is_seen(sim: HeadSim) -> None:
    on_panel = np.array([-0.1, 1.8, 0.15])
    assert visible(sim, 1, on_panel) and visible(sim, 2, on_panel)
    behind = np.array([-0.1, 3.0, 0.15])  # on the back wall, behind the panel
    assert surface_of(sim, behind)[1] <= ON_SURFACE_M
    assert not visible(sim, 1, behind) and not visible(sim, 2, behind)


def test_the_click_is_the_true_projection_plus_its_stated_error(sim: HeadSim) -> None:
    point = np.array([-0.1, 1.8, 0.15])
    exact = click(sim, point, np.random.default_rng(0), error_px=0.0)
    np.testing.assert_allclose(exact.true_uv, sim.project(point[None, :], 1)[0])
    assert exact.clicked_uv == exact.true_uv
    errors = np.array(
        [
            np.subtract(c.clicked_uv, c.true_uv)
            for c in (click(sim, point, np.random.default_rng(k)) for k in range(400))
        ]
    )
    assert errors.std() == pytest.approx(0.5, rel=0.1)
    assert click(sim, point, np.random.default_rng(7)) == click(
        sim, point, np.random.default_rng(7)
    )


def test_random_targets_lie_on_surfaces_both_cameras_see_and_every_draw_is_counted(
    sim: HeadSim,
) -> None:
    drawn = draw_targets(sim, 4, np.random.default_rng(3), depth_m=(0.5, 2.5), lateral=0.3)
    assert len(drawn.targets) == 4
    assert drawn.drawn == 4 + sum(drawn.refused.values())
    assert set(drawn.refused) <= set(SURFACE_REFUSALS)
    for target in drawn.targets:
        p = np.array(target.point_world_m)
        assert surface_of(sim, p)[1] <= ON_SURFACE_M
        assert visible(sim, 1, p) and visible(sim, 2, p)
        assert 0.5 <= sim.transform_points(p, "world", "head")[0][2] <= 2.5
    again = draw_targets(sim, 4, np.random.default_rng(3), depth_m=(0.5, 2.5), lateral=0.3)
    assert again == drawn
