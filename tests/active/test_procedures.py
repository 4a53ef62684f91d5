"""The paper's procedures end to end with real rendering (small scenes, few points)."""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np
import pytest
from scipy.optimize import brentq

from headsim.active.procedures import (
    CalibrationError,
    HeadKnowledge,
    Model2Config,
    body_target,
    calibrate_head,
    calibration_layout,
    measure_chessboard,
    measure_model1,
    measure_model2,
    relative_positioning,
    seen_by_both,
    track_moving_target,
)
from headsim.active.search import FailureCause
from headsim.active.servo import EyeServo, NeckServo
from headsim.sim import names
from headsim.sim.settings import CameraSettings, HeadSettings, paper_head
from headsim.sim.simulator import HeadSim
from headsim.vision.detect import find_cross_point, find_marker

RED = body_target("marker_red", partial(find_marker, colour="red"))
BALL = body_target(names.CALIBRATION_BALL, partial(find_marker, colour="yellow"))


def _place_in_head(sim: HeadSim, body: str, p_head) -> None:
    sim.set_body_pose(body, sim.transform_points(np.asarray(p_head, float), "head", "world")[0])


def test_model2_measures_ideal_targets_within_a_fraction_of_a_percent() -> None:
    with HeadSim("default") as sim:
        servo = EyeServo(sim)
        renders = []
        for p_head in ([0.03, -0.02, 0.4], [-0.1, 0.05, 0.9], [0.12, 0.08, 1.4]):
            _place_in_head(sim, "marker_red", p_head)
            m = measure_model2(sim, servo, RED)
            assert m.ok, m.status
            np.testing.assert_allclose(m.truth_head_m, p_head, atol=1e-12)
            assert m.error_pct_of_depth < 0.3
            np.testing.assert_allclose(m.estimate_world_m, m.truth_world_m, atol=0.004 * m.depth_m)
            assert max(abs(r) for r in m.servo_residual_px) <= 0.11
            # The covariance is a real one: symmetric, positive, depth the least sure.
            cov = m.covariance_head_m2
            np.testing.assert_allclose(cov, cov.T, atol=1e-15)
            assert np.all(np.linalg.eigvalsh(cov) > 0) and cov[2, 2] == cov.diagonal().max()
            renders.append(m.renders)
        assert np.mean(renders[1:]) <= 9  # the servo gains carry over after the first point


def test_near_midline_target_uses_the_remedy_image() -> None:
    with HeadSim("default") as sim:
        _place_in_head(sim, "marker_red", [0.0, 0.06, 0.8])
        m = measure_model2(sim, EyeServo(sim), RED)
        assert m.ok
        # The y images were retaken away from the fixations ...
        assert m.details["gamma1_rad"] != pytest.approx(m.details["alpha2_rad"], abs=1e-3)
        # ... so y is measured, not 0/0.
        assert abs(m.error_head_m[1]) < 0.002 * m.depth_m
        without = measure_model2(sim, EyeServo(sim), RED, config=Model2Config(midline_px=0.0))
        assert not without.ok or abs(without.error_head_m[1]) > abs(m.error_head_m[1])


def test_a_target_out_of_view_fails_cleanly() -> None:
    with HeadSim("default") as sim:
        sim.set_body_pose("marker_red", [0.0, -1.0, 0.2])
        m = measure_model2(sim, EyeServo(sim), RED)
        assert m.failure is not None and m.failure.cause is FailureCause.LOST
        assert (m.failure.camera, m.failure.stage) == (1, "step 1")
        assert m.detail.startswith("Ca1 at step 1: target lost")
        assert np.all(np.isnan(m.estimate_head_m))
        assert np.all(np.isfinite(m.truth_head_m))


