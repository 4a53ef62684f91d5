"""MJCF geoms logged to Rerun: every visible geom of every model file, read back from a real .rrd."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import mujoco
import numpy as np
import pytest
import rerun as rr
from rerun.chunk import RrdReader

from headsim.cli import main
from headsim.runs import mjcf_rerun
from headsim.sim.model import HEAD_PREFIX, MODELS_DIR

MODEL_FILES = sorted(MODELS_DIR.glob("*.xml"))

#: Each batched archetype's per-instance size component.
_SIZE_COMPONENT = {
    "Boxes3D": "Boxes3D:half_sizes",
    "Ellipsoids3D": "Ellipsoids3D:half_sizes",
    "Cylinders3D": "Cylinders3D:lengths",
    "Capsules3D": "Capsules3D:lengths",
}


def _columns(path: Path) -> dict[str, dict[str, list[object]]]:
    """entity -> component -> the values of its last row (static or temporal)."""
    out: dict[str, dict[str, list[object]]] = defaultdict(dict)
    for chunk in RrdReader(path).stream():
        batch = chunk.to_record_batch()
        for name in batch.schema.names:
            if ":" in name:
                values = batch.column(name).to_pylist()
                if values and values[-1] is not None:
                    out[chunk.entity_path][name] = values[-1]
    return out


def _record(tmp_path: Path, model: mujoco.MjModel, data: mujoco.MjData) -> tuple[Path, object]:
    path = tmp_path / "geometry.rrd"
    rec = rr.RecordingStream("headsim_test", recording_id="geometry")
    rec.save(path)
    geometry = mjcf_rerun.log_model_geometry(rec, model)
    rec.set_time("frame", sequence=0)
    mjcf_rerun.BodyPoses(model).log(rec, data)
    rec.flush()
    rec.disconnect()
    return path, geometry


def _pose(values: dict[str, list[object]]) -> np.ndarray:
    """world_from_body (4x4) from a logged Transform3D (translation, xyzw quaternion)."""
    x, y, z, w = values.get("Transform3D:quaternion", [[0.0, 0.0, 0.0, 1.0]])[0]
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, np.array([w, x, y, z], dtype=float))
    pose = np.eye(4)
    pose[:3, :3] = matrix.reshape(3, 3)
    pose[:3, 3] = values.get("Transform3D:translation", [[0.0, 0.0, 0.0]])[0]
    return pose


@pytest.mark.parametrize("model_file", MODEL_FILES, ids=lambda p: p.name)
def test_every_geom_of_every_model_file_is_logged_where_mujoco_puts_it(
    tmp_path: Path, model_file: Path
) -> None:
    model = mujoco.MjModel.from_xml_path(str(model_file))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    data.qpos[:] = np.resize([0.3, -0.2, 0.1, 0.1], model.nq)  # a pose other than home
    mujoco.mj_forward(model, data)
    path, geometry = _record(tmp_path, model, data)
    assert geometry.skipped == () and geometry.invisible == ()
    assert len(geometry.logged) == model.ngeom
    assert sorted(g.geom for g in geometry.logged) == sorted(
        mjcf_rerun.geom_name(model, g) for g in range(model.ngeom)
    )
    columns = _columns(path)
    # Instances in the file: one per geom, in the batch of its body and archetype.
    by_entity: dict[str, list[mjcf_rerun.LoggedGeom]] = defaultdict(list)
    for logged in geometry.logged:
        by_entity[logged.path].append(logged)
    assert sum(len(columns[e][_SIZE_COMPONENT[g[0].archetype]]) for e, g in by_entity.items()) == (
        model.ngeom
    )
    # Each geom's centre, through the logged body pose, is where MuJoCo has it.
    for entity, logged in by_entity.items():
        body = entity.rsplit("/", 1)[0]
        world_from_body = _pose(columns.get(body, {}))  # the world body: identity
        component = logged[0].archetype + ":centers"
        centres = columns[entity].get(component, [[0.0, 0.0, 0.0]] * len(logged))
        for geom, centre in zip(logged, centres, strict=True):
            geom_id = model.geom(geom.geom).id
            if geom.type == "plane":
                continue  # drawn as a slab just below its surface
            world = world_from_body @ np.append(centre, 1.0)
            np.testing.assert_allclose(world[:3], data.geom_xpos[geom_id], atol=1e-6)
            colour = columns[entity][logged[0].archetype + ":colors"][logged.index(geom)]
            expected = np.round(mjcf_rerun.geom_rgba(model, geom_id) * 255).astype(int)
            rgba = [(colour >> s) & 0xFF for s in (24, 16, 8, 0)]
            np.testing.assert_allclose(rgba, expected, atol=1)


def test_colours_come_from_geom_material_and_texture() -> None:
    model = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "scene_blocks.xml"))
    # A material's colour (emissive markers).
    np.testing.assert_allclose(mjcf_rerun.geom_rgba(model, model.geom("object_1").id), [1, 0, 0, 1])
    # A default class's rgba (the head's grey).
    np.testing.assert_allclose(
        mjcf_rerun.geom_rgba(model, model.geom("skull").id), [0.55, 0.57, 0.6, 1]
    )
    # A textured material: the mean of its checker's two colours.
    floor = mjcf_rerun.geom_rgba(model, model.geom("floor").id)
    np.testing.assert_allclose(floor[:3], [0.28, 0.28, 0.30], atol=0.01)


_SHAPES = """
<mujoco>
  <asset>
    <mesh name="tetra" vertex="0 0 0  0.1 0 0  0 0.1 0  0 0 0.1"/>
    <hfield name="bumps" nrow="3" ncol="4" size="0.3 0.2 0.05 0.01"
            elevation="0 1 0 1  1 0 1 0  0 1 0 1"/>
  </asset>
  <worldbody>
    <body name="thing" pos="0.1 0.2 0.3" euler="0.3 0.2 0.1">
      <freejoint/>
      <geom name="cap" type="capsule" size="0.02 0.05" pos="0.01 0.02 0.03" euler="0.5 0 0"/>
      <geom name="egg" type="ellipsoid" size="0.01 0.02 0.03" rgba="0 1 0 1"/>
      <geom name="tetra" type="mesh" mesh="tetra" pos="0 0 0.2"/>
      <geom name="ghost" type="sphere" size="0.01" rgba="1 1 1 0"/>
    </body>
    <geom name="ground" type="hfield" hfield="bumps"/>
    <geom name="endless" type="plane" size="0 0 1"/>
  </worldbody>
