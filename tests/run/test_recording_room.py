"""A room run's recording (run/recording_room.py, run/mjcf_textures.py), written by a real
run of ``natural_field --fast`` and read back: the textured room as meshes carrying their
textures, each eye's fovea, camera 1's template and camera 2's matched patch, the match
scores and status, the rays to where each eye landed; and the textured meshes' geometry
(exact)."""

from __future__ import annotations

import json
import re
from collections import defaultdict
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
from rerun.chunk import RrdReader

from headsim.cli import main
from headsim.runs import mjcf_textures
from headsim.runs.recording_layout import FOVEA_HALF_PX
from headsim.runs.recording_room import EYE_COLOURS, crop
from headsim.scenario.loading import load_scenario
from headsim.sim import names
from headsim.sim.simulator import HeadSim
from headsim.sim.textured_scene import texture_bytes
from headsim.vision.correspondence import MatchConfig, MatchStatus

from .rrd import rows
from .test_recording_layout import _blueprint_views


@pytest.fixture(scope="module")
def room_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("natural_field")
    rrd = out / "recording.rrd"
    command = ["run", "natural_field", "--fast", "--out", str(out), "--rrd", str(rrd)]
    assert main([*command, "--no-progress"]) == 0
    return rrd, json.loads((out / "results.json").read_text())


def _components(rrd: Path) -> dict[str, set[str]]:
    found: dict[str, set[str]] = defaultdict(set)
    for chunk in RrdReader(rrd).stream():
        found[chunk.entity_path] |= set(chunk.to_record_batch().schema.names)
    return found


def _values(rrd: Path, entity: str, component: str) -> list[Any]:
    """Each row's value of one component (untyped: Arrow's Python values)."""
    return [row["value"] for row in rows(rrd, entity, component)]


def _rgb_rows(rrd: Path, entity: str) -> list[np.ndarray]:
    """The JPEG images logged at ``entity``, decoded (RGB)."""
    images = []
    for value in _values(rrd, entity, "EncodedImage:blob"):
        data = np.frombuffer(bytes(value[0]), dtype=np.uint8)
        decoded = cv2.imdecode(data, cv2.IMREAD_COLOR)
        assert decoded is not None
        images.append(cv2.cvtColor(decoded, cv2.COLOR_BGR2RGB))
    return images


def test_the_room_is_in_3d_as_meshes_carrying_their_textures(room_run: tuple[Path, dict]) -> None:
    rrd, _ = room_run
    scenario = load_scenario("natural_field", fast=True)
    room = scenario.scene.room
    assert room is not None
    found = _components(rrd)
    objects = [*room.surfaces(), *room.objects]  # floor, walls, table; the objects
    assert len(objects) >= 5 + 6
    for obj in objects:
        path = f"/world/model/{obj.name}/{obj.name}"
        assert {"Mesh3D:albedo_texture_buffer", "Mesh3D:vertex_texcoords"} <= found[path], path
    # The texture is the one the renderer used, scaled down: the floor's, row by row.
    floor = room.surfaces()[0]
    [row] = rows(rrd, f"/world/model/{floor.name}/{floor.name}", "Mesh3D:albedo_texture_buffer")
    value: Any = row["value"]
    logged = np.frombuffer(bytes(value[0]), dtype=np.uint8)
    side = mjcf_textures.MAX_TEXTURE_PX
    size = floor.texture.size_px
    made = np.frombuffer(texture_bytes(floor.texture), dtype=np.uint8).reshape(size, size, 3)
    expected = cv2.resize(made, (side, side), interpolation=cv2.INTER_AREA)
    assert logged.size == side * side * 3
    assert np.array_equal(logged.reshape(side, side, 3), expected)
    assert row["frame"] is None  # static: the whole run is in one scene


def test_each_eye_has_its_fovea_and_the_matches_their_patches(room_run: tuple[Path, dict]) -> None:
    rrd, results = room_run
    side = 2 * FOVEA_HALF_PX + 1
    template = 2 * MatchConfig().half_px + 1
    for cam in names.CAMERAS:
        foveas = _rgb_rows(rrd, f"/fovea/{cam}/image")
        assert len(foveas) >= 2 * len(results["measurements"])
        assert all(f.shape == (side, side, 3) for f in foveas)
        assert max(float(f.std()) for f in foveas) > 10.0  # textured, not black
        boxes = _values(rrd, f"/fovea/{cam}/match", "Boxes2D:half_sizes")
        assert boxes and all(b is None or len(b) == 1 for b in boxes)
    templates = _values(rrd, "/fovea/cam1/template", "Image:format")
    assert len(templates) == len(results["measurements"])  # one per clicked target
    assert templates[0][0]["width"] == template
    patches = _values(rrd, "/fovea/cam2/patch", "Image:format")
    assert patches and all(p[0]["height"] == template for p in patches)


