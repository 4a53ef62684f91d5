"""Gaze behaviours on the live head: saccades, smooth pursuit, a position estimate every frame.

Measurement path (no ground truth): :mod:`headsim.live.estimator` turns each
frame's marker centroids (or a markerless pair's tracked and corresponded points) and encoders into the *fixation angles* ``q*`` and
a position estimate.

Smooth pursuit drives the motors towards ``q*``; with the constant-velocity
predictor the goal moves on at ``q*``'s estimated velocity, which makes up for
the latency.  A saccade (minimum-jerk or bang-bang, within the motor limits)
is made when the target is newly seen or the offset is large.  A target not
seen is coasted after on the prediction for ``coast_frames`` frames; then the
gaze holds.  They see the live head only through its frames (images and encoders), the
commands they send it and its :attr:`~headsim.live.head.LiveHead.head` (the at-rest
servo's, with the head's specification and belief); a frame's truth only scores the run.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from headsim.active.look import foveal_detector
from headsim.active.measurement import HeadKnowledge
from headsim.active.neck_servo import NeckServo
from headsim.active.servo_types import Detector
from headsim.live.estimator import GazeEstimator
from headsim.live.head import Frame, LiveHead
from headsim.live.motors import MotorDriver, bang_bang_duration, min_jerk_duration
from headsim.sim.model import neck_of
from headsim.vision.detection import Detection


class GazeMode(enum.Enum):
    NECK = "neck"  # Model 1: neck yaw, neck pitch and the eye motor
    EYES = "eyes"  # the eye motor alone; the neck stays where it is


class SaccadeProfile(enum.Enum):
    MIN_JERK = "min_jerk"
    BANG_BANG = "bang_bang"


@dataclass(frozen=True)
class GazeConfig:
    """Pursuit and saccade settings (rad, px, s)."""

    mode: GazeMode = GazeMode.NECK
    predictor: bool = True
    saccade: SaccadeProfile = SaccadeProfile.MIN_JERK
    saccade_threshold_rad: float = 0.05  # a larger fixation correction starts a saccade
    fixation_tolerance_px: float = 1.0
    velocity_smoothing: float = 0.5  # weight of the newest velocity sample, (0, 1]
    coast_frames: int = 10  # frames the gaze coasts on its prediction when the target is not seen
    max_frames: int = 100_000


@dataclass(frozen=True)
class FrameRecord:
    """What happened at one frame (truth only for scoring)."""

    time_s: float
    found: bool
    error_px: np.ndarray | None
    estimate_world_m: np.ndarray | None
    truth_world_m: np.ndarray | None
    encoders_rad: np.ndarray
    fixation_rad: np.ndarray | None
    saccade: bool
    uv_px: tuple[tuple[float, float] | None, tuple[float, float] | None] = (None, None)


@dataclass(frozen=True)
class PursuitFrame:
    """The event the live pursuit reports at each frame it measured (see
    :mod:`headsim.active.events`): the frame's record."""

    record: FrameRecord


