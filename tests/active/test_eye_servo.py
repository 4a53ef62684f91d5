"""The image-only eye servo with real rendering: convergence and every way it ends."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.eye_servo import EyeServo
from headsim.active.servo_types import ServoConfig, ServoOutcome
from headsim.sim.settings import CameraSettings, HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

RED = MarkerDetector("red")


MARKER = "marker_red"


# Focal length 0.5x-2x the default, principal point shifted up to 40 px:
# the servo is not told any of it.
UNTOLD_CAMERAS = {
    "half_focal": CameraSettings().with_zoom(0.5),
    "double_focal": CameraSettings().with_zoom(2.0),
    "principal_left_up": CameraSettings(cx=279.5, cy=199.5),
    "principal_right_down_zoomed": CameraSettings(cx=359.5, cy=279.5).with_zoom(1.5),
}


@pytest.mark.parametrize("variant", sorted(UNTOLD_CAMERAS))
def test_servo_centres_the_target_in_each_camera(variant: str, rng) -> None:
    camera = UNTOLD_CAMERAS[variant]
    with HeadSim("default", HeadSettings(cameras=(camera, camera))) as sim:
        servo = EyeServo(sim)
        for _ in range(3):
            sim.set_body_pose(
                MARKER,
                [rng.uniform(-0.1, 0.1), rng.uniform(0.35, 1.2), 0.21 + rng.uniform(-0.05, 0.05)],
            )
            for index in (1, 2):
                result = servo.run(index, RED)
                assert result.outcome is ServoOutcome.CONVERGED
                # As close as whole encoder steps allow: within half a step's image motion.
                step_px = abs(result.gain_px_per_step)
                assert abs(result.residual_px) <= max(0.1, 0.5 * step_px) + 0.03
                truth = sim.project(sim.position(MARKER), index)[0]
                assert abs(truth[0] - camera.image_centre[0]) <= 0.5 * step_px + 0.12
                assert result.steps == sim.eye_encoder_steps()


def test_gain_sign_is_learnt_per_camera_and_seeds_the_next_target(rng) -> None:
    with HeadSim("default") as sim:
        servo = EyeServo(sim)
        sim.set_body_pose(MARKER, [0.05, 0.7, 0.21])
        first = servo.run(1, RED)
        # Turning Ca1 inward moves the image left: negative gain, about -f * step.
        expected = -579.41 * sim.settings.encoder_resolution_rad
        assert first.gain_px_per_step == pytest.approx(expected, rel=0.05)
        second_camera = servo.run(2, RED)
        assert second_camera.gain_px_per_step == pytest.approx(-expected, rel=0.05)
        sim.set_body_pose(MARKER, [-0.04, 0.9, 0.25])
        seeded = servo.run(1, RED)
        assert seeded.converged
        assert seeded.renders < first.renders + 1  # no probe needed


def test_subpixel_step_interpolates_the_fixation(rng) -> None:
    with HeadSim("default") as sim:
        servo = EyeServo(sim)
        sim.set_body_pose(MARKER, [0.03, 0.8, 0.22])
        result = servo.run(1, RED)
        # The true eye angle that centres the marker, from the geometry.
        p_eye = sim.position(MARKER, "head") - np.array([-0.075, 0.0, 0.0])
        true_steps = np.arctan2(p_eye[0], p_eye[2]) / sim.settings.encoder_resolution_rad
        assert abs(result.subpixel_steps - true_steps) < 0.35
        assert abs(result.subpixel_steps - true_steps) <= abs(result.steps - true_steps) + 0.05


def test_lost_target_is_reported() -> None:
    with HeadSim("default") as sim:
        sim.set_body_pose(MARKER, [0.0, -1.0, 0.2])
        result = EyeServo(sim).run(1, RED)
        assert result.outcome is ServoOutcome.TARGET_LOST
        assert result.renders == 1
        assert np.isnan(result.residual_px)


def test_iteration_limit_is_reported() -> None:
    with HeadSim("default") as sim:
        sim.set_body_pose(MARKER, [0.15, 0.5, 0.21])
        result = EyeServo(sim, ServoConfig(max_iterations=2)).run(1, RED)
        assert result.outcome is ServoOutcome.ITERATION_LIMIT
        assert result.iterations == 2
        assert abs(result.residual_px) > 0.1


def test_joint_limit_is_reported() -> None:
    with HeadSim("default") as sim:
        sim.move(eye=-0.65)  # eyes far outward
        # A target Ca1 sees but could only centre by turning beyond -0.7 rad.
        p_cam1 = np.array([-0.35, 0.0, 1.0])
        sim.set_body_pose(MARKER, sim.transform_points(p_cam1, "cam1", "world")[0])
        result = EyeServo(sim).run(1, RED)
        assert result.outcome is ServoOutcome.JOINT_LIMIT
        low, _ = sim.joint_range("eye1_yaw")
        assert sim.eye_encoder() >= low


def _true_steps(sim: HeadSim) -> float:
    """Ca1's eye steps that centre the marker on the ideal head (scoring only)."""
    p_eye = sim.position(MARKER, "head") - np.array([-0.075, 0.0, 0.0])
    return float(np.arctan2(p_eye[0], p_eye[2]) / sim.settings.encoder_resolution_rad)


def test_fixation_is_averaged_over_one_pixel() -> None:
    places = [[0.03, 0.8, 0.22], [-0.06, 0.6, 0.19], [0.08, 1.1, 0.25], [0.0, 0.45, 0.2]]
    errors: dict[str, list[float]] = {"single": [], "averaged": []}
    with HeadSim("default") as sim:
        single = EyeServo(sim)
        averaging = EyeServo(sim, ServoConfig(average_fixation=True))
        for place in places:
            sim.set_body_pose(MARKER, place)
            sim.command_eye_steps(0)
            sim.settle()
            one = single.run(1, RED)
            assert one.fixation_samples == 1
            sim.command_eye_steps(0)
            sim.settle()
            result = averaging.run(1, RED)
            assert result.converged and one.converged
            gain = abs(result.gain_px_per_step)
            # One pixel's worth of whole steps, each a render unless the servo had
            # seen that step; the eye back at its final step.
            assert result.fixation_samples == round(1 / gain) >= 3
            extra = result.renders - one.renders
            assert 0 < extra <= result.fixation_samples
            assert sim.eye_encoder_steps() == result.steps == one.steps
            # Its images lie within one pixel of image motion around the crossing.
            near = [
                s for s, _, _ in result.seen if abs(s - result.subpixel_steps) * gain <= 0.5 + gain
            ]
            assert len(near) >= result.fixation_samples
            truth = _true_steps(sim)
            errors["single"].append(one.subpixel_steps - truth)
            errors["averaged"].append(result.subpixel_steps - truth)
    rms = {k: float(np.sqrt(np.mean(np.square(v)))) for k, v in errors.items()}
    assert rms["averaged"] < 0.7 * rms["single"], rms
