"""The shipped iCub head (models/icub.xml), with real MuJoCo: what its file cites (the
iCub 2.0's neck chain and offsets, eye tilt, version and vergence tendons, cameras), and
the simulator on it: its design, a preset on it, its neck (H10) against MuJoCo's own
kinematics, its version and vergence actuators, and its mapping's errors.  What every
shipped head must satisfy is tests/models/test_shipped_heads.py's."""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np
import pytest

from headsim.sim import heads
from headsim.sim.joints import JointLimitError
from headsim.sim.model import design, neck_of, on_head
from headsim.sim.settings import HeadSettings, preset
from headsim.sim.simulator import HeadSim
from tests.models.mjcf import (
    TIGHT,
    joint_axis_w,
    load,
    posed,
    settle,
    w_from_h,
    w_from_opencv_camera,
)

ICUB = heads.shipped("icub")


def test_icub_neck_pitch_roll_yaw_chain_and_its_offsets() -> None:
    """iKinFwd.cpp (v2): roll 9.5 mm above pitch, yaw through roll, H 50.9 mm ahead, 91.55 mm up."""
    model = load("icub")
    data = posed(model)
    assert [model.joint(j).id for j in ("neck_pitch", "neck_roll", "neck_yaw")] == [0, 1, 2]
    assert np.allclose(
        data.xanchor[model.joint("neck_pitch").id], [0.0, 0.0, 0.0], rtol=0, atol=TIGHT
    )
    assert np.allclose(joint_axis_w(model, data, "neck_roll"), [0.0, 1.0, 0.0], rtol=0, atol=TIGHT)
    assert np.allclose(
        data.xanchor[model.joint("neck_roll").id], [0.0, 0.0, 0.0095], rtol=0, atol=TIGHT
    )
    assert np.allclose(
        data.xanchor[model.joint("neck_yaw").id], [0.0, 0.0, 0.0095], rtol=0, atol=TIGHT
    )
    assert np.allclose(
        data.xpos[model.body("head_center").id], [0.0, 0.0509, 0.09155], rtol=0, atol=TIGHT
    )
    # Positive roll tips the head's top (H's -y) to the right, about the forward axis.
    rolled = posed(model, neck_roll=0.2)
    up_w = -rolled.xmat[model.body("head_center").id].reshape(3, 3)[:, 1]
    assert np.allclose(up_w, [np.sin(0.2), 0.0, np.cos(0.2)], rtol=0, atol=TIGHT)


def test_icub_eyes_tilt_is_about_the_baseline_and_positive_looks_up() -> None:
    model = load("icub")
    home = posed(model)
    tilted = posed(model, eyes_tilt=0.2)
    w_from_h_home = w_from_h(model, home, "icub")
    assert np.allclose(
        joint_axis_w(model, home, "eyes_tilt"), w_from_h_home[:, 0], rtol=0, atol=TIGHT
    )
    # The axis is the baseline: tilting moves neither optical centre, nor H.
    assert np.allclose(tilted.cam_xpos, home.cam_xpos, rtol=0, atol=TIGHT)
    assert np.allclose(w_from_h(model, tilted, "icub"), w_from_h_home, rtol=0, atol=TIGHT)
    for camera in ICUB.mapping.cameras:
        axis_w = w_from_opencv_camera(tilted, model, camera)[:, 2]
        assert np.allclose(axis_w, [0.0, np.cos(0.2), np.sin(0.2)], rtol=0, atol=TIGHT)
    # The pans tilt with the eyes: their axes stay square to the optical axis.
    pan_w = joint_axis_w(model, tilted, "l_eye_pan")
    assert abs(pan_w @ w_from_opencv_camera(tilted, model, "l_eye_camera")[:, 2]) < TIGHT