def test_calibration_recovers_effective_initial_directions_and_corrects_measurements() -> None:
    cams = (
        CameraSettings(mount_yaw_rad=0.03, cx=300.0),
        CameraSettings(mount_yaw_rad=-0.02, cy=250.0),
    )
    with HeadSim("default", HeadSettings(cameras=cams)) as sim:
        servo = EyeServo(sim)
        rng = np.random.default_rng(4)
        run = calibrate_head(
            sim, servo, BALL, names.CALIBRATION_BALL, calibration_layout(sim, rng, 24)
        )
        assert run.samples >= 22  # a target or two may fall out of one camera's view
        # The ball is parked again where it was, not left in front of other targets.
        np.testing.assert_allclose(sim.position(names.CALIBRATION_BALL), [0.0, 0.5, -1.0])
        assert np.abs(run.alpha_e_error).max() < 5e-4
        truth = np.array(run.truth_alpha_e)
        assert np.all(np.abs(truth) >= 0.02)  # there was something to find
        v0 = run.vertical[1].v0
        assert v0 == pytest.approx(250.0, abs=1.5)
        _place_in_head(sim, "marker_red", [0.05, 0.02, 0.7])
        before = measure_model2(sim, servo, RED)
        after = measure_model2(sim, servo, RED, run.knowledge)
        assert after.error_pct_of_depth < 0.3
        assert before.error_pct_of_depth > 3 * after.error_pct_of_depth


def test_calibration_fixates_a_position_on_the_midline_with_the_near_midline_remedy() -> None:
    with HeadSim("default", paper_head()) as sim:
        e1, e2 = (sim.effective_initial_direction(c) for c in (1, 2))
        half, z = sim.settings.baseline_m / 2, 0.4
        # Where both eyes fixate at the same angle: each camera's y image then
        # shows P on its goal column (NO_Y), unless taken at another eye angle.
        x = brentq(lambda x: np.arctan2(x + half, z) - e1 - np.arctan2(half - x, z) + e2, -0.2, 0.2)
        layout = np.array([[x, 0.01, z], [-0.05, -0.02, 0.3], [0.06, 0.03, 0.5], [0.0, 0.0, 0.35]])
        world = sim.transform_points(layout, "head", "world")
        sim.set_body_pose(names.CALIBRATION_BALL, world[0])
        plain = measure_model2(sim, EyeServo(sim), BALL, config=Model2Config(midline_px=0.0))
        assert plain.failure is not None and plain.failure.cause is FailureCause.ESTIMATOR
        run = calibrate_head(sim, EyeServo(sim), BALL, names.CALIBRATION_BALL, world)
    assert run.outcomes == (None, None, None, None) and run.samples == 4
    assert np.abs(run.alpha_e_error).max() < 1e-3


def test_calibration_with_too_few_visible_targets_says_so() -> None:
    with (
        HeadSim("default") as sim,
        pytest.raises(
            CalibrationError,
            match=r"too few positions seen: 0 of 2 fixated .* because 2 Ca1 at step 1: target lost",
        ),
    ):
        calibrate_head(
            sim, EyeServo(sim), BALL, names.CALIBRATION_BALL, np.array([[0, -1, 0.2]] * 2)
        )


def test_chessboard_squares_come_out_30_mm() -> None:
    with HeadSim("chessboard") as sim:
        sim.set_body_pose(names.CHESSBOARD, [-0.105, 0.8, 0.285])
        # A 3 x 2 block of corners: 2 widths per row, 3 heights.
        run = measure_chessboard(sim, EyeServo(sim), corners=[9, 10, 11, 17, 18, 19])
        assert run.measured == 6
        assert len(run.widths_m) == 4 and len(run.heights_m) == 3
        np.testing.assert_allclose(run.true_widths_m, 0.03, atol=1e-9)
        np.testing.assert_allclose(run.widths_m, 0.03, atol=0.0005)
        np.testing.assert_allclose(run.heights_m, 0.03, atol=0.0005)
        assert {m.name for m in run.measurements} == {
            "corner_1_1",
            "corner_2_1",
            "corner_3_1",
            "corner_1_2",
            "corner_2_2",
            "corner_3_2",
        }


def test_relative_positioning_places_every_object_in_its_true_area() -> None:
    with HeadSim("blocks") as sim:
        run = relative_positioning(
            sim,
            EyeServo(sim),
            body_target(names.BLOCKS, find_cross_point),
            names.RELATIVE_OBJECT_COLOURS,
        )
        assert run.reference.ok
        assert run.missing == ()
        assert run.comparison is not None and run.comparison.n_disagree_outside == 0
        for name in names.RELATIVE_OBJECTS:
            assert run.areas[name] == run.true_areas[name] != 0
        assert len(set(run.areas.values())) >= 3  # the layout spans several areas


