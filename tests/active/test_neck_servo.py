"""The image-only neck servo (Model 1's fixation) with real rendering: every way it ends."""

from __future__ import annotations

from functools import partial

import numpy as np

from headsim.active.servo_types import ServoConfig, ServoOutcome
from headsim.sim.simulator import HeadSim
from headsim.vision.detect import find_marker

RED = partial(find_marker, colour="red")


MARKER = "marker_red"


def test_neck_servo_reports_lost_and_iteration_limit() -> None:
    from headsim.active.neck_servo import NeckServo

    with HeadSim("default") as sim:
        sim.set_body_pose(MARKER, [0.0, -1.0, 0.2])
        lost = NeckServo(sim).run(RED)
        assert lost.outcome is ServoOutcome.TARGET_LOST
        # One look through each camera, after a binned preview that did not find it.
        assert lost.renders == 4
        sim.set_body_pose(MARKER, [0.2, 0.6, 0.4])
        limited = NeckServo(sim, ServoConfig(max_iterations=1)).run(RED)
        assert limited.outcome is ServoOutcome.ITERATION_LIMIT
        assert limited.residual_px > 0.1
        converged = NeckServo(sim).run(RED)
        assert converged.converged
        assert converged.residual_px <= 0.2
        assert converged.jacobian is not None and abs(np.linalg.det(converged.jacobian)) > 0