def test_match_scores_are_scalars_and_the_status_text(room_run: tuple[Path, dict]) -> None:
    rrd, results = room_run
    for cam in names.CAMERAS:
        scores = [v[0] for v in _values(rrd, f"/correlation/{cam}/score", "Scalars:scalars")]
        ambiguity = [v[0] for v in _values(rrd, f"/correlation/{cam}/ambiguity", "Scalars:scalars")]
        assert scores and len(scores) == len(ambiguity)
        assert all(-1.0 <= s <= 1.0 for s in scores)
        assert all(0.0 <= a <= 1.0 for a in ambiguity)
    texts = [v[0] for v in _values(rrd, "/correlation/status", "TextLog:text")]
    statuses = {s.value for s in MatchStatus}
    assert texts and all(t.split(":")[0].split(" ", 1)[1] in statuses for t in texts)
    # The score camera 2's last match gave is the one the measurement was scored with.
    last = results["measurements"][-1]["fixation"]
    cam2 = [v[0] for v in _values(rrd, "/correlation/cam2/score", "Scalars:scalars")]
    assert any(abs(score - last["match_score"]) < 1e-6 for score in cam2)


def test_rays_run_from_each_eye_to_where_the_scorer_says_it_landed(
    room_run: tuple[Path, dict],
) -> None:
    rrd, results = room_run
    fixations = [m["fixation"] for m in results["measurements"] if m["status"] == "ok"]
    assert fixations
    strips = _values(rrd, "/world/landing/rays", "LineStrips3D:strips")[-1]
    colours = _values(rrd, "/world/landing/rays", "LineStrips3D:colors")[-1]
    assert len(strips) == 2 * len(fixations)
    settings = load_scenario("natural_field", fast=True).settings
    for k, fixation in enumerate(fixations):
        for camera in (1, 2):
            start, end = (np.array(p) for p in strips[2 * k + camera - 1])
            assert np.allclose(end, fixation["landed_world_m"][camera - 1], atol=1e-5)
            assert np.linalg.norm(end - start) > 0.25  # the targets lie 0.3-2 m deep
            colour = colours[2 * k + camera - 1]
            rgb = ((colour >> 24) & 255, (colour >> 16) & 255, (colour >> 8) & 255)
            assert rgb == EYE_COLOURS[camera - 1]  # no false fixation here
        # The rays start at the two eyes' centres: a baseline apart.
        starts = [np.array(strips[2 * k + c][0]) for c in (0, 1)]
        assert abs(np.linalg.norm(starts[0] - starts[1]) - settings.baseline_m) < 0.01
    targets = _values(rrd, "/world/landing/targets", "Points3D:positions")[-1]
    truth = [m["truth_world_m"] for m in results["measurements"] if m["status"] == "ok"]
    assert np.allclose(np.array(targets), np.array(truth), atol=1e-6)


def test_room_runs_have_the_foveal_views_and_marker_runs_keep_theirs(
    room_run: tuple[Path, dict], recorded: tuple[Path, dict]
) -> None:
    def origins(rrd: Path) -> set[str]:
        views: list[Any] = list(_blueprint_views(rrd).values())
        return {v["origin"][0] for v in views if "origin" in v}

    foveal = {"/fovea/cam1", "/fovea/cam1/template", "/fovea/cam2", "/fovea/cam2/patch"}
    room, markers = origins(room_run[0]), origins(recorded[0])
    assert foveal | {"/correlation", "/correlation/status"} <= room
    assert not (foveal | {"/correlation"}) & markers
    assert {"/world", "/world/head/cam1", "/world/head/cam2", "/servo"} <= room & markers


# -- the textured meshes' geometry (exact) -------------------------------------------------


