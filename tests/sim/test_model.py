"""Every model and scene file loads, steps cleanly, and names everything."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from headsim.sim import names
from headsim.sim.model import MODELS_DIR, build_model
from headsim.sim.settings import paper_head

MODEL_FILES = sorted(MODELS_DIR.glob("*.xml"))


def test_models_dir_has_the_head_and_its_scenes() -> None:
    found = {path.name for path in MODEL_FILES}
    assert names.HEAD_MODEL in found
    assert set(names.SCENES.values()) <= found


@pytest.mark.parametrize("path", MODEL_FILES, ids=lambda p: p.name)
def test_model_loads_and_steps_without_warnings(path: Path) -> None:
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(names.HOME).id)
    # Off-home targets for every motor (the heads have 3 to 6), inside each motor's range.
    targets = np.resize([0.3, -0.2, 0.1], model.nu)
    data.ctrl[:] = np.clip(targets, model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1])
    for _ in range(500):
        mujoco.mj_step(model, data)
    assert np.all(data.warning.number == 0), f"MuJoCo warnings: {data.warning.number}"
    assert np.all(np.isfinite(data.qpos))


@pytest.mark.parametrize("path", MODEL_FILES, ids=lambda p: p.name)
def test_every_element_is_named(path: Path) -> None:
    model = mujoco.MjModel.from_xml_path(str(path))
    kinds = {
        "body": (model.nbody, mujoco.mjtObj.mjOBJ_BODY, 1),  # body 0 is the world
        "joint": (model.njnt, mujoco.mjtObj.mjOBJ_JOINT, 0),
        "camera": (model.ncam, mujoco.mjtObj.mjOBJ_CAMERA, 0),
        "site": (model.nsite, mujoco.mjtObj.mjOBJ_SITE, 0),
        "actuator": (model.nu, mujoco.mjtObj.mjOBJ_ACTUATOR, 0),
        "geom": (model.ngeom, mujoco.mjtObj.mjOBJ_GEOM, 0),
    }
    for kind, (count, obj, first) in kinds.items():
        for index in range(first, count):
            assert mujoco.mj_id2name(model, obj, index), f"unnamed {kind} #{index} in {path.name}"


def test_head_has_the_documented_structure() -> None:
    model = mujoco.MjModel.from_xml_path(str(MODELS_DIR / names.HEAD_MODEL))
    for joint in (names.NECK_YAW, names.NECK_PITCH, *names.EYE_JOINTS):
        assert model.joint(joint).type == mujoco.mjtJoint.mjJNT_HINGE
    assert {model.actuator(i).name for i in range(model.nu)} == {
        names.NECK_YAW_MOTOR,
        names.NECK_PITCH_MOTOR,
        names.EYE_MOTOR,
    }
    assert model.equality(names.EYE_COUPLING).type == mujoco.mjtEq.mjEQ_JOINT
    assert model.vis.quality.shadowsize == 0


@pytest.mark.parametrize("scene", sorted(names.SCENES))
def test_scenes_build_with_the_paper_cameras(scene: str) -> None:
    built = build_model(scene, paper_head())
    # The distorted cameras render on a larger pinhole canvas that fits the buffer.
    for canvas in built.canvases:
        assert canvas.size[0] <= built.model.vis.global_.offwidth
        assert canvas.size[1] <= built.model.vis.global_.offheight
        assert canvas.size[0] >= 640 and canvas.size[1] >= 480
