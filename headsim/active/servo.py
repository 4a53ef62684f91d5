"""Uncalibrated visual servoing from images alone: no focal length, no principal point.

The eye servo drives the eye motor, in whole encoder steps, until the chosen
camera sees the target at a goal column (the image centre).  Its gain (px per
encoder step) is measured from the images: a probe move when nothing is known,
then secant (1-D Broyden) updates after every large enough move.  A gain
learnt on one target seeds the next.  Every loop is bounded and returns a
:class:`ServoResult` that says why it ended.
"""

from __future__ import annotations

import enum
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from headsim.active.events import Detected, ServoKind, ServoStep
from headsim.sim import names
from headsim.sim.events import EventSink
from headsim.sim.render import Window
from headsim.sim.simulator import HeadSim
from headsim.vision.detect import Detection, DetectionStatus, find_marker

Detector = Callable[[np.ndarray], Detection]

#: Detectors (or the functions that partials of them wrap) that find their target
#: in a window: a blob's centroid, decided by the blob and what lies within one blob
#: size of it.  Others (a whole chessboard, a cross point) always see full frames.
WINDOWED_DETECTORS: set[Callable[..., object]] = {find_marker}


def windowed(detector: object) -> bool:
    """Whether ``detector`` (possibly a ``functools.partial``) may look at windows."""
    while isinstance(detector, functools.partial):
        detector = detector.func
    return detector in WINDOWED_DETECTORS


def pattern_windowed(detector: object) -> bool:
    """Whether ``detector`` finds a feature as part of a pattern it reports the extent of
    (``Detection.extent_px``) and names by a ``window_key`` shared by the pattern's features."""
    while isinstance(detector, functools.partial):
        detector = detector.func
    return getattr(detector, "window_key", None) is not None


def reporting(
    detector: Detector, sink: EventSink, camera: int, window: Window | None = None
) -> Detector:
    """``detector``, reporting to ``sink`` each detection it makes in camera ``camera``'s
    image (:class:`headsim.active.events.Detected`; in a ``window``, its offset added)."""

    def detect(image: np.ndarray) -> Detection:
        detection = detector(image)
        uv = detection.uv if detection.found else None
        if uv is not None and window is not None:  # in the full frame's pixels
            uv = (uv[0] + window.x0, uv[1] + window.y0)
        sink.emit(Detected(camera, detection.status, uv))
        return detection

    return detect


def pattern_window(
    sim: HeadSim,
    camera: int,
    expected_uv: tuple[float, float],
    extent_px: tuple[float, float, float, float],
    motion_px: float,
    margin_px: float,
) -> Window | None:
    """The window to look for a pattern of ``extent_px`` around ``expected_uv`` after an
    image motion of ``motion_px``: the extent plus the margin and a quarter of the motion
    on every side.  None where it would be barely cheaper than the frame."""
    settings = sim.camera_settings(camera)
    grow = margin_px + 0.25 * abs(motion_px)
    u, v = expected_uv
    left, top, right, bottom = extent_px
    x0 = max(math.floor(u + left - grow), 0)
    y0 = max(math.floor(v + top - grow), 0)
    x1 = min(math.ceil(u + right + grow) + 1, settings.width)
    y1 = min(math.ceil(v + bottom + grow) + 1, settings.height)
    if x1 <= x0 or y1 <= y0 or (x1 - x0) * (y1 - y0) >= 0.5 * settings.width * settings.height:
        return None
    return Window(int(x0), int(y0), int(x1 - x0), int(y1 - y0))


def expected_window(
    sim: HeadSim,
    camera: int,
    expected_uv: tuple[float, float],
    area_px: float,
    motion_px: float,
    margin_px: float,
) -> Window | None:
    """The window to look for a blob of ``area_px`` expected at ``expected_uv`` after an
    image motion of ``motion_px``: half-side 3 blob radii + margin + a quarter of the
    motion.  None where it would be barely cheaper than the frame."""
    half = 3.0 * math.sqrt(area_px / math.pi) + margin_px + 0.25 * abs(motion_px)
    settings = sim.camera_settings(camera)
    window = Window.around(expected_uv, half, (settings.width, settings.height))
    if window.width * window.height >= 0.5 * settings.width * settings.height:
        return None
    return window


