"""Each imperfection the head's settings offer moves a figure when it is on.

One test per imperfection that no other test would miss if the simulator
ignored it: the figure it moves, in the direction and by about the size the
geometry predicts.  Real MuJoCo renders and real detection; the expected
values come from the settings through explicit geometry, never from the
simulator's own model of the imperfection.
"""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, body_target, to_world
from headsim.active.model2 import measure_model2
from headsim.geometry.kinematics import head_to_world
from headsim.geometry.transforms import rotation_z
from headsim.sim import names
from headsim.sim.settings import CameraSettings, HeadBelief, HeadSettings, RenderFidelity
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector, find_marker

MARKER = "marker_red"
RED = body_target(MARKER, MarkerDetector("red"))


def test_a_mount_roll_turns_the_image_about_the_optical_axis() -> None:
    roll = 0.02
    target = [0.1, 0.5, 0.26]  # world: about 200 px right of and 60 px above the centre
    with HeadSim("default") as plain:
        plain.set_body_pose(MARKER, target)
        p_cam = plain.transform_points(np.array(target), "world", "cam1")[0]
        upright = np.array(find_marker(plain.render(1), "red").uv)
    rolled = CameraSettings(mount_roll_rad=roll)
    with HeadSim("default", HeadSettings(cameras=(rolled, CameraSettings()))) as sim:
        sim.set_body_pose(MARKER, target)
        seen = find_marker(sim.render(1), "red")
    # The camera turned by the roll about its z: the point turns the other way in its frame.
    expected = rolled.pinhole().project((rotation_z(roll).T @ p_cam)[None])[0]
    assert seen.found
    assert np.linalg.norm(np.array(seen.uv) - expected) < 0.15
    assert np.linalg.norm(expected - upright) > 3.0  # about roll x 200 px: 4 px


def test_multisampling_sharpens_the_marker_centroid() -> None:
    rng = np.random.default_rng(8)
    poses = [
        ([rng.uniform(-0.08, 0.08), rng.uniform(0.45, 0.9), 0.21 + rng.uniform(-0.06, 0.06)],
         float(rng.uniform(-0.04, 0.12)))
        for _ in range(12)
    ]  # fmt: skip
    floors = {}
    for offsamples in (0, 4):
        errors = []
        with HeadSim("default", HeadSettings(render=RenderFidelity(offsamples, 1))) as sim:
            for target, eye in poses:
                sim.set_body_pose(MARKER, target)
                sim.move(eye=eye)
                seen = find_marker(sim.render(1), "red")
                truth = sim.project(sim.position(MARKER), 1)[0]
                errors.append(float(np.linalg.norm(np.array(seen.uv) - truth)))
        floors[offsamples] = float(np.mean(errors))
    print(f"centroid error, mean of {len(poses)} poses: {floors} px")
    # One coverage sample per pixel puts each edge on the pixel grid; four, on a quarter of it.
    assert floors[0] > 1.5 * floors[4]


def test_a_baseline_wider_than_believed_scales_model_2s_estimate() -> None:
    true_d, believed_d = 0.153, 0.150
    settings = HeadSettings(baseline_m=true_d, belief=HeadBelief(baseline_m=believed_d))
    with HeadSim("default", settings) as sim:
        sim.set_body_pose(
            MARKER, sim.transform_points(np.array([0.02, 0.01, 0.5]), "head", "world")[0]
        )
        m = measure_model2(sim, EyeServo(sim), RED)
    assert m.ok
    # Rays from the believed eyes at the measured angles meet at the truth scaled about the
    # mid-baseline by D_believed / D_true: 2 % nearer, 10 mm at 0.5 m.
    np.testing.assert_allclose(m.estimate_head_m, m.truth_head_m * believed_d / true_d, atol=1e-3)
    assert m.error_head_m[2] < -0.008


