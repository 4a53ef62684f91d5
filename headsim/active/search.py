"""Finding a lost target again from images alone.

A search uses only what a real head knows: the eye steps at which a camera
last saw the target (the servo's memory), the start pose, and the gains the
servo has learnt (px per encoder step: the image width over the gain is the
field of view in steps, with no focal length).  Every image it takes is a
render, counted by the caller through ``HeadSim.render_count``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.active.neck_servo import NeckServo
from headsim.active.servo_types import Detector
from headsim.vision.detection import Detection


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

    One render per pose (a full frame: a preview and its window would be two
    where the target is, and a preview and the frame two where it is not); at
    most ``max_poses``.  None: not found (the caller names the failure).
    """
    sim = servo.sim
    width = sim.camera_settings(camera).width
    poses = search_poses(servo, camera, remembered, width)[:max_poses]
    for tried, steps in enumerate(poses, start=1):
        sim.command_eye_steps(steps)
        sim.settle()
        detection = servo.observe(camera, detector, preview=False)
        if detection.found and detection.uv is not None:
            return Found(steps, detection, tried)
    return None


def neck_search_poses(
    servo: NeckServo,
    last: Sequence[tuple[int, int, int]],
    size_px: tuple[int, int],
    rings: int = 2,
) -> list[tuple[int, int, int]]:
    """Neck poses to look from for a target lost since the last fixation, best first.

    ``last``: the fixations' (yaw, pitch, eye) steps where the target was seen,
    oldest first.  Around the most recent one, a grid of neck (yaw, pitch)
    offsets in strides of 0.7 of the field of view in steps (image width and
    height over the learnt Jacobian's px per step: no focal length), out to
    ``rings`` strides; ordered by distance from where the last two fixations
    predict it (a constant velocity in steps), so that a target moving on
    steadily is found first.  Within the joints' ranges; the eye stays.
    """
    jac = servo.jacobian
    if not last or jac is None:
        return []
    centre = np.array(last[-1], dtype=float)
    predicted = 2 * centre - np.array(last[-2], dtype=float) if len(last) > 1 else centre
    width, height = size_px
    per_yaw = float(max(abs(jac[0, 0]), abs(jac[1, 0])))
    per_pitch = float(abs(jac[2, 1]))
    if per_yaw <= 0 or per_pitch <= 0:
        return []
    stride = np.array([max(1, int(0.7 * width / per_yaw)), max(1, int(0.7 * height / per_pitch))])
    poses = {
        (int(centre[0] + i * stride[0]), int(centre[1] + j * stride[1]), int(centre[2]))
        for i in range(-rings, rings + 1)
        for j in range(-rings, rings + 1)
        if (i, j) != (0, 0)
    }
    if len(last) > 1:  # the prediction itself, to the whole step
        poses.add(tuple(round(float(x)) for x in predicted))  # type: ignore[arg-type]
    ranges = servo.step_ranges
    here = servo.steps()
    scale = np.array([stride[0], stride[1], 1.0])
    inside = [
        p
        for p in poses
        if p != here and all(lo <= s <= hi for s, (lo, hi) in zip(p, ranges, strict=True))
    ]
    return sorted(
        inside, key=lambda p: (float(np.linalg.norm((np.array(p) - predicted) / scale)), p)
    )


def find_neck_view(
    servo: NeckServo,
    detector: Detector,
    last: Sequence[tuple[int, int, int]],
    max_poses: int = 12,
) -> tuple[tuple[int, int, int], int] | None:
    """Look from each of :func:`neck_search_poses` until both cameras see the target.

    Two renders per pose (one where camera 1 does not see it); at most
    ``max_poses``.  Returns the pose and the number of poses tried, or None
    (the caller names the failure).
    """
    cam = servo.sim.camera_settings(1)
    poses = neck_search_poses(servo, last, (cam.width, cam.height))[:max_poses]
    for tried, pose in enumerate(poses, start=1):
        if servo.look_from(pose, detector):
            return pose, tried
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
    "Found",
    "find_neck_view",
    "find_view",
    "nearest_seen",
    "neck_search_poses",
    "search_poses",
]
