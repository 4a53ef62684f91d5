"""Why a measurement failed, and finding a lost target again from images alone.

A search uses only what a real head knows: the eye steps at which a camera
last saw the target (the servo's memory), the start pose, and the gains the
servo has learnt (px per encoder step: the image width over the gain is the
field of view in steps, with no focal length).  Every image it takes is a
render, counted by the caller through ``HeadSim.render_count``.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable
from dataclasses import dataclass

from headsim.servo import Detector, EyeServo, NeckServoResult, ServoOutcome, ServoResult
from headsim.vision import Detection, DetectionStatus


class FailureCause(enum.Enum):
    """Why a measurement (or one calibration position) failed."""

    LOST = "lost"  # nothing of the target in the camera's image
    CUT = "cut"  # the target runs off the image border
    OCCLUDED = "occluded"  # partly hidden
    JOINT_LIMIT = "joint limit"  # the fixation needs a joint beyond its range
    ITERATION_LIMIT = "iteration limit"  # the servo's bound on moves
    ESTIMATOR = "estimator"  # the estimator flagged the point invalid


_FROM_DETECTION = {
    DetectionStatus.LOST: FailureCause.LOST,
    DetectionStatus.CUT: FailureCause.CUT,
    DetectionStatus.OCCLUDED: FailureCause.OCCLUDED,
}
_FROM_OUTCOME = {
    ServoOutcome.JOINT_LIMIT: FailureCause.JOINT_LIMIT,
    ServoOutcome.ITERATION_LIMIT: FailureCause.ITERATION_LIMIT,
}


@dataclass(frozen=True)
class Failure:
    """A failure's cause, where it happened (``stage``: "step 1", "step 2",
    "search", "fixation", "estimate"), in which camera (1, 2; None: not one
    camera's), and any detail."""

    cause: FailureCause
    stage: str
    camera: int | None = None
    detail: str = ""

    @property
    def message(self) -> str:
        where = f"Ca{self.camera} at {self.stage}" if self.camera else self.stage
        what = (
            f"target {self.cause.value}"
            if self.cause in _FROM_DETECTION.values()
            else (self.cause.value)
        )
        return f"{where}: {what}" + (f" ({self.detail})" if self.detail else "")

    def as_dict(self) -> dict[str, object]:
        return {
            "cause": self.cause.value,
            "stage": self.stage,
            "camera": self.camera,
            "detail": self.detail,
        }


def detection_failure(detection: Detection, stage: str, camera: int, detail: str = "") -> Failure:
    """The failure of a detection that did not find the target."""
    cause = _FROM_DETECTION.get(detection.status, FailureCause.LOST)
    return Failure(cause, stage, camera, detail)


def servo_failure(result: ServoResult, stage: str, camera: int) -> Failure:
    """The failure of an eye servo run that did not converge."""
    if result.outcome is ServoOutcome.TARGET_LOST:
        cause = _FROM_DETECTION.get(result.lost_status or DetectionStatus.LOST, FailureCause.LOST)
    else:
        cause = _FROM_OUTCOME[result.outcome]
    detail = f"after {result.iterations} moves" if result.iterations else "in its first image"
    return Failure(cause, stage, camera, detail)


def neck_failure(result: NeckServoResult, stage: str = "fixation") -> Failure:
    """The failure of a neck servo run (Model 1) that did not converge."""
    if result.outcome is ServoOutcome.TARGET_LOST:
        cause = _FROM_DETECTION.get(result.lost_status or DetectionStatus.LOST, FailureCause.LOST)
        return Failure(cause, stage, result.lost_camera, f"after {result.iterations} moves")
    return Failure(_FROM_OUTCOME[result.outcome], stage, None, f"after {result.iterations} moves")


@dataclass(frozen=True)
class Found:
    """Where a search found the target: eye steps, the detection there, poses tried."""

    steps: int
    detection: Detection
    tried: int


def search_poses(
    servo: EyeServo,
    camera: int,
    remembered: Iterable[int],
    width_px: int,
    max_sweep: int = 8,
) -> list[int]:
    """Eye steps to look at for ``camera``, best first, within the eye range.

    The poses where it last saw the target (most recent first), the start pose
    (eye 0), then a sweep out from the current pose in strides of 0.7 of the
    field of view in steps (image width over the learnt gain), both ways.
    """
    low, high = servo.step_range
    current = servo.sim.eye_encoder_steps()
    poses: list[int] = [*reversed(list(remembered)), 0]
    gain = servo.gains.get(camera) or servo.gains.get(3 - camera)
    if gain:
        stride = max(1, int(0.7 * width_px / abs(gain)))
        for k in range(1, max_sweep + 1):
            poses += [current + sign * k * stride for sign in (1, -1)]
    unique = []
    for p in poses:
        if low <= p <= high and p != current and p not in unique:
            unique.append(p)
    return unique


def find_view(
    servo: EyeServo,
    camera: int,
    detector: Detector,
    remembered: Iterable[int] = (),
    max_poses: int = 12,
) -> Found | None:
    """Turn the eyes to each of :func:`search_poses` in turn until ``camera`` sees the target.

    One render per pose; at most ``max_poses``.  None: not found (the caller
    names the failure).
    """
    sim = servo.sim
    width = sim.camera_settings(camera).width
    poses = search_poses(servo, camera, remembered, width)[:max_poses]
    for tried, steps in enumerate(poses, start=1):
        sim.command_eye_steps(steps)
        sim.settle()
        detection = servo.observe(camera, detector)
        if detection.found and detection.uv is not None:
            return Found(steps, detection, tried)
    return None


def nearest_seen(
    seen: Iterable[tuple[int, float, float]], steps: int, goal_u: float, midline_px: float
) -> tuple[int, float, float] | None:
    """From a servo's memory, the image nearest eye step ``steps`` whose target is at least
    ``midline_px`` off the goal column (else the one farthest off it)."""
    memory = list(seen)
    if not memory:
        return None
    off = [m for m in memory if abs(m[1] - goal_u) >= midline_px]
    if off:
        return min(off, key=lambda m: abs(m[0] - steps))
    return max(memory, key=lambda m: abs(m[1] - goal_u))


__all__ = [
    "Failure",
    "FailureCause",
    "Found",
    "detection_failure",
    "find_view",
    "nearest_seen",
    "neck_failure",
    "search_poses",
    "servo_failure",
]
