"""Finding a lost target again, or a new one out of view, from images alone.

A search uses only what a real head knows: the eye steps at which a camera
last saw the target (the servo's memory), the start pose, the joints' ranges
in encoder steps, and the gains the servo has learnt (px per encoder step:
the image width over the gain is the field of view in steps, with no focal
length).  A *scan* (:func:`scan_eyes`, :func:`scan_neck`) looks for a target
that no memory places over the whole range of the joints a procedure may
move, on binned previews; with no gain learnt yet it steps at a fixed share
of the range (:data:`SCAN_DIVISIONS`), which needs no field of view.  Every
image it takes is a render, counted by the caller through ``HeadSim.render_count``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from headsim.active.eye_servo import EyeServo
from headsim.active.look import Glance, Looker, finds_blob
from headsim.active.neck_servo import NeckServo
from headsim.active.servo_types import Detector
from headsim.vision.detection import Detection

#: A scan's poses are at most this share of a field of view apart (the image width,
#: or height, over the learnt gain): each view overlaps the next by 0.3 of itself.
SCAN_STRIDE = 0.7

#: With no gain learnt, a scan steps at 1/SCAN_DIVISIONS of each joint's range: it then
#: covers any field of view wider than that (the eyes' 1.4 rad: 0.0875 rad, 5 degrees).
SCAN_DIVISIONS = 16

#: The most poses an eye scan looks from (it stops at the first that shows the target).
MAX_SCAN_POSES = 48

#: Levels of a neck scan with no Jacobian learnt: its grid at 4, 2 and 1 stride(s).
SCAN_LEVELS = 3


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
    field of view in steps (image width over the learnt gain), both ways, each
    end of the range included where the sweep passes it.
    """
    low, high = servo.step_range
    current = servo.sim.eye_encoder_steps()
    poses: list[int] = [*reversed(list(remembered)), 0]
    gain = servo.gains.get(camera) or servo.gains.get(3 - camera)
    if gain:
        stride = max(1, int(0.7 * width_px / abs(gain)))
        for k in range(1, max_sweep + 1):
            # Clipped to the range: a view needing an end of it less than a stride away.
            poses += [min(high, max(low, current + sign * k * stride)) for sign in (1, -1)]
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
    width = servo.looker.image_sizes_px[camera][0]
    poses = search_poses(servo, camera, remembered, width)[:max_poses]
    for tried, steps in enumerate(poses, start=1):
        sim.command_eye_steps(steps)
        sim.settle()
        detection = servo.observe(camera, detector, preview=False)
        if detection.found and detection.uv is not None:
            return Found(steps, detection, tried)
    return None


@dataclass(frozen=True)
class Scan:
    """What a scan did: the pose where it found the target (eye steps, or neck yaw,
    neck pitch and eye steps; None: nowhere), the detection there (a full frame's, when
    the scan looked with full frames; None when a binned preview showed it: the servo's
    first look takes its own), and the poses it looked from."""

    pose: tuple[int, ...] | None
    detection: Detection | None
    tried: int

    @property
    def found(self) -> bool:
        return self.pose is not None


def _grid(low: int, high: int, stride: float) -> list[int]:
    """Whole steps from ``low`` to ``high``, both included, evenly at most ``stride`` apart."""
    if high <= low:
        return [low]
    n = max(1, math.ceil((high - low) / max(stride, 1.0)))
    return sorted({round(low + k * (high - low) / n) for k in range(n + 1)})


def scan_eye_poses(servo: EyeServo, camera: int, width_px: int) -> list[int]:
    """Eye steps a scan looks from, nearest the start pose first: the start pose (eye 0),
    then the eye range covered evenly at most :data:`SCAN_STRIDE` of a field of view apart
    (image width over the learnt gain), or 1/:data:`SCAN_DIVISIONS` of the range with no
    gain yet."""
    low, high = servo.step_range
    gain = servo.gains.get(camera) or servo.gains.get(3 - camera)
    stride = SCAN_STRIDE * width_px / abs(gain) if gain else (high - low) / SCAN_DIVISIONS
    poses = [0, *sorted(_grid(low, high, stride), key=lambda p: (abs(p), p))]
    return [p for k, p in enumerate(poses) if low <= p <= high and p not in poses[:k]]


def _binning(looker: Looker, camera: int, detector: Detector) -> int:
    """The preview binning a scan looks with (1: full frames): the servo's, for a blob
    detector, where it divides the image."""
    b = looker.config.preview_binning if looker.config.windows else 1
    width, height = looker.image_sizes_px[camera]
    if b <= 1 or not finds_blob(detector) or width % b or height % b:
        return 1
    return b