def test_icub_version_and_vergence_tendons_are_the_stated_pan_combinations() -> None:
    model = load("icub")
    version, vergence = model.tendon("eyes_version").id, model.tendon("eyes_vergence").id
    for left, right in ((0.2, 0.1), (0.1, -0.1), (-0.3, 0.05)):
        data = posed(model, l_eye_pan=left, r_eye_pan=right)
        assert data.ten_length[version] == pytest.approx((left - right) / 2, abs=TIGHT)
        assert data.ten_length[vergence] == pytest.approx(left + right, abs=TIGHT)
    for motor, tendon in (
        ("eyes_version_motor", "eyes_version"),
        ("eyes_vergence_motor", "eyes_vergence"),
    ):
        actuator = model.actuator(motor)
        assert actuator.trntype[0] == mujoco.mjtTrn.mjTRN_TENDON
        assert actuator.trnid[0] == model.tendon(tendon).id


def test_icub_version_turns_both_eyes_one_way_and_vergence_turns_them_inward() -> None:
    model = load("icub")
    left, right = (
        model.joint(j).qposadr[0] for j in (ICUB.mapping.left_eye, ICUB.mapping.right_eye)
    )

    def optical_axes_x_h(data: mujoco.MjData) -> list[float]:
        w_from_h_now = w_from_h(model, data, "icub")
        return [
            (w_from_h_now.T @ w_from_opencv_camera(data, model, c)[:, 2])[0]
            for c in ICUB.mapping.cameras
        ]

    turned = settle(model, {"eyes_version_motor": 0.2})
    assert turned.qpos[left] == pytest.approx(0.2, abs=1e-6)
    assert turned.qpos[right] == pytest.approx(-0.2, abs=1e-6)
    # Both optical axes turn the same way, about H's +y: towards H's +x.
    assert optical_axes_x_h(turned) == pytest.approx([np.sin(0.2)] * 2, abs=1e-6)

    verged = settle(model, {"eyes_vergence_motor": 0.3})
    assert verged.qpos[left] == pytest.approx(0.15, abs=1e-6)
    assert verged.qpos[right] == pytest.approx(0.15, abs=1e-6)
    # Opposite ways: each inward, the left towards +x, the right towards -x.
    assert optical_axes_x_h(verged) == pytest.approx([np.sin(0.15), -np.sin(0.15)], abs=1e-6)

    both = settle(model, {"eyes_version_motor": 0.1, "eyes_vergence_motor": 0.2})
    assert both.qpos[left] == pytest.approx(0.1 + 0.2 / 2, abs=1e-6)
    assert both.qpos[right] == pytest.approx(0.2 / 2 - 0.1, abs=1e-6)


def test_design_is_the_icub_2_kinematics_and_cameras_cited_in_the_file() -> None:
    designed = design(ICUB)
    assert designed.baseline_m == pytest.approx(0.068, abs=1e-12)
    assert designed.neck.order == "pitch_yaw"
    assert designed.neck.forward_m == pytest.approx(0.0509, abs=1e-12)
    assert designed.neck_d1_m == pytest.approx(0.0095, abs=1e-12)
    assert designed.neck_a2_m == pytest.approx(0.08205, abs=1e-12)
    for camera in designed.cameras:
        assert (camera.width, camera.height) == (320, 240)
        assert (camera.fx_px, camera.fy_px) == pytest.approx((257.34, 257.34), abs=1e-4)
        assert (camera.cx_px, camera.cy_px) == (159.5, 119.5)


def test_a_preset_takes_the_icubs_cameras_and_keeps_its_lens_and_tolerances() -> None:
    realistic = preset("realistic")
    moved = on_head(realistic, ICUB)
    for cam, before in zip(moved.cameras, realistic.cameras, strict=True):
        assert (cam.width, cam.height, cam.cx, cam.cy) == (320, 240, 159.5, 119.5)
        assert cam.kx == pytest.approx(257.34, abs=1e-4)
        assert (cam.k1, cam.nodal_offset_m, cam.side_offset_m) == (
            before.k1,
            before.nodal_offset_m,
            before.side_offset_m,
        )
    # The lengths move by the preset's departure from the paper's design.
    assert moved.baseline_m - 0.068 == pytest.approx(realistic.baseline_m - 0.150, abs=1e-12)
    assert moved.belief is not None and moved.belief.baseline_m == pytest.approx(0.068)