def test_neck_lengths_apart_from_the_belief_move_the_world_estimate_by_their_difference() -> None:
    true_d1, true_a2 = 0.125, 0.088
    believed = HeadBelief(neck_d1_m=0.12, neck_a2_m=0.09)
    settings = HeadSettings(neck_d1_m=true_d1, neck_a2_m=true_a2, belief=believed)
    with HeadSim("default", settings) as sim:
        resolution = settings.encoder_resolution_rad
        yaw, pitch = round(0.2 / resolution) * resolution, round(0.15 / resolution) * resolution
        sim.move(neck_yaw=yaw, neck_pitch=pitch)
        p_head = np.array([0.02, 0.01, 0.5])
        truth = sim.transform_points(p_head, "head", "world")[0]
        estimate = to_world(sim, p_head)  # a measurement's estimate_world_m
    # The simulated neck is the true one (eq. 3 with its lengths); the estimate uses the belief's.
    np.testing.assert_allclose(
        truth, head_to_world(p_head, yaw, pitch, true_d1, true_a2), atol=1e-9
    )
    expected = head_to_world(p_head, yaw, pitch, 0.12, 0.09) - truth
    np.testing.assert_allclose(estimate - truth, expected, atol=1e-9)
    assert np.linalg.norm(expected) > 2.5e-3  # -5 mm on d1, +2 mm on a2 nearly along it: 3 mm


def test_each_camera_and_its_previews_get_the_cameras_own_noise() -> None:
    cameras = (CameraSettings(), CameraSettings(noise_std=4.0))
    with (
        HeadSim("default", HeadSettings(cameras=cameras, seed=7)) as sim,
        HeadSim("default") as plain,
    ):
        images = [sim.render(1), sim.render(2), sim.render_preview(2, 4)]
        clean = [plain.render(1), plain.render(2), plain.render_preview(2, 4)]
    np.testing.assert_array_equal(images[0], clean[0])  # Ca1 has none
    for image, reference in zip(images[1:], clean[1:], strict=True):  # Ca2's frames and previews
        reference = reference.astype(float)
        residual = (image - reference)[(reference > 20) & (reference < 235)]
        assert residual.size > 10_000
        assert abs(residual.std() - 4.0) < 0.2
        assert abs(residual.mean()) < 0.1


def test_the_eye_turns_one_encoder_resolution_a_step_and_model_2_reads_it_so() -> None:
    resolution = 1e-3  # four of the paper's steps: 0.58 px at the image centre
    with HeadSim("default", HeadSettings(encoder_resolution_rad=resolution)) as sim:
        sim.command_eye_steps(25)
        sim.settle()
        assert sim.eye_encoder_steps() == 25
        assert sim.true_joint_angles()[names.EYE_JOINTS[0]] == pytest.approx(
            25 * resolution, abs=1e-12
        )
        sim.set_body_pose(
            MARKER, sim.transform_points(np.array([0.02, 0.01, 0.5]), "head", "world")[0]
        )
        m = measure_model2(sim, EyeServo(sim), RED)
    assert m.ok
    # Each fixation angle within half a step: z^2 / D x resolution bounds the depth error.
    assert abs(m.error_head_m[2]) < 0.5**2 / 0.15 * resolution


def test_a_side_offset_the_head_believes_is_taken_into_model_2() -> None:
    side = 0.002  # Ca1's optical centre 2 mm along its x, off its yaw axis
    cams = (CameraSettings(side_offset_m=side), CameraSettings())
    with HeadSim("default", HeadSettings(cameras=cams)) as sim:
        sim.set_body_pose(
            MARKER, sim.transform_points(np.array([0.02, 0.01, 0.5]), "head", "world")[0]
        )
        servo = EyeServo(sim)
        unaware = measure_model2(sim, servo, RED, HeadKnowledge(belief=HeadBelief()))
        told = HeadKnowledge(belief=HeadBelief(side_offset_m=(side, 0.0)))
        aware = measure_model2(sim, servo, RED, told)
    assert unaware.ok and aware.ok
    # Unaware, Ca1's line of sight is 2 mm off: about s z / D = 6.7 mm of depth at 0.5 m.
    assert unaware.error_head_m[2] == pytest.approx(side * 0.5 / 0.15, rel=0.2)
    assert np.linalg.norm(aware.error_head_m) < 5e-4
