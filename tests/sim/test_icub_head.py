"""The shipped iCub head as the simulator runs it, with real MuJoCo: its design read from
models/icub.xml, its neck (H10) against MuJoCo's own kinematics, its version and vergence
actuators, and its mapping's errors."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.sim import heads
from headsim.sim.joints import JointLimitError
from headsim.sim.model import design, neck_of, on_head
from headsim.sim.settings import HeadSettings, preset
from headsim.sim.simulator import HeadSim

ICUB = heads.shipped("icub")


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