@pytest.mark.parametrize("mode", ["kinematic", "physics"])
def test_h10_is_where_mujoco_puts_h_and_version_vergence_reach_each_eye(mode: str) -> None:
    settings = on_head(HeadSettings(), ICUB)
    designed = design(ICUB)
    with HeadSim(settings=settings, settle_mode=mode) as sim:
        assert sim.motors == ("neck_yaw", "neck_pitch", "eye", "eye2")
        rng = np.random.default_rng(5)
        for yaw, pitch, left, right in rng.uniform((-0.4, -0.4, -0.1, -0.05), 0.4, (4, 4)):
            result = sim.move(neck_yaw=yaw, neck_pitch=pitch, eye=left, eye2=right)
            assert result.max_error_rad < 1e-4
            truth = sim.true_joint_angles()
            assert (truth["head:l_eye_pan"], truth["head:r_eye_pan"]) == pytest.approx(
                (left, right), abs=1e-4
            )
            expected = neck_of(ICUB).world_from_head(
                truth["head:neck_yaw"],
                truth["head:neck_pitch"],
                designed.neck_d1_m,
                designed.neck_a2_m,
            )
            # Physics holds the roll to within ~1e-7 rad of zero, not exactly.
            np.testing.assert_allclose(
                sim.world_from_head(), expected, atol=1e-9 if mode == "kinematic" else 1e-6
            )
            # The roll and the tilt are held at zero.
            for held in ("head:neck_roll", "head:eyes_tilt"):
                assert abs(sim.data.qpos[sim.model.joint(held).qposadr[0]]) < 1e-6
            if mode == "physics":
                version, vergence = (
                    sim.data.ctrl[sim.model.actuator(f"head:{n}").id]
                    for n in ("eyes_version_motor", "eyes_vergence_motor")
                )
                assert (version, vergence) == pytest.approx(((left - right) / 2, left + right))


def test_version_and_vergence_must_be_the_pans_combinations() -> None:
    swapped = replace(
        ICUB,
        mapping=replace(ICUB.mapping, version="eyes_vergence_motor", vergence="eyes_version_motor"),
    )
    with pytest.raises(
        heads.HeadError,
        match=r"head\.mapping\.version: actuator 'eyes_vergence_motor' moves the pans by \[1\.0, 1\.0\]",
    ):
        design(swapped)
    with pytest.raises(heads.HeadError, match=r"head\.mapping\.vergence: is not given"):
        replace(ICUB.mapping, vergence=None)
    with pytest.raises(heads.HeadError, match=r"head\.mapping\.version: is given without"):
        replace(ICUB.mapping, eyes="independent")
    missing = replace(ICUB, mapping=replace(ICUB.mapping, neck_roll="neck_twist"))
    with pytest.raises(
        heads.HeadError, match=r"head\.mapping\.neck_roll: the model has no joint 'neck_twist'"
    ):
        design(missing)


def test_the_eyes_cannot_diverge_beyond_the_vergence_actuators_range() -> None:
    with HeadSim(settings=on_head(HeadSettings(), ICUB)) as sim:
        low, high = sim.joint_range("eye")  # the counter-yaw's: half the vergence's range
        assert (low, high) == pytest.approx((-0.3490659 / 2, 0.8726646), abs=1e-7)
        with pytest.raises(JointLimitError, match=r"outside its range \[-0\.1745"):
            sim.command(eye=-0.2)
        with pytest.raises(JointLimitError, match=r"vergence left \+ right of -0\.400000 rad"):
            sim.command(eye=0.0, eye2=-0.4)
        sim.command(eye=low)