def test_model1_fixates_with_the_neck_and_places_the_point_in_the_world() -> None:
    with HeadSim("default") as sim:
        sim.set_body_pose("marker_red", [0.15, 0.7, 0.35])
        m = measure_model1(sim, NeckServo(sim), RED)
        assert m.ok, m.status
        assert abs(m.details["neck_yaw_rad"]) > 0.1 and m.details["neck_pitch_rad"] > 0.1
        # Fixated on the bisector, in the plane of the optical axes.
        assert np.linalg.norm(m.truth_head_m[:2]) < 0.003
        assert m.error_pct_of_depth < 0.5
        np.testing.assert_allclose(m.estimate_world_m, m.truth_world_m, atol=0.005 * m.depth_m)


def test_tracking_follows_a_moving_target_with_fewer_renders_after_the_first() -> None:
    with HeadSim("default", replace(HeadSettings(), seed=1)) as sim:

        def path(t: float) -> np.ndarray:
            return np.array([0.1 * np.sin(t), 0.8, 0.25 + 0.05 * t])

        run = track_moving_target(sim, NeckServo(sim), RED, "marker_red", path, [0.0, 0.3, 0.6])
        assert all(m.ok for m in run.measurements)
        assert np.all(run.errors_world_m < 0.006)
        renders = [m.renders for m in run.measurements]
        assert max(renders[1:]) < renders[0]


def test_tracking_searches_around_its_last_fixation_for_a_target_that_left_both_views() -> None:
    # Twice the focal length: the view at 0.8 m is about +-0.2 m wide, and the
    # target moves 0.25 m between fixations, out of both views and out of the
    # start pose's view too (the old fallback).
    base = replace(HeadSettings(), seed=1)
    cams = tuple(replace(c, kx=c.kx * 2, ky=c.ky * 2) for c in base.cameras)
    with HeadSim("default", replace(base, cameras=cams)) as sim:  # type: ignore[arg-type]

        def path(t: float) -> np.ndarray:
            return np.array([0.25 * t, 0.8, 0.3])

        assert not seen_by_both(sim, path(1.0)[None], 0.01)[0]  # not from the start pose
        servo = NeckServo(sim)
        run = track_moving_target(sim, servo, RED, "marker_red", path, [0.0, 1.0, 2.0, 2.6])
    assert all(m.ok for m in run.measurements), [m.status for m in run.measurements]
    searched = [m.search_renders for m in run.measurements]
    assert searched[0] == 0 and searched[1] > 0
    # The first look (2 renders) and at most 3 poses of 2 renders each.
    assert max(searched) <= 8
    assert all(m.error_pct_of_depth < 0.2 for m in run.measurements)


def test_paper_cameras_after_calibration_measure_within_the_papers_accuracy() -> None:
    settings = paper_head()
    with HeadSim("default", settings) as sim:
        servo = EyeServo(sim)
        run = calibrate_head(
            sim,
            servo,
            BALL,
            names.CALIBRATION_BALL,
            calibration_layout(sim, np.random.default_rng(0), 30),
        )
        assert np.abs(run.alpha_e_error).max() < 4e-4
        for p_head in ([0.04, 0.01, 0.6], [-0.06, -0.02, 1.0]):
            _place_in_head(sim, "marker_red", p_head)
            m = measure_model2(sim, servo, RED, run.knowledge)
            assert m.ok
            assert abs(m.error_head_m[0]) < 0.003 * m.depth_m
            assert abs(m.error_head_m[2]) < 0.003 * m.depth_m
            assert abs(m.error_head_m[1]) < 0.003 * m.depth_m  # with the extended calibration
            plain = measure_model2(sim, servo, RED, HeadKnowledge(alpha_e=run.knowledge.alpha_e))
            assert abs(plain.error_head_m[1]) > abs(m.error_head_m[1])


def test_a_target_out_of_view_where_the_eyes_are_is_found_straight_ahead() -> None:
    with HeadSim("default") as sim:
        sim.move(eye=0.6)  # converged on something near: the new target is out of Ca1's view
        _place_in_head(sim, "marker_red", [-0.1, 0.0, 0.9])
        assert not find_marker(sim.render(1), "red").found
        m = measure_model2(sim, EyeServo(sim), RED)
        assert m.ok, m.status
        assert m.error_pct_of_depth < 0.3