def preview_window(
    sim: HeadSim, camera: int, detector: object, config: ServoConfig
) -> Window | None:
    """Render a preview of ``camera``'s whole view binned ``config.preview_binning`` x
    ``config.preview_binning`` and return the window where it shows the blob, or None
    (not found, or a window barely cheaper than the frame: a full frame follows)."""
    b = config.preview_binning
    assert callable(detector)
    seen = detector(sim.render_preview(camera, b))
    if not isinstance(seen, Detection) or not seen.found or seen.uv is None:
        return None
    # Binned pixel i covers pixels b i .. b i + b - 1; its position is good to about b px.
    offset = (b - 1) / 2.0
    uv = (b * seen.uv[0] + offset, b * seen.uv[1] + offset)
    return expected_window(sim, camera, uv, b * b * seen.area_px, 4.0 * b, config.window_margin_px)


def look_in_window(
    sim: HeadSim, camera: int, detector: Detector, window: Window
) -> Detection | None:
    """Render ``window`` and detect there: the detection in full-frame pixels, or None (a miss).

    It counts only if FOUND at least 3 blob radii + 2 px inside the window, so
    that the blob and every piece the detector looks for beside it (within one
    blob size) lie in the window: then the full frame gives the same answer.
    """
    seen = detector(sim.render_window(camera, window))
    if not seen.found or seen.uv is None:
        return None
    u, v = seen.uv[0] + window.x0, seen.uv[1] + window.y0
    if seen.extent_px is not None:
        # A pattern counts only if all of it lies 2 px inside the window, or runs
        # off a side where the window's edge is the image's (the full frame ends there too).
        left, top, right, bottom = seen.extent_px
        settings = sim.camera_settings(camera)
        if (
            (window.x0 == 0 or window.x0 + 2 <= u + left)
            and (window.x1 == settings.width or u + right <= window.x1 - 3)
            and (window.y0 == 0 or window.y0 + 2 <= v + top)
            and (window.y1 == settings.height or v + bottom <= window.y1 - 3)
        ):
            return Detection(DetectionStatus.FOUND, (u, v), seen.area_px, seen.extent_px)
        return None
    inset = 3.0 * math.sqrt(seen.area_px / math.pi) + 2.0
    if (
        window.x0 + inset <= u <= window.x1 - 1 - inset
        and window.y0 + inset <= v <= window.y1 - 1 - inset
    ):
        return Detection(DetectionStatus.FOUND, (u, v), seen.area_px)
    return None


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
    interpolated with the gain (the image tells more than the encoder);
    ``renders``: images taken; ``iterations``: moves made.  ``lost_status``:
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