@dataclass(frozen=True)
class PursuitRun:
    """A live run of the gaze controller: per-frame records and the figures that score it."""

    records: tuple[FrameRecord, ...]
    ended: str  # why the loop ended

    def _scored(self) -> list[FrameRecord]:
        return [r for r in self.records if r.found and r.truth_world_m is not None]

    @property
    def errors_m(self) -> np.ndarray:
        return np.array(
            [np.linalg.norm(r.estimate_world_m - r.truth_world_m) for r in self._scored()]  # type: ignore[operator]
        )

    @property
    def depths_m(self) -> np.ndarray:
        return np.array([np.linalg.norm(r.truth_world_m) for r in self._scored()])  # type: ignore[arg-type]

    def rms_error_pct_of_depth(self, skip_s: float = 0.0) -> float:
        """RMS over frames of the 3-D error as % of the target's distance (frames after ``skip_s``)."""
        scored = self._scored()
        keep = np.array([r.time_s >= skip_s for r in scored], bool)
        if not keep.any():
            return math.nan
        pct = 100 * self.errors_m[keep] / self.depths_m[keep]
        return float(np.sqrt(np.mean(pct**2)))

    @property
    def losses(self) -> int:
        """Frames on which a present target went from seen to not seen."""
        count, seen = 0, False
        for r in self.records:
            if r.truth_world_m is None:
                seen = False
                continue
            if seen and not r.found:
                count += 1
            seen = r.found
        return count

    @property
    def reacquisitions(self) -> int:
        count, lost = 0, False
        for r in self.records:
            if r.truth_world_m is None:
                lost = False
                continue
            if lost and r.found:
                count += 1
            if r.found:
                lost = False
            elif any(p.found for p in self.records if p.time_s < r.time_s):
                lost = True
        return count

    @property
    def frames_lost(self) -> int:
        return sum(1 for r in self.records if r.truth_world_m is not None and not r.found)

    def time_to_fixation_s(self, tolerance_px: float, since_s: float = 0.0) -> float:
        """First time after ``since_s`` at which all offsets are within ``tolerance_px``, minus ``since_s``."""
        for r in self.records:
            if (
                r.time_s >= since_s
                and r.found
                and r.error_px is not None
                and np.all(np.abs(r.error_px) <= tolerance_px)
            ):
                return r.time_s - since_s
        return math.nan

    def lag_s(self) -> float:
        """Pursuit lag: least-squares time shift of the joints behind the fixation angles, s."""
        rows = [r for r in self.records if r.found and r.fixation_rad is not None]
        if len(rows) < 3:
            return math.nan
        t = np.array([r.time_s for r in rows])
        target = np.array([r.fixation_rad for r in rows])
        joints = np.array([r.encoders_rad for r in rows])
        rate = np.gradient(target, t, axis=0)
        denominator = float(np.sum(rate**2))
        return (
            float(np.sum((target - joints) * rate) / denominator) if denominator > 0 else math.nan
        )

    def rms_offset_px(self) -> float:
        errors = [r.error_px for r in self.records if r.found and r.error_px is not None]
        return float(np.sqrt(np.mean(np.square(errors)))) if errors else math.nan


def detect(detector: Detector, camera: int, image: np.ndarray) -> Detection:
    """``detector``'s answer on ``camera``'s whole ``image``; a foveal detector (a
    markerless pair) is told the camera and handed only the window it names (around
    its last sight, or its band), so correlation stays foveal."""
    foveal = foveal_detector(detector)
    if foveal is None:
        return detector(image)
    height, width = image.shape[:2]
    window = foveal.search_window(camera, (width, height), None)
    crop = image[window.y0 : window.y1, window.x0 : window.x1]
    return foveal.locate(camera, crop, (window.x0, window.y0))


def _saccade_duration(move_rad: np.ndarray, live: LiveHead, profile: SaccadeProfile) -> float:
    limits = live.motors.motors
    fn = min_jerk_duration if profile is SaccadeProfile.MIN_JERK else bang_bang_duration
    return max(fn(float(d), m.limits) for d, m in zip(move_rad, limits, strict=True))


def _command(
    goal: np.ndarray, velocity: np.ndarray, time_s: float, joints: tuple[int, ...]
) -> Callable[[MotorDriver, float], None]:
    def apply(motors: MotorDriver, now: float) -> None:
        for j in joints:
            motors.track(j, float(goal[j]), float(velocity[j]), time_s)

    return apply


def _saccade_command(
    goal: np.ndarray, duration: float, joints: tuple[int, ...], profile: SaccadeProfile
) -> Callable[[MotorDriver, float], None]:
    def apply(motors: MotorDriver, now: float) -> None:
        for j in joints:
            if profile is SaccadeProfile.MIN_JERK:
                motors.profile(j, float(goal[j]), now, duration)
            else:  # the track law at rest is the time-optimal bang-bang move
                motors.track(j, float(goal[j]), 0.0, now)

    return apply


