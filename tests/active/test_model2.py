"""Model 2, the two-step measurement, end to end with real rendering."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.eye_servo import EyeServo
from headsim.active.failure import FailureCause
from headsim.active.measurement import body_target
from headsim.active.model2 import Model2Config, measure_model2
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector, find_marker

RED = body_target("marker_red", MarkerDetector("red"))


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
        # The servo gains carry over after the first point; each camera first looks for
        # a moved point where it saw the last one (a miss: one render more than a preview).
        assert np.mean(renders[1:]) <= 9 + 2


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


def test_a_target_out_of_view_where_the_eyes_are_is_found_straight_ahead() -> None:
    with HeadSim("default") as sim:
        sim.move(eye=0.6)  # converged on something near: the new target is out of Ca1's view
        _place_in_head(sim, "marker_red", [-0.1, 0.0, 0.9])
        assert not find_marker(sim.render(1), "red").found
        m = measure_model2(sim, EyeServo(sim), RED)
        assert m.ok, m.status
        assert m.error_pct_of_depth < 0.3