class EyeServo:
    """Servo the eye motor so that one camera's target column reaches a goal u."""

    def __init__(
        self, sim: HeadSim, config: ServoConfig | None = None, sink: EventSink | None = None
    ) -> None:
        self.sim = sim
        self.config = config or ServoConfig()
        #: Where detections and moves are reported (None: the simulator's sink).
        self.sink = sim.sink if sink is None else sink
        low, high = sim.joint_range(names.EYE_MOTOR_JOINT)
        resolution = sim.settings.encoder_resolution_rad
        self._step_range = (math.ceil(low / resolution), math.floor(high / resolution))
        #: Gain per camera, px per encoder step, carried from one target to the next.
        self.gains: dict[int, float] = {}
        #: Per camera, the last detection the window is predicted from:
        #: (detector, eye steps, neck encoders, placements, uv px, area px^2).
        self._seen: dict[
            int, tuple[object, int, tuple[float, float], int, tuple[float, float], float]
        ] = {}
        #: Per camera, the extent of the pattern last seen (None: a blob).
        self._extent: dict[int, tuple[float, float, float, float] | None] = {}
        #: Binned previews rendered to place a window (see ``ServoConfig.preview_binning``).
        self.previews = 0
        #: Windows rendered, and windows that missed the target (a full frame followed).
        self.window_renders = 0
        self.window_misses = 0

    @property
    def step_range(self) -> tuple[int, int]:
        """Eye-motor range, whole encoder steps."""
        return self._step_range

    def observe(self, camera: int, detector: Detector, key: object = None) -> Detection:
        """Render ``camera`` and detect the target in it (one render, two on a window miss).

        With windows on, and when this camera last saw the same target
        (``key``, default the detector) with the neck and the scene unchanged
        since and a gain known, only a window is rendered: around where the
        head expects the target from that detection and the eye steps moved
        since (u + gain * steps), of half-side 3 blob radii plus the margin
        and a quarter of the predicted motion (blob detectors only, see
        :data:`WINDOWED_DETECTORS`).  The detection there counts
        only if it is FOUND at least 3 blob radii + 2 px inside the window
        (so the blob and every piece the detector looks for beside it lie in
        the window); otherwise the window is a miss (counted) and a full
        frame is rendered.  Never from the truth: detections, gain, encoders.
        """
        key = detector if key is None else key
        sim = self.sim
        steps, neck = sim.eye_encoder_steps(), sim.neck_encoders()
        pattern = pattern_windowed(key)
        if pattern:  # a pattern's features share their windows
            key = getattr(key, "window_key", key)
        window = self._window(camera, key, steps, neck) if pattern or windowed(key) else None
        if window is None and not pattern and windowed(key) and self._unseen(camera, key, neck):
            window = self._preview(camera, key)
        detection = None
        if window is not None:
            self.window_renders += 1
            detection = look_in_window(
                sim, camera, reporting(detector, self.sink, camera, window), window
            )
            if detection is None:
                self.window_misses += 1
                # the same instant, whole
                detection = reporting(detector, self.sink, camera)(sim.retake(camera))
        if detection is None:
            detection = reporting(detector, self.sink, camera)(sim.render(camera))
        # Only blob detections (a centroid and an area) predict a window.
        if isinstance(detection, Detection) and detection.found and detection.uv is not None:
            self._seen[camera] = (key, steps, neck, sim.placements, detection.uv, detection.area_px)
            self._extent[camera] = detection.extent_px
        else:
            self._seen.pop(camera, None)
        return detection

    def _unseen(self, camera: int, key: object, neck: tuple[float, float]) -> bool:
        """Whether no detection of ``key``'s target predicts where it is (a new target,
        one moved, or the neck moved since): a preview may find it."""
        seen = self._seen.get(camera)
        return seen is None or seen[0] != key or seen[2] != neck or seen[3] != self.sim.placements

    def _preview(self, camera: int, detector: object) -> Window | None:
        """A preview's window for ``detector``'s blob (see :func:`preview_window`)."""
        if not self.config.windows or self.config.preview_binning <= 1:
            return None
        self.previews += 1
        return preview_window(self.sim, camera, detector, self.config)

    def _window(
        self, camera: int, key: object, steps: int, neck: tuple[float, float]
    ) -> Window | None:
        """Where to look for ``key``'s target in ``camera``, or None for the full frame."""
        cfg, sim = self.config, self.sim
        seen, gain = self._seen.get(camera), self.gains.get(camera)
        if not cfg.windows or seen is None or gain is None:
            return None
        seen_key, seen_steps, seen_neck, placements, uv, area = seen
        if seen_key != key or seen_neck != neck or placements != sim.placements:
            return None
        motion = gain * (steps - seen_steps)
        extent = self._extent.get(camera)
        if extent is not None:
            return pattern_window(
                sim, camera, (uv[0] + motion, uv[1]), extent, motion, cfg.window_margin_px
            )
        return expected_window(
            sim, camera, (uv[0] + motion, uv[1]), area, motion, cfg.window_margin_px
        )

    def run(
        self,
        camera: int,
        detector: Detector,
        goal_u: float | None = None,
        first: Detection | None = None,
    ) -> ServoResult:
        """Drive the eye motor until ``camera`` sees the target at ``goal_u`` (image centre).

        ``first``: a detection already made at the current eye position (saves
        a render).  A move after which the target is gone is undone (back to
        the last step that saw it, no render needed) and retried at half the
        length, at most ``max_retreats`` times.
        """
        sim, cfg = self.sim, self.config
        goal = sim.camera_settings(camera).image_centre[0] if goal_u is None else goal_u
        self._renders = 0
        steps = sim.eye_encoder_steps()
        if first is None:
            first = self.observe(camera, detector)
            self._renders += 1
        self._path: list[tuple[int, float, float]] = []
        self._retreats = 0
        if not first.found or first.uv is None:
            return self._result(
                ServoOutcome.TARGET_LOST, steps, None, goal, 0, camera, lost=first.status
            )
        visited: dict[int, tuple[float, float]] = {steps: first.uv}
        self._path.append((steps, *first.uv))
        uv = first.uv
        gain = self.gains.get(camera)
        probe = cfg.probe_steps
        damping = 1.0
        for iteration in range(1, cfg.max_iterations + 1):
            error = uv[0] - goal
            if gain is not None and abs(error) <= max(cfg.tolerance_px, 0.5 * abs(gain)):
                return self._result(
                    ServoOutcome.CONVERGED, steps, uv, goal, iteration - 1, camera, gain
                )
            if gain is None:
                move = probe if steps + probe <= self._step_range[1] else -probe
                move = round(move * damping) or (1 if move > 0 else -1)
            else:
                move = round(-damping * error / gain) or (-1 if error / gain > 0 else 1)
            target = steps + move
            if not self._step_range[0] <= target <= self._step_range[1]:
                return self._result(
                    ServoOutcome.JOINT_LIMIT, steps, uv, goal, iteration - 1, camera, gain
                )
            if target in visited:
                # Revisiting a step (pixel locking between neighbours): the best
                # visited step is as close as whole steps get.
                best = min(visited, key=lambda s: abs(visited[s][0] - goal))
                if best != steps:
                    sim.command_eye_steps(best)
                    sim.settle()
                return self._result(
                    ServoOutcome.CONVERGED, best, visited[best], goal, iteration, camera, gain
                )
            sim.command_eye_steps(target)
            sim.settle()
            detection = self.observe(camera, detector)
            self._renders += 1
            self.sink.emit(
                ServoStep(
                    ServoKind.EYE,
                    iteration,
                    (target,),
                    None
                    if not detection.found or detection.uv is None
                    else (detection.uv[0] - goal,),
                )
            )
            if not detection.found or detection.uv is None:
                if self._retreats >= cfg.max_retreats or abs(move) <= 1:
                    return self._result(
                        ServoOutcome.TARGET_LOST,
                        target,
                        None,
                        goal,
                        iteration,
                        camera,
                        gain,
                        lost=detection.status,
                    )
                # Re-acquire: back to the last step that saw it, then a shorter move.
                self._retreats += 1
                damping *= 0.5
                sim.command_eye_steps(steps)
                sim.settle()
                continue
            change = detection.uv[0] - uv[0]
            if gain is None:
                if abs(change) >= cfg.min_probe_px:
                    gain = change / move
                else:
                    probe *= 4
            elif abs(move) >= cfg.min_secant_steps and change != 0.0:
                gain = change / move
            if gain is not None:
                self.gains[camera] = gain  # what the next window is predicted with
            steps, uv = target, detection.uv
            visited[steps] = uv
            self._path.append((steps, *uv))
        # The last move may have landed within tolerance: that is converged.
        done = gain is not None and abs(uv[0] - goal) <= max(cfg.tolerance_px, 0.5 * abs(gain))
        outcome = ServoOutcome.CONVERGED if done else ServoOutcome.ITERATION_LIMIT
        return self._result(outcome, steps, uv, goal, cfg.max_iterations, camera, gain)

    def _result(
        self,
        outcome: ServoOutcome,
        steps: int,
        uv: tuple[float, float] | None,
        goal: float,
        iterations: int,
        camera: int,
        gain: float | None = None,
        lost: DetectionStatus | None = None,
    ) -> ServoResult:
        if gain is not None:
            self.gains[camera] = gain
        residual = math.nan if uv is None else uv[0] - goal
        subpixel = float(steps) if gain is None or uv is None else steps - residual / gain
        return ServoResult(
            outcome,
            steps,
            uv,
            residual,
            gain,
            subpixel,
            self._renders,
            iterations,
            lost,
            tuple(self._path),
            self._retreats,
        )


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

    @property
    def converged(self) -> bool:
        return self.outcome is ServoOutcome.CONVERGED

    @property
    def residual_px(self) -> float:
        """Largest |error| component, px."""
        return float(np.max(np.abs(self.error_px)))


