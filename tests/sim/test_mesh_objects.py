"""Room objects as simple meshes: exact distances to triangles, the texture's projection,
and a textured wedge rendered, met by rays, targeted on its surface and read from a
scenario's keys."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from headsim.runs.mjcf_textures import mesh_mesh
from headsim.scenario.loading import load_scenario, scenario_from_document
from headsim.scenario.surface_targets import (
    NotOnSurface,
    cast,
    on_object,
    surface_normal,
    triangle_distance_m,
)
from headsim.scenario.tables import ScenarioError
from headsim.sim.simulator import HeadSim
from headsim.sim.textured_scene import SceneObject, mesh_texcoords
from headsim.sim.textures import TextureSpec

# A wedge on a 16 x 10 cm base, 10 cm high at the back, its slope facing -y and up.
WEDGE_V = (
    (-0.08, -0.05, -0.05), (0.08, -0.05, -0.05), (0.08, 0.05, -0.05),
    (-0.08, 0.05, -0.05), (-0.08, 0.05, 0.05), (0.08, 0.05, 0.05),
)  # fmt: skip
WEDGE_F = ((0, 2, 1), (0, 3, 2), (0, 1, 5), (0, 5, 4), (3, 4, 5), (3, 5, 2), (0, 4, 3), (1, 2, 5))
CENTRE = (-0.05, 0.8, 0.2)  # in the head's view, in front of the back wall
TRIANGLE = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])


@pytest.mark.parametrize(
    ("point", "distance"),
    [
        ((0.2, 0.2, 0.3), 0.3),  # above the inside: the height
        ((0.5, -0.4, 0.0), 0.4),  # beside an edge, in the plane
        ((-0.3, -0.4, 1.2), 1.3),  # beyond a corner: to the vertex
        ((1.0, 1.0, 0.0), math.sqrt(0.5)),  # beyond the hypotenuse
    ],
)
def test_the_distance_to_a_triangle_is_exact(point: tuple[float, ...], distance: float) -> None:
    assert triangle_distance_m(np.array(point), TRIANGLE) == pytest.approx(distance, rel=1e-12)


def test_each_face_takes_the_texture_projected_on_the_plane_it_faces() -> None:
    uv, index = mesh_texcoords(np.array(WEDGE_V), np.array(WEDGE_F), tile_m=0.2)
    assert uv.shape == (3 * len(WEDGE_F), 2) and index.shape == (len(WEDGE_F), 3)
    # The base faces -z: its corners' (x, y) over the tile.
    np.testing.assert_allclose(
        uv[:3], np.array([[-0.08, -0.05], [0.08, 0.05], [0.08, -0.05]]) / 0.2
    )
    # The back faces +y: (z, x).
    np.testing.assert_allclose(uv[12], np.array([-0.05, -0.08]) / 0.2)


@pytest.fixture(scope="module")
def sim() -> HeadSim:
    scenario = load_scenario("natural_field", fast=True)
    assert scenario.scene.room is not None
    wedge = SceneObject(
        "wedge", "mesh", (0.0, 0.0, 0.0), CENTRE, TextureSpec("pink", seed=3), tile_m=0.2,
        vertices_m=WEDGE_V, faces=WEDGE_F,
    )  # fmt: skip
    room = replace(scenario.scene.room, objects=(*scenario.scene.room.objects, wedge))
    return HeadSim("default", scenario.settings, room=room)


def test_a_textured_wedge_is_drawn_with_its_texture_and_met_by_rays(sim: HeadSim) -> None:
    # A point on the slope, 2 cm above the front edge's middle.
    on_slope = np.array(CENTRE) + np.array([0.0, -0.03, -0.03])
    u, v = sim.project(on_slope[None, :], 1)[0]
    image = sim.render(1).astype(float).mean(axis=2)
    patch = image[round(v) - 8 : round(v) + 9, round(u) - 8 : round(u) + 9]
    assert patch.std() > 5.0  # pink noise, not a flat colour
    origin = sim.world_from_camera(1)[:3, 3]
    hit, _, geom = cast(sim.model, sim.data, origin, on_slope - origin)
    assert hit is not None and sim.model.geom(geom).name == "wedge"
    assert float(np.linalg.norm(hit - on_slope)) < 1e-9
    # The slope's outward normal: toward the head and up, at 45 degrees.
    np.testing.assert_allclose(surface_normal(sim, on_slope), [0.0, -1 / 2**0.5, 1 / 2**0.5])


def test_a_target_on_the_wedge_is_on_its_surface_and_one_beside_it_is_not(sim: HeadSim) -> None:
    target = on_object(sim, "t", "wedge", (0.0, -0.03, -0.03))
    np.testing.assert_allclose(target.point_world_m, np.add(CENTRE, (0.0, -0.03, -0.03)))
    with pytest.raises(NotOnSurface, match=r"lies 5\.0 mm from 'wedge''s surface"):
        on_object(sim, "t", "wedge", (0.0, -0.03 - 0.005 / 2**0.5, -0.03 + 0.005 / 2**0.5))


def test_the_recordings_mesh_has_each_faces_own_vertices(sim: HeadSim) -> None:
    positions, normals, uv, triangles = mesh_mesh(sim.model, sim.model.geom("wedge").id)
    assert positions.shape == (3 * len(WEDGE_F), 3) and triangles.shape == (len(WEDGE_F), 3)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0)
    assert uv.min() >= 0.0 and uv.reshape(-1, 3, 2).min(axis=1).max() < 1.0


def _doc(obj: dict) -> dict:
    return {
        "description": "d",
        "experiment": {"procedure": "model2"},
        "scene": {"room": {"clutter": 0, "targets": 1, "objects": [obj]}},
    }


def test_a_mesh_objects_keys_are_checked() -> None:
    wedge = {
        "name": "wedge", "shape": "mesh", "pos_world_m": [0.0, 1.0, 0.0],
        "vertices_m": [list(v) for v in WEDGE_V], "faces": [list(f) for f in WEDGE_F],
    }  # fmt: skip
    scenario = scenario_from_document(_doc(wedge), "s")
    assert scenario.scene.room is not None
    (obj,) = [o for o in scenario.scene.room.objects if o.name == "wedge"]
    assert obj.vertices_m == WEDGE_V and obj.faces == WEDGE_F
    bad_index = {**wedge, "faces": [*wedge["faces"][:1], [0, 1, 9], *wedge["faces"][2:]]}
    with pytest.raises(ScenarioError, match=r"objects\[0\]\.faces\[1\]: must be three vertex"):
        scenario_from_document(_doc(bad_index), "s")
    flat = {**wedge, "faces": [[0, 1, 1], *wedge["faces"][1:]]}
    with pytest.raises(ScenarioError, match=r"faces\[0\]: has no area"):
        scenario_from_document(_doc(flat), "s")
    with pytest.raises(ScenarioError, match=r"objects\[0\]\.size_m"):
        scenario_from_document(_doc({**wedge, "size_m": [0.1, 0.1, 0.1]}), "s")