def _shows(looker: Looker, camera: int, detector: Detector, binning: int) -> bool:
    """Whether ``camera``'s binned preview shows the target (found, not cut or hidden)."""
    seen = looker.look(camera, detector, Glance(binning))
    return bool(seen.found and seen.uv is not None)


def scan_eyes(
    servo: EyeServo, camera: int, detector: Detector, max_poses: int = MAX_SCAN_POSES
) -> Scan:
    """Turn the eyes to each of :func:`scan_eye_poses` in turn (the neck still) until
    ``camera`` sees the target: a new target that no memory places and that the eyes'
    pose shows not.

    One binned preview per pose (``ServoConfig.preview_binning``, for a blob
    detector; else a full frame), at most ``max_poses``, the pose the eyes are at
    skipped (it was just looked from).  The eyes stay where it was found.
    """
    sim = servo.sim
    binning = _binning(servo.looker, camera, detector)
    poses = scan_eye_poses(servo, camera, servo.looker.image_sizes_px[camera][0])
    current = sim.eye_encoder_steps()
    poses = [p for p in poses if p != current][:max_poses]
    for tried, steps in enumerate(poses, start=1):
        sim.command_eye_steps(steps)
        sim.settle()
        if binning > 1:
            if _shows(servo.looker, camera, detector, binning):
                return Scan((steps,), None, tried)
            continue
        detection = servo.observe(camera, detector, preview=False)
        if detection.found and detection.uv is not None:
            return Scan((steps,), detection, tried)
    return Scan(None, None, len(poses))


def _level(index: int, levels: int) -> int:
    """The coarsest level of a coarse-to-fine grid (0: every 2**(levels - 1)-th point)
    that grid point ``index`` belongs to."""
    for level in range(levels - 1):
        if index % 2 ** (levels - 1 - level) == 0:
            return level
    return levels - 1


def neck_scan_strides(servo: NeckServo, size_px: tuple[int, int]) -> tuple[float, float]:
    """(yaw, pitch) steps between a neck scan's poses: :data:`SCAN_STRIDE` of a field of
    view (image width and height over the learnt Jacobian's px per step), or
    1/:data:`SCAN_DIVISIONS` of each range with none learnt yet."""
    (ylo, yhi), (plo, phi), _ = servo.step_ranges
    jac = servo.jacobian
    width, height = size_px
    per_yaw = float(max(abs(jac[0, 0]), abs(jac[1, 0]))) if jac is not None else 0.0
    per_pitch = float(abs(jac[2, 1])) if jac is not None else 0.0
    if per_yaw > 0 and per_pitch > 0:
        return SCAN_STRIDE * width / per_yaw, SCAN_STRIDE * height / per_pitch
    return max((yhi - ylo) / SCAN_DIVISIONS, 1.0), max((phi - plo) / SCAN_DIVISIONS, 1.0)


def _neck_scan_grid(
    servo: NeckServo, size_px: tuple[int, int]
) -> list[tuple[tuple[int, int, int], tuple[float, float]]]:
    """:func:`scan_neck_poses` in order, each with the (yaw, pitch) spacing of its level, steps."""
    (ylo, yhi), (plo, phi), _ = servo.step_ranges
    strides = neck_scan_strides(servo, size_px)
    levels = 1 if servo.jacobian is not None else SCAN_LEVELS
    yaws, pitches = _grid(ylo, yhi, strides[0]), _grid(plo, phi, strides[1])

    def key(i: int, j: int) -> tuple[float, int, int, int]:
        # Distance from the start pose in the strides of the pose's own level: each
        # level reaches out as fast as its spacing allows, the levels interleaved.
        level = max(_level(i, levels), _level(j, levels))
        y, p = yaws[i], pitches[j]
        spacing = 2 ** (levels - 1 - level)
        return math.hypot(y / strides[0], p / strides[1]) / spacing, level, y, p

    order = sorted(
        ((i, j) for i in range(len(yaws)) for j in range(len(pitches))), key=lambda q: key(*q)
    )
    out = []
    for i, j in order:
        spacing = 2 ** (levels - 1 - max(_level(i, levels), _level(j, levels)))
        out.append(((yaws[i], pitches[j], 0), (spacing * strides[0], spacing * strides[1])))
    return out


