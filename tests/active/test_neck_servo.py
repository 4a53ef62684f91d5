"""The image-only neck servo (Model 1's fixation) with real rendering: every way it ends."""

from __future__ import annotations

import numpy as np

from headsim.active.servo_types import ServoConfig, ServoOutcome
from headsim.sim.simulator import HeadSim
from headsim.vision.markers import MarkerDetector

RED = MarkerDetector("red")


MARKER = "marker_red"


def test_neck_servo_reports_lost_and_iteration_limit() -> None:
    from headsim.active.neck_servo import NeckServo

    with HeadSim("default") as sim:
        sim.set_body_pose(MARKER, [0.0, -1.0, 0.2])
        lost = NeckServo(sim).run(RED)
        assert lost.outcome is ServoOutcome.TARGET_LOST
        # Camera 1's look, after a binned preview that did not find it; camera 2
        # is not rendered once camera 1 has lost the target.
        assert lost.renders == 2 and lost.lost_camera == 1
        sim.set_body_pose(MARKER, [0.2, 0.6, 0.4])
        limited = NeckServo(sim, ServoConfig(max_iterations=1)).run(RED)
        assert limited.outcome is ServoOutcome.ITERATION_LIMIT
        assert limited.residual_px > 0.1
        converged = NeckServo(sim).run(RED)
        assert converged.converged
        assert converged.residual_px <= 0.2
        assert converged.jacobian is not None and abs(np.linalg.det(converged.jacobian)) > 0


def test_neck_servo_averages_its_fixation_along_the_eye_joint() -> None:
    from headsim.active.neck_servo import NeckServo

    with HeadSim("default") as sim:
        sim.set_body_pose(MARKER, [0.05, 0.7, 0.24])
        single = NeckServo(sim).run(RED)
        sim.move(neck_yaw=0.0, neck_pitch=0.0, eye=0.0)
        averaged = NeckServo(sim, ServoConfig(average_fixation=True)).run(RED)
        assert single.converged and averaged.converged
        assert single.fixation_samples == 1 and averaged.fixation_samples >= 2
        # Two renders a pose; the neck and eyes back where the servo converged.
        assert 0 < averaged.renders - single.renders <= 2 * averaged.fixation_samples
        assert averaged.steps == single.steps
        resolution = sim.settings.encoder_resolution_rad
        yaw, pitch = (round(a / resolution) for a in sim.neck_encoders())
        assert (yaw, pitch, sim.eye_encoder_steps()) == averaged.steps
        # Averaging moves the sub-step fixation by less than a step.
        assert np.all(np.abs(np.subtract(averaged.subpixel_steps, single.subpixel_steps)) < 1.0)


def test_neck_servo_probes_its_jacobian_through_windows() -> None:
    """The Jacobian's probe looks are located like a new target's (a binned preview, then
    the window it places), not as whole frames: the same steps and Jacobian as whole
    frames give, from a small share of their pixels."""
    from headsim.active.neck_servo import NeckServo

    results, frames = {}, {}
    for windows in (True, False):
        with HeadSim("default") as sim:
            sim.set_body_pose(MARKER, [0.2, 0.6, 0.4])
            before = sim.rendered_frames
            results[windows] = NeckServo(sim, ServoConfig(windows=windows)).run(RED)
            frames[windows] = sim.rendered_frames - before
    windowed, whole = results[True], results[False]
    assert windowed.converged and whole.converged
    assert windowed.steps == whole.steps
    assert windowed.jacobian is not None and whole.jacobian is not None
    # A window's pixels are the frame's crop but for an MSAA sample flipped on a rim
    # now and then (docs/concepts/servo.md), which moves a centroid by ~0.002 px.
    np.testing.assert_allclose(windowed.jacobian, whole.jacobian, rtol=1e-3, atol=1e-4)
    # Whole frames for the probes alone would be 6 frames of pixels.
    assert frames[True] < 0.1 * frames[False]
