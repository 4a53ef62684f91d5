"""Why a measurement (or one calibration position) failed: its cause, the stage
and camera where it happened, from a detection or a servo run that did not end
converged.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from headsim.active.servo_types import NeckServoResult, ServoOutcome, ServoResult
from headsim.vision.detection import Detection, DetectionStatus


class FailureCause(enum.Enum):
    """Why a measurement (or one calibration position) failed."""

    LOST = "lost"  # nothing of the target in the camera's image
    CUT = "cut"  # the target runs off the image border
    OCCLUDED = "occluded"  # partly hidden
    LOW_TEXTURE = "low texture"  # the fovea's template too plain to track (markerless)
    AMBIGUOUS = "ambiguous"  # the match had a rival nearly as good (markerless)
    JOINT_LIMIT = "joint limit"  # the fixation needs a joint beyond its range
    ITERATION_LIMIT = "iteration limit"  # the servo's bound on moves
    ESTIMATOR = "estimator"  # the estimator flagged the point invalid


_FROM_DETECTION = {
    DetectionStatus.LOST: FailureCause.LOST,
    DetectionStatus.CUT: FailureCause.CUT,
    DetectionStatus.OCCLUDED: FailureCause.OCCLUDED,
    DetectionStatus.LOW_TEXTURE: FailureCause.LOW_TEXTURE,
    DetectionStatus.AMBIGUOUS: FailureCause.AMBIGUOUS,
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


__all__ = ["Failure", "FailureCause", "detection_failure", "neck_failure", "servo_failure"]
