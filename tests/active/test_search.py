"""Search and re-acquisition of lost targets, on rendered images."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from headsim.active.calibration import calibrate_head
from headsim.active.eye_servo import EyeServo
from headsim.active.measurement import HeadKnowledge, body_target
from headsim.active.model1 import measure_model1
from headsim.active.model2 import measure_model2
from headsim.active.neck_servo import NeckServo
from headsim.active.placement import calibration_layout
from headsim.active.search import neck_search_poses
from headsim.geometry.kinematics import head_to_world
from headsim.scenario.reach import ReachHead, model2_refusal, reach_refusal
from headsim.sim import names
from headsim.sim.settings import HeadSettings, paper_head
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))


BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))


def _zoomed(zoom: float) -> HeadSettings:
    base = paper_head()
    cams = tuple(replace(c, kx=c.kx * zoom, ky=c.ky * zoom) for c in base.cameras)
    return replace(base, cameras=cams)  # type: ignore[arg-type]


def _place_in_head(sim: HeadSim, body: str, p_head: list[float]) -> np.ndarray:
    p_world = sim.transform_points(np.asarray(p_head, float), "head", "world")[0]
    sim.set_body_pose(body, p_world)
    return p_world


def test_model2_finds_ca2_again_when_ca1_fixation_turns_it_away() -> None:
    # 1.3x the paper's focal length and a target far right: once Ca1 fixates it,
    # the coupled eyes have turned Ca2 past it (the failure).
    settings = _zoomed(1.3)
    p_head = [0.12, 0.0, 0.6]
    with HeadSim("default", settings) as sim:
        p_world = _place_in_head(sim, "marker_red", p_head)
        assert model2_refusal(ReachHead.of(settings), p_world, "target", 0.004) is None
        servo = EyeServo(sim)
        # A calibrated head (the initial directions Sec. V would find).
        known = HeadKnowledge(
            alpha_e=(sim.effective_initial_direction(1), sim.effective_initial_direction(2))
        )
        m = measure_model2(sim, servo, RED, known)
        assert m.ok, m.status
        assert m.search_renders == 1  # one full frame at the first pose tried
        # Ca2's y image was taken where it saw the target, not at Ca1's fixation.
        assert m.details["gamma2_rad"] != pytest.approx(m.details["step1_encoder_rad"])
        # x and z to 0.2 % of depth (y needs v0, which this head was not told).
        assert np.linalg.norm(m.error_head_m[[0, 2]]) < 0.002 * m.depth_m
        # Without the search it would have failed: Ca2 does not see P at alpha1.
        sim.command_eye_steps(round(m.details["step1_encoder_rad"] / 2.454369e-4))
        sim.settle()
        assert not RED.detector(sim.render(2)).found


def test_model1_fixates_a_new_target_from_the_start_pose_and_searches_for_a_tracked_one() -> None:
    with HeadSim("default", paper_head()) as sim:
        neck = NeckServo(sim)
        resolution = sim.settings.encoder_resolution_rad
        _place_in_head(sim, "marker_red", [0.15, 0.0, 0.7])
        first = measure_model1(sim, neck, RED)
        assert first.ok and first.search_renders == 0
        # The next target is on the left (placed in H at the start pose), and the
        # last task left the neck turned far right.
        sim.command(neck_yaw=0.0, neck_pitch=0.0, eye=0.0)
        sim.settle()
        _place_in_head(sim, "marker_red", [-0.15, 0.05, 0.7])
        sim.command(neck_yaw=-0.6)
        sim.settle()
        known = HeadKnowledge(
            alpha_e=(sim.effective_initial_direction(1), sim.effective_initial_direction(2))
        )
        renders = sim.render_count
        second = measure_model1(sim, neck, RED, known)
        # A new target: fixated from the start pose, no look where the neck was left.
        assert second.ok, second.status
        assert second.search_renders == 0 and second.renders == sim.render_count - renders
        # A tracked target last fixated with the neck far right, and gone from there:
        # the head looks around that fixation, then from the start pose.
        last = (round(-0.6 / resolution), 0, 0)
        sim.command(neck_yaw=-0.6, neck_pitch=0.0, eye=0.0)
        sim.settle()
        tracked = measure_model1(sim, neck, RED, known, last_seen=[last])
        assert tracked.ok, tracked.status
        # The failed look (camera 1) and every pose of the search were rendered.
        assert tracked.search_renders >= 2
        assert tracked.renders > second.renders
        # As good as a fixation that needed no search (the paper head's v0 and
        # offsets limit both alike).
        assert tracked.error_pct_of_depth == pytest.approx(second.error_pct_of_depth, abs=0.05)


def test_the_eye_servo_retreats_to_the_last_pose_that_saw_the_target() -> None:
    # A carried gain 2.5x too small makes the first move overshoot past the view
    # (1.3x focal: about +-0.29 rad); the servo undoes it, retries shorter, converges.
    with HeadSim("default", _zoomed(1.3)) as sim:
        _place_in_head(sim, "marker_red", [0.12, 0.0, 0.6])
        servo = EyeServo(sim)
        reference = servo.run(1, RED.detector)
        assert reference.converged and reference.retreats == 0
        sim.command_eye_steps(0)
        sim.settle()
        servo.gains[1] = reference.gain_px_per_step / 2.5
        result = servo.run(1, RED.detector)
        assert result.converged
        assert result.retreats >= 1
        assert abs(result.steps - reference.steps) <= 1


def test_neck_search_looks_first_where_the_last_two_fixations_predict_the_target() -> None:
    with HeadSim("default", HeadSettings()) as sim:
        servo = NeckServo(sim)
        assert neck_search_poses(servo, [(0, 0, 0)], (640, 480)) == []  # no gains learnt yet
        # px per step: yaw moves both u by 2, pitch moves v by 2 (a learnt Jacobian).
        servo.jacobian = np.array([[2.0, 0.0, 1.0], [2.0, 0.0, -1.0], [0.0, 2.0, 0.0]])
        last = [(0, 0, 40), (100, 20, 40)]
        poses = neck_search_poses(servo, last, (640, 480))
    assert poses[0] == (200, 40, 40)  # constant velocity in steps
    # The rest: a grid around the last fixation in strides of 0.7 of the view.
    stride = (int(0.7 * 640 / 2), int(0.7 * 480 / 2))
    assert (100 + stride[0], 20, 40) in poses and (100, 20 - stride[1], 40) in poses
    assert (100, 20, 40) not in poses and len(poses) == len(set(poses))
    yaw_range, pitch_range, _ = servo.step_ranges
    assert all(yaw_range[0] <= p[0] <= yaw_range[1] for p in poses)
    assert all(pitch_range[0] <= p[1] <= pitch_range[1] for p in poses)


def test_a_calibration_layout_with_the_eyes_turned_in_spreads_wider_and_is_all_fixated() -> None:
    # Twice the paper's focal length: from the start pose both cameras share
    # only a narrow view of the near range that separates the two offsets.
    base = paper_head()
    cams = tuple(replace(c, kx=c.kx * 2, ky=c.ky * 2) for c in base.cameras)
    with HeadSim("default", replace(base, cameras=cams)) as sim:  # type: ignore[arg-type]
        narrow = calibration_layout(sim.stereo_views(), np.random.default_rng(5), 16)
        wide = calibration_layout(sim.stereo_views((0.1, 0.2, 0.3)), np.random.default_rng(5), 16)
        assert sim.stereo_view().sees_whole(wide[:1], 0.008)[0]  # the first one from the start pose
        assert not sim.stereo_view().sees_whole(wide, 0.008).all()  # others need the eyes turned in

        def spread(p: np.ndarray) -> float:
            p_head = sim.transform_points(p, "world", "head")
            return float(np.std(p_head[:, 0] / p_head[:, 2]))

        assert spread(wide) > 2 * spread(narrow)
        run = calibrate_head(sim, EyeServo(sim), BALL, names.CALIBRATION_BALL, wide)
    assert run.outcomes == (None,) * 16
    assert np.abs(run.alpha_e_error).max() < 5e-4


def test_reach_refusal_is_the_scenario_check_for_both_models() -> None:
    settings = paper_head()
    ahead = head_to_world(
        np.array([0.0, 0.0, 0.8]), 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m
    )
    edge = head_to_world(
        np.array([0.6, 0.0, 0.8]), 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m
    )
    aside = head_to_world(
        np.array([0.8, 0.0, 0.8]), 0.0, 0.0, settings.neck_d1_m, settings.neck_a2_m
    )
    assert reach_refusal(settings, ahead) is None
    # Outside the start pose's view, but both eyes (and the neck) can fixate it: accepted.
    assert not ReachHead.of(settings).in_start_view(edge)
    assert reach_refusal(settings, edge) is None
    refusal = reach_refusal(settings, aside, "ball")
    assert refusal is not None and refusal.message.startswith("ball at ")
    assert refusal.code == "eye_range"
    assert refusal == model2_refusal(ReachHead.of(settings), aside, "ball")
