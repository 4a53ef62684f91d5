"""What the image-only servos take and return: the detector they are handed,
their bounds and tolerances (:class:`ServoConfig`), how a run ended
(:class:`ServoOutcome`) and its result, for the eye servo
(:class:`ServoResult`) and the neck servo (:class:`NeckServoResult`).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from headsim.vision.detection import Detection, DetectionStatus

Detector = Callable[[np.ndarray], Detection]


class ServoOutcome(enum.Enum):
    CONVERGED = "converged"
    TARGET_LOST = "target lost"
    ITERATION_LIMIT = "iteration limit"
    JOINT_LIMIT = "joint limit"


@dataclass(frozen=True)
class ServoResult:
    """How a servo ended.

    ``steps``: final eye-motor position, encoder steps; ``uv``: the target's
    image point there, px; ``residual_px``: ``u - goal_u`` there;
    ``gain_px_per_step``: the last gain estimate (seed for the next target);
    ``subpixel_steps``: the fractional step at which u would equal the goal,
    interpolated with the gain (the image tells more than the encoder), the
    mean over ``fixation_samples`` images around the crossing (see
    ``ServoConfig.average_fixation``); ``renders``: images taken; ``iterations``: moves made.  ``lost_status``:
    when the target was lost, what the detector said (lost, cut, occluded).
    ``seen``: every (steps, u, v) at which the camera saw the target, in order
    (the memory a search returns to).  ``retreats``: moves undone because the
    target was lost there (re-acquired at the last pose that saw it).
    """

    outcome: ServoOutcome
    steps: int
    uv: tuple[float, float] | None
    residual_px: float
    gain_px_per_step: float | None
    subpixel_steps: float
    renders: int
    iterations: int
    lost_status: DetectionStatus | None = None
    seen: tuple[tuple[int, float, float], ...] = ()
    retreats: int = 0
    fixation_samples: int = 1

    @property
    def converged(self) -> bool:
        return self.outcome is ServoOutcome.CONVERGED


@dataclass(frozen=True)
class ServoConfig:
    """Bounds and tolerances of the eye servo.

    ``tolerance_px``: stop when |u - goal| is within this, or within half the
    image motion of one encoder step (no whole step can do better).
    ``probe_steps``: first probe when no gain is known; grown x4 until the
    image moves ``min_probe_px``.  ``min_secant_steps``: moves shorter than this
    do not update the gain (centroid pixel-locking would corrupt it).
    ``max_retreats``: moves after which the target was gone that are undone
    and retried at half the length, per run.
    ``windows``: render only a window around where the target is expected
    (see :meth:`EyeServo.observe`); ``window_margin_px`` is added to its
    half-side beyond the blob and a quarter of the predicted motion.
    ``preview_binning``: where no detection predicts a blob's window (a new
    target), find it first in the whole view binned b x b (1/b^2 of the
    pixels), then render its window; 1: a full frame instead.

    ``average_fixation``: once converged, take images at the whole steps that
    spread the target over one pixel of image motion around the crossing (at
    most ``max_fixation_samples``, every k-th step beyond), average their
    crossings and return to the final step.  One image's sub-step fixation is
    off by the centroid's sub-pixel rendering floor over the gain, which is
    more angle at a shorter focal length; the average leaves the same angle
    at every zoom (``headsim.active.eye_servo``), for about twice the
    renders.  Off: one image, the final step's.  Blob detectors only; a
    pattern (a chessboard's corners) is fixated from one image.
    """

    tolerance_px: float = 0.1
    max_iterations: int = 25
    probe_steps: int = 16
    min_probe_px: float = 2.0
    min_secant_steps: int = 8
    max_retreats: int = 3
    windows: bool = True
    window_margin_px: float = 8.0
    preview_binning: int = 4
    average_fixation: bool = False
    max_fixation_samples: int = 8


@dataclass(frozen=True)
class NeckServoResult:
    """How a neck-and-eyes fixation ended.

    ``steps``: final (neck yaw, neck pitch, eye) positions, encoder steps;
    ``error_px``: (u1 - u10, u2 - u20, mean v - v0) there; ``subpixel_steps``:
    the fractional positions at which the error would vanish, from the learnt
    Jacobian; ``jacobian``: px per step (3 x 3), seed for the next fixation.
    """

    outcome: ServoOutcome
    steps: tuple[int, int, int]
    error_px: tuple[float, float, float]
    subpixel_steps: tuple[float, float, float]
    jacobian: np.ndarray | None
    renders: int
    iterations: int
    lost_camera: int | None = None
    lost_status: DetectionStatus | None = None
    retreats: int = 0
    fixation_samples: int = 1

    @property
    def converged(self) -> bool:
        return self.outcome is ServoOutcome.CONVERGED

    @property
    def residual_px(self) -> float:
        """Largest |error| component, px."""
        return float(np.max(np.abs(self.error_px)))


__all__ = ["Detector", "NeckServoResult", "ServoConfig", "ServoOutcome", "ServoResult"]