def _check_faces(mesh: mjcf_textures.Mesh) -> None:
    """Every triangle faces its normal (Rerun's front: counter-clockwise seen from the
    outside) and its texture coordinates lie in [0, 1]."""
    positions, normals, uv, triangles = mesh
    a, b, c = (positions[triangles[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    area = np.linalg.norm(cross, axis=1)
    facing = np.einsum("ij,ij->i", cross, normals[triangles[:, 0]])
    assert np.all(facing[area > 1e-12] > 0.0)
    assert uv.min() >= 0.0 and uv.max() <= 1.0


def test_a_plane_repeats_its_texture_as_mujoco_does() -> None:
    mesh = mjcf_textures.plane_mesh(2.0, 1.5, (4.0, 2.5))
    positions, normals, uv, _ = mesh
    assert len(positions) == 4 * 4 * 3  # 4 x 3 quads: the last row cut at half a tile
    _check_faces(mesh)
    # Column j of the texture runs along +x, row 0 at the +y edge: a tile is 1 m x 1.2 m.
    x, y = positions[:, 0], positions[:, 1]
    tile_x, tile_y = 4.0 / 4.0, 3.0 / 2.5
    u_expected = (x + 2.0) / tile_x - np.floor((x + 2.0) / tile_x + 1e-9)
    v_expected = (1.5 - y) / tile_y - np.floor((1.5 - y) / tile_y + 1e-9)
    inner_u, inner_v = uv[:, 0] < 1.0 - 1e-6, uv[:, 1] < 1.0 - 1e-6  # not a tile's far edge
    assert np.allclose(uv[inner_u, 0], u_expected[inner_u], atol=1e-5)
    assert np.allclose(uv[inner_v, 1], v_expected[inner_v], atol=1e-5)
    assert np.isclose(uv[:, 1].max(), 1.0) and np.any(np.isclose(uv[:, 1], 0.5))
    assert np.all(normals == [0.0, 0.0, 1.0])


@pytest.mark.parametrize(
    "mesh",
    [
        mjcf_textures.box_mesh(np.array([0.1, 0.2, 0.3])),
        mjcf_textures.cylinder_mesh(0.05, 0.07),
        mjcf_textures.sphere_mesh(0.08),
    ],
    ids=["box", "cylinder", "sphere"],
)
def test_closed_shapes_face_outwards_and_lie_on_their_surface(
    mesh: mjcf_textures.Mesh,
) -> None:
    _check_faces(mesh)
    positions, normals, _, _ = mesh
    assert np.all(np.einsum("ij,ij->i", positions, normals) > 0.0)  # outward


def test_the_model_texture_is_read_and_scaled_down() -> None:
    scenario = load_scenario("natural_field", fast=True)
    sim = HeadSim("default", scenario.settings, room=scenario.scene.room)
    model = sim.model
    textured = [g for g in range(model.ngeom) if mjcf_textures.texture_id(model, g) >= 0]
    assert len(textured) >= 11
    image = mjcf_textures.texture_image(model, mjcf_textures.texture_id(model, textured[0]), 256)
    assert image.shape == (256, 256, 3)


def test_a_crop_off_the_image_is_black_there() -> None:
    image = np.arange(5 * 6 * 3, dtype=np.uint8).reshape(5, 6, 3)
    out = crop(image, (0.4, 4.2), 1)  # centre (0, 4): the left column and bottom row off
    assert out.shape == (3, 3, 3)
    assert np.array_equal(out[:2, 1:], image[3:5, 0:2])
    assert not out[:, 0].any() and not out[2].any()


def test_every_entity_of_the_room_recording_is_documented(room_run: tuple[Path, dict]) -> None:
    rrd, _ = room_run
    page = (Path(__file__).resolve().parents[2] / "docs" / "how-to" / "record.md").read_text()
    table = page[page.index("| entity | type | what |") :].split("\n\n")[0]
    documented = set()
    for cell in re.findall(r"^\| ([^|]+) \|", table, re.M):
        paths = re.findall(r"`([^`]+)`", cell)
        for p in paths:  # "..." continues the first path's parent
            documented.add(paths[0].rsplit("/", 2)[0] + p[3:] if p.startswith("...") else p)
    entities = {c.entity_path for c in RrdReader(rrd).stream()}
    room = {e for e in entities if e.startswith(("/fovea", "/correlation", "/world/landing"))}
    assert len(room) == 14  # 5 correlation, 6 foveal, 3 landing
    others = {e for e in entities if not e.startswith(("/__", "/world/model/"))}
    assert others <= documented, others - documented