def scan_neck_poses(servo: NeckServo, size_px: tuple[int, int]) -> list[tuple[int, int, int]]:
    """(neck yaw, neck pitch, eye) steps a Model 1 scan looks from: the whole of the neck's
    ranges, the eyes at 0, every pose once, at most :func:`neck_scan_strides` apart.

    With a learnt Jacobian, nearest the start pose first (in strides).  With none
    (the first target: no field of view known), coarse to fine: the grid's poses at
    every 4th, every 2nd and every stride of 1/:data:`SCAN_DIVISIONS` of the range
    (:data:`SCAN_LEVELS`), ordered by their distance from the start pose in their
    own level's spacing, so that the coarse poses reach a far target in a few looks
    while the fine ones cover a narrow view near the start."""
    return [pose for pose, _ in _neck_scan_grid(servo, size_px)]


def _refinement(
    servo: NeckServo, pose: tuple[int, int, int], spacing: tuple[float, float]
) -> list[tuple[int, int, int]]:
    """Neck poses half a grid spacing around ``pose`` (within the ranges), the four along
    the axes first: where camera 1 sees the target and camera 2 not, the two views'
    overlap is within a spacing of it."""
    (ylo, yhi), (plo, phi), _ = servo.step_ranges
    dy, dp = (max(1, round(s / 2)) for s in spacing)
    around = [
        (pose[0] + i * dy, pose[1] + j * dp, pose[2])
        for i in (-1, 0, 1)
        for j in (-1, 0, 1)
        if (i, j) != (0, 0)
    ]
    inside = [q for q in around if ylo <= q[0] <= yhi and plo <= q[1] <= phi]
    return sorted(inside, key=lambda q: ((q[0] != pose[0]) + (q[1] != pose[1]), q))


def scan_neck(servo: NeckServo, detector: Detector, max_poses: int | None = None) -> Scan:
    """Move the neck (the eyes at 0) to each of :func:`scan_neck_poses` in turn until both
    cameras see the target (Model 1's servo needs both to start).

    One binned preview of camera 1 per pose, and one of camera 2 where camera 1's
    shows it (a blob detector; else both full frames, :meth:`NeckServo.look_from`).
    Where camera 1 alone sees it from a pose of the grid, the poses half that
    pose's spacing around it come next (:func:`_refinement`; not refined again):
    the two views' overlap, narrower than a view, may fall between the grid's
    poses.  At most ``max_poses`` (default: the whole grid, at most
    (:data:`SCAN_DIVISIONS` + 1)**2 poses before a gain is learnt, and 8 around
    each pose refined), the pose the head is at skipped.  The head stays where it
    was found.
    """
    sim = servo.sim
    binning = min(_binning(servo.looker, c, detector) for c in (1, 2))
    here = servo.steps()
    queue: list[tuple[tuple[int, int, int], tuple[float, float] | None]] = [
        (q, spacing)
        for q, spacing in _neck_scan_grid(servo, servo.looker.image_sizes_px[1])
        if q != here
    ]
    looked = {here}
    resolution = sim.settings.encoder_resolution_rad
    tried = 0
    while queue and (max_poses is None or tried < max_poses):
        pose, spacing = queue.pop(0)
        if pose in looked:
            continue
        looked.add(pose)
        tried += 1
        if binning <= 1:
            if servo.look_from(pose, detector):
                return Scan(pose, None, tried)
            continue
        yaw, pitch, eye = (s * resolution for s in pose)
        sim.command(neck_yaw=yaw, neck_pitch=pitch, eye=eye)
        sim.settle()
        if not _shows(servo.looker, 1, detector, binning):
            continue
        if _shows(servo.looker, 2, detector, binning):
            return Scan(pose, None, tried)
        if spacing is not None:
            refined = [(q, None) for q in _refinement(servo, pose, spacing) if q not in looked]
            queue[:0] = refined
    return Scan(None, None, tried)


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
    poses = neck_search_poses(servo, last, servo.looker.image_sizes_px[1])[:max_poses]
    for tried, pose in enumerate(poses, start=1):
        if servo.look_from(pose, detector):
            return pose, tried
    return None


__all__ = [
    "MAX_SCAN_POSES",
    "SCAN_DIVISIONS",
    "SCAN_LEVELS",
    "SCAN_STRIDE",
    "Found",
    "Scan",
    "find_neck_view",
    "find_view",
    "neck_scan_strides",
    "neck_search_poses",
    "scan_eye_poses",
    "scan_eyes",
    "scan_neck",
    "scan_neck_poses",
    "search_poses",
]
