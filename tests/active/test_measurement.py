"""What a procedure works with and returns (active/measurement.py): knowledge, targets, results."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.failure import Failure, FailureCause
from headsim.active.measurement import (
    HeadKnowledge,
    body_target,
    estimated_measurement,
    failed_measurement,
    to_world,
)
from headsim.estimators.result import Flag, Method, PositionEstimate, Status
from headsim.sim.settings import HeadBelief
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector


@pytest.fixture(scope="module")
def sim():
    with HeadSim("default") as sim:
        sim.move(neck_yaw=0.1, neck_pitch=-0.05)
        yield sim


def test_knowledge_defaults_to_the_image_centre_and_the_believed_design(sim) -> None:
    knows = HeadKnowledge()
    assert knows.reference(sim, 1) == sim.camera_settings(1).image_centre
    told = HeadKnowledge(u0=(None, 330.5), v0=(250.0, None), los_offset_m=(0.001, -0.002))
    assert told.reference(sim, 1) == (sim.camera_settings(1).image_centre[0], 250.0)
    assert told.reference(sim, 2) == (330.5, sim.camera_settings(2).image_centre[1])
    assert knows.head_belief(sim) == sim.belief
    assert knows.line_of_sight_offsets(sim) == sim.belief.side_offset_m
    assert told.line_of_sight_offsets(sim) == (0.001, -0.002)
    belief = HeadBelief(baseline_m=0.2)
    assert HeadKnowledge(belief=belief).head_belief(sim) is belief


def test_to_world_undoes_the_neck_for_a_head_that_is_as_designed(sim) -> None:
    truth_world = sim.position("marker_red")
    truth_head = sim.transform_points(truth_world, "world", "head")[0]
    # The default head's belief is its truth; the neck's encoders read within a count.
    np.testing.assert_allclose(to_world(sim, truth_head), truth_world, atol=1e-4)
    shifted = HeadBelief(neck_d1_m=sim.belief.neck_d1_m + 0.01)
    moved = to_world(sim, truth_head, belief=shifted) - to_world(sim, truth_head)
    np.testing.assert_allclose(moved, [0.0, 0.0, 0.01], atol=1e-12)


def test_a_measurement_sets_estimate_beside_truth_and_a_failure_says_why(sim) -> None:
    target = body_target("marker_red", MarkerDetector("red"))
    truth_world = target.truth_world(sim)
    np.testing.assert_array_equal(truth_world, sim.position("marker_red"))
    truth_head = sim.transform_points(truth_world, "world", "head")[0]
    off = truth_head + np.array([0.003, 0.0, -0.004])  # 5 mm off
    estimate = PositionEstimate(off[None], np.array([True]), np.array([0]), np.eye(3)[None])
    start = sim.render_count
    sim.render(1)
    ok = estimated_measurement(sim, target, "model2", estimate, start, (0.02, 0.03), {"a": 1.0})
    assert ok.ok and ok.status is Status.OK and ok.method is Method.MODEL2
    assert ok.status_text == "ok" and ok.renders == 1
    np.testing.assert_allclose(ok.error_head_m, [0.003, 0.0, -0.004], atol=1e-15)
    assert ok.depth_m == truth_head[2]
    assert ok.error_pct_of_depth == pytest.approx(100 * 0.005 / truth_head[2])
    invalid = PositionEstimate(
        np.full((1, 3), np.nan), np.array([False]), np.array([int(Flag.NOT_CONVERGING)])
    )
    bad = estimated_measurement(sim, target, "model1", invalid, start, (0.1,), {})
    assert not bad.ok and bad.status is Status.FAILED and bad.method is Method.MODEL1
    assert bad.failure is not None and bad.failure.cause is FailureCause.ESTIMATOR
    assert "NOT_CONVERGING" in bad.status_text and np.isnan(bad.estimate_world_m).all()
    np.testing.assert_allclose(bad.truth_head_m, truth_head)
    lost = failed_measurement(sim, target, "model2", Failure(FailureCause.LOST, "step 1", 2), 7, [])
    assert lost.status_text == lost.failure.message and "Ca2" in lost.status_text
    assert lost.renders == 7 and np.isnan(lost.covariance_head_m2).all()
