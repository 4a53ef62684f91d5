"""Measurements made by hand for the result tests: one per error and depth, or a failure."""

from __future__ import annotations

import numpy as np

from headsim.active.failure import Failure, FailureCause
from headsim.active.measurement import Measurement
from headsim.estimators.result import Method, Status

LOST = Failure(FailureCause.LOST, "step 1", 2, "and at 12 eye angles searched")


def measurement(error_m: float, depth_m: float, failure: Failure | None = None) -> Measurement:
    truth = np.array([0.0, 0.0, depth_m])
    estimate = truth + np.array([error_m, 0.0, 0.0]) if failure is None else np.full(3, np.nan)
    """A Model 2 measurement ``error_m`` off in x at ``depth_m`` (or failed)."""
    return Measurement(
        name="t",
        method=Method.MODEL2,
        status=Status.OK if failure is None else Status.FAILED,
        estimate_head_m=estimate,
        truth_head_m=truth,
        estimate_world_m=estimate,
        truth_world_m=truth,
        covariance_head_m2=np.eye(3),
        renders=7,
        servo_residual_px=(0.25, -0.5),
        failure=failure,
        detail="" if failure is None else failure.message,
    )
