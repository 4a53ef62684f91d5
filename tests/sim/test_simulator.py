"""The simulator wrapper against MuJoCo: frames, coupling, encoders, settling."""

from __future__ import annotations

import math

import numpy as np
import pytest

from headsim.sim import names
from headsim.sim.joints import JointLimitError, SettleOutcome
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head, preset
from headsim.sim.simulator import HeadSim, start_views


@pytest.fixture
def sim():
    with HeadSim("default") as s:
        yield s


def test_head_frame_matches_the_documented_axes_at_home(sim: HeadSim) -> None:
    world_from_head = sim.world_from_head()
    np.testing.assert_allclose(world_from_head[:3, 0], [1, 0, 0], atol=1e-12)  # x right
    np.testing.assert_allclose(world_from_head[:3, 1], [0, 0, -1], atol=1e-12)  # y down
    np.testing.assert_allclose(world_from_head[:3, 2], [0, 1, 0], atol=1e-12)  # z forward
    s = sim.settings
    np.testing.assert_allclose(
        world_from_head[:3, 3], [0, 0, s.neck_d1_m + s.neck_a2_m], atol=1e-12
    )


def test_cameras_sit_on_the_baseline_and_turn_inward_with_the_eye_angle() -> None:
    settings = HeadSettings(baseline_m=0.2)
    with HeadSim("default", settings) as sim:
        alpha = 0.123
        sim.move(eye=alpha, neck_yaw=0.3, neck_pitch=-0.2)
        head_from_cam1 = sim.head_from_camera(1)
        head_from_cam2 = sim.head_from_camera(2)
        np.testing.assert_allclose(head_from_cam1[:3, 3], [-0.1, 0, 0], atol=1e-12)
        np.testing.assert_allclose(head_from_cam2[:3, 3], [0.1, 0, 0], atol=1e-12)
        # Optical axes: Ca1 towards +x, Ca2 towards -x by the same angle.
        np.testing.assert_allclose(
            head_from_cam1[:3, 2], [math.sin(alpha), 0, math.cos(alpha)], atol=1e-12
        )
        np.testing.assert_allclose(
            head_from_cam2[:3, 2], [-math.sin(alpha), 0, math.cos(alpha)], atol=1e-12
        )
        # Image y stays H's y (down).
        np.testing.assert_allclose(head_from_cam1[:3, 1], [0, 1, 0], atol=1e-12)


def test_one_motor_turns_both_eyes_equally_and_oppositely_under_physics() -> None:
    with HeadSim("default", settle_mode="physics") as sim:
        for target in (0.05, -0.02, 0.2):
            result = sim.move(eye=target)
            assert result.outcome is SettleOutcome.SETTLED
            angles = sim.true_joint_angles()
            eye1, eye2 = angles[names.EYE_JOINTS[0]], angles[names.EYE_JOINTS[1]]
            assert abs(eye1 - target) < 1e-6
            assert abs(eye2 - eye1) < 1e-6  # coupled: equal joint angles ...
            axis1, axis2 = sim.head_from_camera(1)[:3, 2], sim.head_from_camera(2)[:3, 2]
            assert abs(axis1[0] + axis2[0]) < 1e-6  # ... that turn the axes oppositely
            assert axis1[0] * target > 0


def test_encoder_readings_are_whole_multiples_of_the_resolution(sim: HeadSim, rng) -> None:
    resolution = sim.settings.encoder_resolution_rad
    for angle in rng.uniform(-0.3, 0.3, size=50):
        sim.move(eye=float(angle))
        reading = sim.eye_encoder()
        steps = reading / resolution
        assert abs(steps - round(steps)) < 1e-9
        assert abs(reading - angle) <= resolution / 2 + 1e-15
        assert sim.eye_encoder_steps() == round(steps)
        for neck in sim.neck_encoders():
            assert abs(neck / resolution - round(neck / resolution)) < 1e-9


def test_command_in_steps_reads_back_exactly(sim: HeadSim) -> None:
    sim.command_eye_steps(417)
    sim.settle()
    assert sim.eye_encoder_steps() == 417


def test_physics_settle_reports_a_timeout() -> None:
    with HeadSim("default", settle_mode="physics", max_settle_steps=3) as sim:
        result = sim.move(neck_yaw=0.5)
        assert result.outcome is SettleOutcome.TIMEOUT
        assert result.steps == 3
        assert result.max_error_rad > 0.1


def test_commands_outside_the_joint_range_are_refused(sim: HeadSim) -> None:
    _, high = sim.joint_range(names.EYE_MOTOR_JOINT)
    with pytest.raises(JointLimitError, match=r"eye1_yaw.*outside its range"):
        sim.command(eye=high + 0.01)
    with pytest.raises(JointLimitError, match="neck_pitch"):
        sim.command(neck_pitch=float("nan"))