class NeckServo:
    """Model 1's fixation: neck pitch puts P in the plane of the optical axes, neck
    yaw and the eye motor put it on both goal columns (Sec. II-B), from images only.

    Errors e = (u1 - u10, u2 - u20, (v1 + v2)/2 - v0) are driven to zero by
    whole-step moves of (yaw, pitch, eye) with a Jacobian measured by probing
    each joint once, then updated by Broyden's rule; it is kept for the next
    fixation (tracking).
    """

    JOINTS = (names.NECK_YAW, names.NECK_PITCH, names.EYE_MOTOR_JOINT)

    def __init__(
        self, sim: HeadSim, config: ServoConfig | None = None, sink: EventSink | None = None
    ) -> None:
        self.sim = sim
        self.config = config or ServoConfig()
        #: Where detections and moves are reported (None: the simulator's sink).
        self.sink = sim.sink if sink is None else sink
        resolution = sim.settings.encoder_resolution_rad
        self._ranges = [
            (math.ceil(lo / resolution), math.floor(hi / resolution))
            for lo, hi in (sim.joint_range(j) for j in self.JOINTS)
        ]
        self.jacobian: np.ndarray | None = None
        #: The last images' detections the windows are predicted from:
        #: (detector, steps, placements, ((u, v), area) per camera), and the count
        #: of windows rendered and missed (see :meth:`EyeServo.observe`).
        self._seen: (
            tuple[object, tuple[int, ...], int, list[tuple[tuple[float, float], float]]] | None
        ) = None
        self.window_renders = 0
        self.window_misses = 0
        self.previews = 0
        self._key: object = None
        self._current: np.ndarray | None = None  # the Jacobian as the run stands

    def _steps(self) -> np.ndarray:
        resolution = self.sim.settings.encoder_resolution_rad
        yaw, pitch = (round(a / resolution) for a in self.sim.neck_encoders())
        return np.array([yaw, pitch, self.sim.eye_encoder_steps()])

    def _move(self, steps: np.ndarray) -> None:
        resolution = self.sim.settings.encoder_resolution_rad
        yaw, pitch, eye = (float(s) * resolution for s in steps)
        self.sim.command(neck_yaw=yaw, neck_pitch=pitch, eye=eye)
        self.sim.settle()

    def _error(self, detector: Detector, goals: np.ndarray) -> np.ndarray | None:
        seen = [self._look(camera, detector) for camera in (1, 2)]
        steps = tuple(int(s) for s in self._steps())
        if all(isinstance(s, Detection) and s.found and s.uv is not None for s in seen):
            self._seen = (self._key, steps, self.sim.placements, [(s.uv, s.area_px) for s in seen])  # type: ignore[misc]
        else:
            self._seen = None
        for camera, s in enumerate(seen, start=1):
            if not s.found or s.uv is None:
                self._lost = (camera, s.status)
                return None
        (u1, v1), (u2, v2) = seen[0].uv, seen[1].uv  # type: ignore[misc]
        return np.array([u1, u2, (v1 + v2) / 2]) - goals

    def _look(self, camera: int, detector: Detector) -> Detection:
        """Detect in ``camera``: in a window around where the last images and the
        Jacobian put the target (same target, scene unchanged, blob detector), else
        in the full frame; a miss costs the full frame and is counted."""
        sim, seen = self.sim, self._seen
        jac = self._current
        if (
            self.config.windows
            and seen is not None
            and jac is not None
            and seen[0] is self._key
            and seen[2] == sim.placements
            and windowed(self._key)
        ):
            move = self._steps() - np.array(seen[1])
            du1, du2, dv = jac @ move
            (u, v), area = seen[3][camera - 1]
            du = du1 if camera == 1 else du2
            window = expected_window(
                sim,
                camera,
                (u + du, v + dv),
                area,
                max(abs(du), abs(dv)),
                self.config.window_margin_px,
            )
            if window is not None:
                return self._look_in(window, camera, detector)
        elif (
            self.config.windows
            and self.config.preview_binning > 1
            and windowed(self._key)
            and (seen is None or seen[0] is not self._key or seen[2] != sim.placements)
        ):
            # A new or moved target: find it in a preview, then render its window.
            self.previews += 1
            window = preview_window(sim, camera, self._key, self.config)
            if window is not None:
                return self._look_in(window, camera, detector)
        return reporting(detector, self.sink, camera)(sim.render(camera))

    def _look_in(self, window: Window, camera: int, detector: Detector) -> Detection:
        """Detect in a rendered window; a miss costs the same instant's whole frame."""
        self.window_renders += 1
        detection = look_in_window(
            self.sim, camera, reporting(detector, self.sink, camera, window), window
        )
        if detection is not None:
            return detection
        self.window_misses += 1
        return reporting(detector, self.sink, camera)(self.sim.retake(camera))

    def _in_range(self, steps: np.ndarray) -> bool:
        return all(lo <= s <= hi for s, (lo, hi) in zip(steps, self._ranges, strict=True))

    @property
    def step_ranges(self) -> tuple[tuple[int, int], ...]:
        """(low, high) encoder steps of neck yaw, neck pitch and the eye motor."""
        return tuple(self._ranges)

    def steps(self) -> tuple[int, int, int]:
        """The encoders' (neck yaw, neck pitch, eye) now, whole steps."""
        yaw, pitch, eye = (int(s) for s in self._steps())
        return yaw, pitch, eye

    def look_from(self, steps: tuple[int, int, int], detector: Detector) -> bool:
        """Move to ``steps`` and look with both cameras (two renders): both see it whole.

        Whole frames, no window or preview: a search's look is keyed to no earlier
        detection (as the runner's servo has always looked, its detector wrapped).
        """
        self._key = None
        self._move(np.asarray(steps))
        seen = [self._look(camera, detector) for camera in (1, 2)]
        return all(d.found and d.uv is not None for d in seen)

    def run(
        self,
        detector: Detector,
        goals: tuple[float, float, float] | None = None,
        key: object = None,
    ) -> NeckServoResult:
        """Fixate the target with neck and eyes; ``goals`` = (u10, u20, v0), default image centres.

        ``key``: what identifies the target for windows (default the detector).
        """
        cfg, sim = self.config, self.sim
        self._key = detector if key is None else key
        self._current = self.jacobian
        if goals is None:
            (u10, v10), (u20, v20) = (sim.camera_settings(c).image_centre for c in (1, 2))
            goals = (u10, u20, (v10 + v20) / 2)
        goal = np.asarray(goals, dtype=float)
        start = sim.render_count
        self._lost: tuple[int, DetectionStatus] | None = None
        self._retreats = 0
        steps = self._steps()
        error = self._error(detector, goal)
        if error is None:
            return self._result(ServoOutcome.TARGET_LOST, steps, None, start, 0)
        jac = self.jacobian
        if jac is None:
            jac = np.zeros((3, 3))
            for joint in range(3):
                probe = np.zeros(3, dtype=int)
                probe[joint] = cfg.probe_steps * 4
                moved = steps + probe if self._in_range(steps + probe) else steps - probe
                self._move(moved)
                probed = self._error(detector, goal)
                if probed is None:
                    self._move(steps)
                    return self._result(ServoOutcome.TARGET_LOST, steps, None, start, joint + 1)
                jac[:, joint] = (probed - error) / (moved - steps)[joint]
            self._move(steps)
            self._current = jac
        visited: dict[tuple[int, ...], np.ndarray] = {tuple(steps): error}
        damping = 1.0
        for iteration in range(1, cfg.max_iterations + 1):
            tolerance = np.maximum(cfg.tolerance_px, 0.5 * np.abs(jac).max(axis=1))
            if np.all(np.abs(error) <= tolerance):
                self.jacobian = jac
                return self._result(ServoOutcome.CONVERGED, steps, error, start, iteration - 1, jac)
            move = np.rint(-damping * np.linalg.solve(jac, error)).astype(int)
            if not move.any():
                move[int(np.argmax(np.abs(error)))] = 1
            target = steps + move
            if not self._in_range(target):
                self.jacobian = jac
                return self._result(
                    ServoOutcome.JOINT_LIMIT, steps, error, start, iteration - 1, jac
                )
            if tuple(target) in visited:
                best = min(visited, key=lambda s: float(np.max(np.abs(visited[s]) / tolerance)))
                self._move(np.array(best))
                self.jacobian = jac
                return self._result(
                    ServoOutcome.CONVERGED, np.array(best), visited[best], start, iteration, jac
                )
            self._move(target)
            new_error = self._error(detector, goal)
            self.sink.emit(
                ServoStep(
                    ServoKind.NECK,
                    iteration,
                    tuple(int(s) for s in target),
                    None if new_error is None else tuple(float(e) for e in new_error),
                )
            )
            if new_error is None:
                if self._retreats >= cfg.max_retreats or np.abs(move).max() <= 1:
                    return self._result(
                        ServoOutcome.TARGET_LOST, target, None, start, iteration, jac
                    )
                # Re-acquire: back to the last pose both cameras saw it, then a shorter move.
                self._retreats += 1
                damping *= 0.5
                self._move(steps)
                continue
            if np.abs(move).max() >= cfg.min_secant_steps:
                dq = move.astype(float)
                jac = jac + np.outer(new_error - error - jac @ dq, dq) / (dq @ dq)
                self._current = jac
            steps, error = target, new_error
            visited[tuple(steps)] = error
        self.jacobian = jac
        tolerance = np.maximum(cfg.tolerance_px, 0.5 * np.abs(jac).max(axis=1))
        done = bool(np.all(np.abs(error) <= tolerance))
        outcome = ServoOutcome.CONVERGED if done else ServoOutcome.ITERATION_LIMIT
        return self._result(outcome, steps, error, start, cfg.max_iterations, jac)

    def _result(
        self,
        outcome: ServoOutcome,
        steps: np.ndarray,
        error: np.ndarray | None,
        start: int,
        iterations: int,
        jac: np.ndarray | None = None,
    ) -> NeckServoResult:
        whole = tuple(int(s) for s in steps)
        if error is None:
            err = (math.nan,) * 3
            sub = tuple(float(s) for s in whole)
        else:
            err = tuple(float(e) for e in error)
            sub = tuple(
                float(s)
                for s in (steps - np.linalg.solve(jac, error) if jac is not None else steps)
            )
        lost = self._lost if outcome is ServoOutcome.TARGET_LOST else None
        return NeckServoResult(
            outcome,
            whole,
            err,  # type: ignore[arg-type]
            sub,  # type: ignore[arg-type]
            jac,
            self.sim.render_count - start,
            iterations,
            None if lost is None else lost[0],
            None if lost is None else lost[1],
            self._retreats,
        )