def pursue(
    live: LiveHead,
    detector: Detector,
    estimator: GazeEstimator,
    duration_s: float,
    config: GazeConfig | None = None,
    on_frame: Callable[[FrameRecord], None] | None = None,
) -> PursuitRun:
    """Run the gaze controller for ``duration_s`` of simulated time (bounded by ``max_frames``).

    ``on_frame`` is called with every frame's record (progress, recording).
    """
    cfg = config or GazeConfig()
    joints = (0, 1, 2) if cfg.mode is GazeMode.NECK else (2,)
    records: list[FrameRecord] = []
    last: tuple[float, np.ndarray] | None = None
    velocity = np.zeros(3)
    busy_until = -math.inf
    unseen = 0
    ended = "duration"
    for _ in range(cfg.max_frames):
        if live.time_s >= duration_s:
            break
        frame: Frame = live.capture()
        seen = [detect(detector, camera, image) for camera, image in enumerate(frame.images, 1)]
        uv = (seen[0].uv if seen[0].found else None, seen[1].uv if seen[1].found else None)
        if uv[0] is None or uv[1] is None:
            records.append(
                FrameRecord(
                    frame.time_s,
                    False,
                    None,
                    None,
                    frame.truth_target_world_m,
                    frame.encoders_rad,
                    None,
                    False,
                    uv,
                )
            )
            if on_frame is not None:
                on_frame(records[-1])
            last = None
            unseen += 1
            if unseen == cfg.coast_frames + 1:  # stop coasting: hold where the joints are
                held = frame.encoders_rad.copy()
                live.send(_command(held, np.zeros(3), frame.time_s, joints), frame)
            continue
        unseen = 0
        offsets = estimator.measure((seen[0].uv, seen[1].uv), frame.encoders_rad)  # type: ignore[arg-type]
        fixation = offsets.fixation_rad.copy()
        if cfg.mode is GazeMode.EYES:
            fixation[:2] = frame.encoders_rad[:2]
            fixation[2] = estimator.eye_fixation(offsets, frame.encoders_rad)
        # A jump of the fixation angles (a target newly seen or moved at once) is no
        # motion to extrapolate: the predictor restarts.
        jumped = last is None or bool(
            np.max(np.abs(fixation - last[1])) > cfg.saccade_threshold_rad
        )
        if jumped or not cfg.predictor:
            velocity = np.zeros(3)
        else:
            sample = (fixation - last[1]) / (frame.time_s - last[0])  # type: ignore[index]
            velocity = cfg.velocity_smoothing * sample + (1 - cfg.velocity_smoothing) * velocity
        last = (frame.time_s, fixation)
        correction = fixation - frame.encoders_rad
        saccade = False
        if frame.end_s >= busy_until:
            if np.max(np.abs(correction[list(joints)])) > cfg.saccade_threshold_rad:
                # Aim where the target will be when the saccade lands (catch-up saccade).
                apply_at = frame.end_s + live.config.latency_s
                duration = 0.0
                for _ in range(2):
                    goal = fixation + velocity * (apply_at + duration - frame.time_s)
                    move = np.zeros(3)
                    move[list(joints)] = (goal - frame.encoders_rad)[list(joints)]
                    duration = _saccade_duration(move, live, cfg.saccade)
                live.send(_saccade_command(goal, duration, joints, cfg.saccade), frame)
                busy_until = apply_at + duration
                saccade = True
            else:
                live.send(_command(fixation, velocity, frame.time_s, joints), frame)
        records.append(
            FrameRecord(
                frame.time_s,
                True,
                offsets.error_px,
                offsets.estimate_world_m,
                frame.truth_target_world_m,
                frame.encoders_rad,
                fixation,
                saccade,
                uv,
            )
        )
        if on_frame is not None:
            on_frame(records[-1])
    else:
        ended = "frame limit"
    return PursuitRun(tuple(records), ended)


def acquire(
    live: LiveHead,
    servo: NeckServo,
    detector: Detector,
    knowledge: HeadKnowledge | None = None,
) -> GazeEstimator | None:
    """Fixate the target at rest with ``servo`` (the paper's Model 1 servo on the live
    head's :attr:`~LiveHead.head`) and keep its image Jacobian.

    The head is at rest (the target held where it is at the present time);
    the servo's probes and moves settle kinematically, as the at-rest
    procedures do.  None when the servo did not converge.  The estimator
    measures with ``knowledge``'s belief of the head's geometry, never the
    simulator's true one; the encoder resolution is the encoders'
    specification (counts per turn), known to the head exactly, as in the
    at-rest procedures.
    """
    head = live.head
    if servo.sim is not head:
        raise ValueError("acquire: servo must drive the live head's head (live.head)")
    knowledge = knowledge or HeadKnowledge()
    goals = (knowledge.reference(head, 1), knowledge.reference(head, 2))
    result = servo.run(detector, goals=(goals[0][0], goals[1][0], (goals[0][1] + goals[1][1]) / 2))
    if not result.converged or servo.jacobian is None:
        return None
    live.motors.sync()
    return GazeEstimator(
        servo.jacobian,
        head.settings.encoder_resolution_rad,  # a spec, not an imperfection (see above)
        goals,
        knowledge.head_belief(head),
        knowledge,
        knowledge.line_of_sight_offsets(head),
        neck_of(head.settings.head),
    )