def test_positions_in_frames_are_consistent(sim: HeadSim) -> None:
    sim.move(eye=0.07, neck_yaw=-0.1, neck_pitch=0.15)
    p_world = sim.position("marker_red")
    p_head = sim.position("marker_red", "head")
    p_cam = sim.position("marker_red", "cam2")
    np.testing.assert_allclose(
        sim.world_from_head() @ np.append(p_head, 1), np.append(p_world, 1), atol=1e-12
    )
    np.testing.assert_allclose(
        sim.world_from_camera(2) @ np.append(p_cam, 1), np.append(p_world, 1), atol=1e-12
    )
    assert p_cam[2] > 0  # in front of the camera
    new = np.array([0.05, 0.8, 0.3])
    sim.set_body_pose("marker_red", new)
    np.testing.assert_allclose(sim.position("marker_red"), new, atol=1e-12)


def test_effective_initial_direction_adds_the_centre_ray_to_the_mount() -> None:
    cam1 = CameraSettings(cx=300.0, mount_yaw_rad=0.03)
    cam2 = CameraSettings(cx=340.0, mount_yaw_rad=-0.02)
    with HeadSim("default", HeadSettings(cameras=(cam1, cam2))) as sim:
        # Ca1 inward is +x: a centre right of the principal point adds; Ca2 the opposite.
        expected1 = 0.03 + math.atan((319.5 - 300.0) / cam1.kx)
        expected2 = -0.02 - math.atan((319.5 - 340.0) / cam2.kx)
        assert sim.effective_initial_direction(1) == pytest.approx(expected1, abs=1e-12)
        assert sim.effective_initial_direction(2) == pytest.approx(expected2, abs=1e-12)


def test_paper_preset_reproduces_the_paper_initial_directions() -> None:
    with HeadSim("default", paper_head()) as sim:
        assert sim.effective_initial_direction(1) == pytest.approx(0.0578, abs=1e-12)
        assert sim.effective_initial_direction(2) == pytest.approx(-0.0254, abs=1e-12)
        np.testing.assert_allclose(
            sim.camera_matrix(1)[:2, :], [[834.83, 0, 303.8], [0, 815.42, 306.3]]
        )
        assert sim.dist_coeffs(2)[0] == pytest.approx(-0.30938)


def test_unknown_names_are_refused_with_the_allowed_values(sim: HeadSim) -> None:
    with pytest.raises(ValueError, match="unknown camera 'cam3'; allowed: 1, 2, cam1, cam2"):
        sim.render("cam3")
    with pytest.raises(ValueError, match="unknown frame"):
        sim.position("marker_red", "torso")
    with pytest.raises(ValueError, match="no body or site named"):
        sim.position("nothing")
    with pytest.raises(ValueError, match="not a movable"):
        sim.set_body_pose(names.HEAD, [0, 0, 0])


def test_eq1_matches_mujocos_head_frame_for_1000_random_neck_angles(rng) -> None:
    from headsim.geometry.kinematics import world_from_head

    settings = HeadSettings(neck_d1_m=0.14, neck_a2_m=0.07)
    with HeadSim("default", settings) as sim:
        low_yaw, high_yaw = sim.joint_range(names.NECK_YAW)
        low_pitch, high_pitch = sim.joint_range(names.NECK_PITCH)
        worst = 0.0
        for yaw, pitch in zip(
            rng.uniform(low_yaw, high_yaw, 1000),
            rng.uniform(low_pitch, high_pitch, 1000),
            strict=True,
        ):
            sim.move(neck_yaw=float(yaw), neck_pitch=float(pitch), eye=0.0)
            expected = world_from_head(yaw, pitch, settings.neck_d1_m, settings.neck_a2_m)
            worst = max(worst, float(np.abs(sim.world_from_head() - expected).max()))
        assert worst < 1e-9


def test_effective_initial_direction_agrees_with_the_forward_model() -> None:
    from headsim.geometry.camera_model import PinholeCamera
    from headsim.geometry.synthetic import effective_initial_direction

    settings = paper_head()
    with HeadSim("default", settings) as sim:
        for camera, cam in zip((1, 2), settings.cameras, strict=True):
            pinhole = PinholeCamera(
                cam.width, cam.height, cam.kx, cam.ky, *cam.principal, cam.k1, cam.k2
            )
            expected = effective_initial_direction(
                camera, cam.mount_yaw_rad, pinhole, cam.image_centre[0]
            )
            assert sim.effective_initial_direction(camera) == pytest.approx(expected, abs=1e-12)


def test_start_views_are_a_fresh_simulators_views_of_the_same_head() -> None:
    settings = preset("realistic")  # joint errors: the start pose is not the design's
    views = start_views(settings)
    with HeadSim("default", settings) as sim:
        (fresh,) = sim.stereo_views()
        sim.move(eye=0.1)
        (turned,) = sim.stereo_views()
    (view,) = views
    np.testing.assert_array_equal(view.world_from_head, fresh.world_from_head)
    for mine, theirs, moved in zip(
        view.camera_from_world, fresh.camera_from_world, turned.camera_from_world, strict=True
    ):
        np.testing.assert_array_equal(mine, theirs)
        assert not np.array_equal(mine, moved)
    assert view.cameras == fresh.cameras
