"""The servos' result types (active/servo_types.py): outcomes, convergence, residuals."""

from __future__ import annotations

import numpy as np

from headsim.active.servo_types import NeckServoResult, ServoConfig, ServoOutcome, ServoResult


def test_only_a_converged_outcome_is_converged() -> None:
    for outcome in ServoOutcome:
        eye = ServoResult(outcome, 10, (320.0, 240.0), 0.05, 1.5, 10.03, 4, 3)
        neck = NeckServoResult(outcome, (1, 2, 3), (0.0, 0.0, 0.0), (1.0, 2.0, 3.0), None, 4, 3)
        assert eye.converged == neck.converged == (outcome is ServoOutcome.CONVERGED)
    assert {o.value for o in ServoOutcome} == {
        "converged",
        "target lost",
        "iteration limit",
        "joint limit",
    }


def test_the_neck_residual_is_its_largest_error_component() -> None:
    result = NeckServoResult(
        ServoOutcome.CONVERGED, (0, 0, 0), (0.2, -0.7, 0.5), (0.0, 0.0, 0.0), np.eye(3), 9, 4
    )
    assert result.residual_px == 0.7
    assert result.lost_camera is None and result.retreats == 0


def test_the_default_config_bounds_every_loop_and_looks_through_windows() -> None:
    config = ServoConfig()
    assert config.max_iterations > 0 and config.max_retreats >= 0
    assert config.windows and config.preview_binning >= 1
    assert 0 < config.tolerance_px < 1  # sub-pixel fixation
