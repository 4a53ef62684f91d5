"""Each named failure cause of a measurement or a calibration position, on rendered images."""

from __future__ import annotations

import numpy as np
import pytest

from headsim.active.calibration import CalibrationError, calibrate_head
from headsim.active.eye_servo import EyeServo
from headsim.active.failure import FailureCause, detection_failure
from headsim.active.measurement import body_target
from headsim.active.model2 import Model2Config, measure_model2
from headsim.active.servo_types import ServoConfig
from headsim.sim import names
from headsim.sim.settings import CameraSettings, HeadSettings
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import DetectionStatus
from headsim.vision.markers import MarkerDetector

RED = body_target("marker_red", MarkerDetector("red"))


BALL = body_target(names.CALIBRATION_BALL, MarkerDetector("yellow"))


def _place_in_head(sim: HeadSim, body: str, p_head: list[float]) -> np.ndarray:
    p_world = sim.transform_points(np.asarray(p_head, float), "head", "world")[0]
    sim.set_body_pose(body, p_world)
    return p_world


def test_each_failure_names_its_cause() -> None:
    with HeadSim("default") as sim:
        # Lost: behind the head.
        sim.set_body_pose("marker_red", [0.0, -1.0, 0.2])
        lost = measure_model2(sim, EyeServo(sim), RED)
        assert lost.failure is not None and lost.failure.cause is FailureCause.LOST
        # Cut: half over Ca1's left border at the start pose.  The detection says so,
        # and its failure is a cut of camera 1 at step 1 ...
        cam = sim.camera_settings(1)
        x_over_z = (
            3.0 - cam.image_centre[0]
        ) / cam.kx  # centre 3 px in: the 7.7 px ball crosses the border
        left = sim.transform_points(
            np.array([x_over_z * 0.3, 0.0, 0.3]), names.CAMERAS[0], "world"
        )[0]
        sim.set_body_pose("marker_red", left)
        seen = RED.detector(sim.render(1))
        assert seen.status is DetectionStatus.CUT
        failure = detection_failure(seen, "step 1", 1)
        assert (failure.cause, failure.camera, failure.stage) == (FailureCause.CUT, 1, "step 1")
        # ... but the eyes can fixate it, so Model 2 scans the eye range and measures it.
        cut = measure_model2(sim, EyeServo(sim), RED)
        assert cut.ok and cut.scan_renders > 0, cut.status
        assert np.linalg.norm(cut.estimate_head_m - cut.truth_head_m) < 0.01 * 0.3
        # Estimator: on the midline without the near-midline remedy, y is 0/0.
        _place_in_head(sim, "marker_red", [0.0, 0.03, 0.6])
        flat = measure_model2(sim, EyeServo(sim), RED, config=Model2Config(midline_px=0.0))
        assert flat.failure is not None and flat.failure.cause is FailureCause.ESTIMATOR
        assert "NO_Y" in flat.detail
        # Iteration limit: one move allowed.
        _place_in_head(sim, "marker_red", [0.1, 0.0, 0.5])
        short = measure_model2(sim, EyeServo(sim, ServoConfig(max_iterations=1)), RED)
        assert short.failure is not None
        assert short.failure.cause is FailureCause.ITERATION_LIMIT
        assert short.detail == "Ca1 at step 1: iteration limit (after 1 moves)"
    # Joint limit: a wide-angle head sees a near target that Ca1 would need 0.9 rad to fixate.
    wide = CameraSettings(kx=200.0, ky=200.0)
    with HeadSim("default", HeadSettings(cameras=(wide, wide))) as sim:
        _place_in_head(sim, "marker_red", [0.175, 0.0, 0.2])
        far = measure_model2(sim, EyeServo(sim), RED)
        assert far.failure is not None and far.failure.cause is FailureCause.JOINT_LIMIT, far.status
        assert far.failure.camera == 1


def test_calibration_failures_name_their_cause() -> None:
    with HeadSim("default") as sim:
        servo = EyeServo(sim)
        ahead = sim.transform_points(np.array([0.02, 0.0, 0.4]), "head", "world")[0]
        beside = sim.transform_points(np.array([0.05, 0.0, 0.4]), "head", "world")[0]
        behind = np.array([0.0, -1.0, 0.2])
        with pytest.raises(
            CalibrationError,
            match=r"too few positions seen: 1 of 3 .* because 2 Ca1 at step 1: target lost$",
        ) as err:
            calibrate_head(
                sim, servo, BALL, names.CALIBRATION_BALL, np.array([ahead, behind, behind])
            )
        assert [o is None for o in err.value.outcomes] == [True, False, False]
        # Two positions at one depth, one lateral spread: alpha_e1 and alpha_e2 not separable.
        with pytest.raises(CalibrationError, match="degenerate layout because the 2 fixated"):
            calibrate_head(
                sim, servo, BALL, names.CALIBRATION_BALL, np.array([ahead, ahead]), extended=False
            )
        # Three positions at y = 0: nothing for the extended fit's v0 and kx/ky.
        near = sim.transform_points(np.array([-0.03, 0.0, 0.3]), "head", "world")[0]
        with pytest.raises(CalibrationError, match="needs a vertical spread"):
            calibrate_head(
                sim, servo, BALL, names.CALIBRATION_BALL, np.array([ahead, beside, near])
            )
