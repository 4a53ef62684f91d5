"""The shipped independent_eyes head (models/independent_eyes.xml), with real MuJoCo: the
paper's neck and cameras with a motor per eye and none of head.xml's names, and on the
simulator its cameras where the paper head's are.  What every shipped head must satisfy
is tests/models/test_shipped_heads.py's."""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np
import pytest

from headsim.sim import heads
from headsim.sim.model import MODELS_DIR, on_head
from headsim.sim.settings import preset
from headsim.sim.simulator import HeadSim
from tests.models.mjcf import NAMED_KINDS, TIGHT, load, posed, settle


def test_independent_eyes_has_no_coupling_and_none_of_head_xmls_names() -> None:
    model = load("independent_eyes")
    paper = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "head.xml"))
    assert model.neq == 0
    assert model.nu == 4
    for kind, count in NAMED_KINDS.items():
        if kind in (mujoco.mjtObj.mjOBJ_GEOM, mujoco.mjtObj.mjOBJ_KEY):
            continue  # visual geoms may share names; "home" is every head's keyframe
        ours = {mujoco.mj_id2name(model, kind, i) for i in range(getattr(model, count))}
        theirs = {mujoco.mj_id2name(paper, kind, i) for i in range(getattr(paper, count))}
        assert not (ours & theirs) - {"world"}, kind.name
    # Each eye motor drives its own pan joint, and nothing else.
    for motor, joint in (("left_eye_motor", "left_eye_pan"), ("right_eye_motor", "right_eye_pan")):
        actuator = model.actuator(motor)
        assert actuator.trntype[0] == mujoco.mjtTrn.mjTRN_JOINT
        assert actuator.trnid[0] == model.joint(joint).id


def test_independent_eyes_keeps_the_papers_neck_and_cameras() -> None:
    model = load("independent_eyes")
    paper = mujoco.MjModel.from_xml_path(str(MODELS_DIR / "head.xml"))
    for yaw, pitch in ((0.0, 0.0), (0.4, -0.3)):
        ours = posed(model, neck_yaw_joint=yaw, neck_pitch_joint=pitch)
        theirs = posed(paper, neck_yaw=yaw, neck_pitch=pitch)
        assert np.allclose(
            ours.xpos[model.body("head_frame").id],
            theirs.xpos[paper.body("head").id],
            rtol=0,
            atol=TIGHT,
        )
        assert np.allclose(
            ours.xmat[model.body("head_frame").id],
            theirs.xmat[paper.body("head").id],
            rtol=0,
            atol=TIGHT,
        )
        assert np.allclose(ours.cam_xpos, theirs.cam_xpos, rtol=0, atol=TIGHT)
    assert np.array_equal(model.cam_resolution, paper.cam_resolution)
    assert np.array_equal(model.cam_intrinsic, paper.cam_intrinsic)


def test_independent_eyes_motors_turn_one_eye_each() -> None:
    model = load("independent_eyes")
    data = settle(model, {"left_eye_motor": 0.2, "right_eye_motor": -0.05})
    assert data.qpos[model.joint("left_eye_pan").qposadr[0]] == pytest.approx(0.2, abs=1e-6)
    assert data.qpos[model.joint("right_eye_pan").qposadr[0]] == pytest.approx(-0.05, abs=1e-6)


def test_a_cameras_offsets_act_once_on_another_head_as_on_the_papers() -> None:
    """independent_eyes is the paper's geometry with a motor per eye: under the realistic
    preset (entrance pupils 20 mm ahead, sideways offsets, tilted axes) its cameras sit
    exactly where the paper head's do, at every eye angle (joint errors off: each eye's
    own motor draws its own count error)."""
    realistic = replace(preset("realistic"), backlash_rad=0.0, count_error=False)
    other = on_head(realistic, heads.shipped("independent_eyes"))
    with HeadSim(settings=realistic) as paper, HeadSim(settings=other) as sim:
        for eye in (0.0, 0.2, -0.1):
            paper.move(eye=eye)
            sim.move(eye=eye)
            for camera in (1, 2):
                np.testing.assert_allclose(
                    sim.head_from_camera(camera), paper.head_from_camera(camera), atol=1e-9
                )