</mujoco>
"""


def test_capsules_meshes_height_fields_and_invisible_geoms(tmp_path: Path) -> None:
    model = mujoco.MjModel.from_xml_string(_SHAPES)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    path, geometry = _record(tmp_path, model, data)
    assert geometry.invisible == ("ghost",)
    assert {g.geom: g.archetype for g in geometry.logged} == {
        "cap": "Capsules3D",
        "egg": "Ellipsoids3D",
        "tetra": "Mesh3D",
        "ground": "Mesh3D",
        "endless": "Boxes3D",
    }
    columns = _columns(path)
    # Rerun's capsule starts at its translation: the MuJoCo capsule's lower end cap centre.
    capsule = columns["/world/model/thing/capsules"]
    cap = model.geom("cap")
    axis = np.zeros(3)
    mujoco.mju_rotVecQuat(axis, np.array([0.0, 0.0, 1.0]), cap.quat)
    np.testing.assert_allclose(capsule["Capsules3D:translations"][0], cap.pos - 0.05 * axis)
    np.testing.assert_allclose(capsule["Capsules3D:lengths"], [0.1])
    np.testing.assert_allclose(
        columns["/world/model/thing/ellipsoids"]["Ellipsoids3D:half_sizes"], [[0.01, 0.02, 0.03]]
    )
    mesh = columns["/world/model/thing/tetra"]
    assert len(mesh["Mesh3D:vertex_positions"]) == 4
    assert len(mesh["Mesh3D:triangle_indices"]) == model.mesh_facenum[0]
    np.testing.assert_allclose(mesh["Transform3D:translation"][0], model.geom("tetra").pos)
    ground = columns["/world/model/world/ground"]
    assert len(ground["Mesh3D:vertex_positions"]) == 12
    assert len(ground["Mesh3D:triangle_indices"]) == 2 * 2 * 3
    assert np.max(np.array(ground["Mesh3D:vertex_positions"])[:, 2]) == pytest.approx(0.05)
    # An infinite plane is drawn as a finite slab.
    half = columns["/world/model/world/boxes"]["Boxes3D:half_sizes"][0]
    assert half[0] > 0 and half[1] > 0 and half[2] < 0.001
    # The moving body's pose.
    thing = columns["/world/model/thing"]
    np.testing.assert_allclose(thing["Transform3D:translation"][0], data.xpos[1])


def test_body_poses_are_logged_only_when_a_body_moved() -> None:
    model = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rec = rr.RecordingStream("headsim_test")  # no sink: logging is dropped
    poses = mjcf_rerun.BodyPoses(model)
    assert poses.log(rec, data) == model.nbody - 1  # every body but the world
    assert poses.log(rec, data) == 0
    data.qpos[model.joint("eye1_yaw").qposadr[0]] = 0.1
    mujoco.mj_forward(model, data)
    assert poses.log(rec, data) == 1


def test_a_run_on_another_head_draws_that_head_s_geoms(tmp_path: Path) -> None:
    """``headsim run independent_eyes --rrd``: the attached head's bodies and geoms, named
    as the scene names them (``head:`` escaped as Rerun escapes it), each body posed."""
    rrd = tmp_path / "run.rrd"
    argv = ["run", "independent_eyes", "--fast", "--out", str(tmp_path / "out"), "--rrd", str(rrd)]
    assert main([*argv, "--no-progress"]) == 0
    columns = _columns(rrd)
    head = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "independent_eyes.xml"))
    prefix = f"{mjcf_rerun.ROOT}/{rr.escape_entity_path_part(HEAD_PREFIX)}"
    assert prefix == "/world/model/head\\:"
    for body in range(1, head.nbody):
        values = columns[prefix + rr.escape_entity_path_part(head.body(body).name)]
        assert "Transform3D:translation" in values, head.body(body).name
    # One drawn instance per geom of the head's file, all under its prefixed bodies.
    drawn = sum(
        len(values)
        for entity, components in columns.items()
        if entity.startswith(prefix)
        for component, values in components.items()
        if component in _SIZE_COMPONENT.values()
    )
    assert drawn == head.ngeom > 0
    # The scenes' own head (models/head.xml) is not drawn beside it.
    assert not any(entity.startswith(f"{mjcf_rerun.ROOT}/head/") for entity in columns)
    assert f"{mjcf_rerun.ROOT}/eye1" not in columns
