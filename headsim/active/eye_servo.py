"""Uncalibrated visual servoing of the eye motor from images alone: no focal
length, no principal point.

The eye servo drives the eye motor, in whole encoder steps, until the chosen
camera sees the target at a goal column (the image centre).  Its gain (px per
encoder step) is measured from the images: a probe move when nothing is known,
then secant (1-D Broyden) updates after every large enough move.  A gain
learnt on one target seeds the next.  Every loop is bounded and returns a
:class:`headsim.active.servo_types.ServoResult` that says why it ended.
"""

from __future__ import annotations

import math
from functools import partial

from headsim.active.events import ServoKind, ServoStep
from headsim.active.fixation_average import average_eye_crossing
from headsim.active.seen_pattern import SeenPattern, remembered
from headsim.active.servo_types import (
    Detector,
    ServoConfig,
    ServoOutcome,
    ServoResult,
)
from headsim.active.windows import (
    AloneFinder,
    alone_finder,
    expected_window,
    look_again,
    look_in_window,
    pattern_preview,
    pattern_window,
    pattern_windowed,
    preview_window,
    reporting,
    windowed,
)
from headsim.sim import names
from headsim.sim.events import EventSink
from headsim.sim.render import Window
from headsim.sim.simulator import HeadSim
from headsim.vision.detection import Detection, DetectionStatus


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
        #: Per camera, the last detection the window is predicted from (what the head
        #: saw and did, not whether the scene changed): (detector, eye steps, neck
        #: encoders, uv px, area px^2).
        self._seen: dict[
            int, tuple[object, int, tuple[float, float], tuple[float, float], float]
        ] = {}
        #: Per camera, the extent of the pattern last seen (None: a blob).
        self._extent: dict[int, tuple[float, float, float, float] | None] = {}
        #: Per camera, where the last detection puts its pattern (a board seen whole,
        #: then moved with each feature found alone); absent after a blob or a miss.
        self._pattern: dict[int, SeenPattern] = {}
        #: Cameras that saw the pattern whole in this fixation (``run`` begins one): only
        #: they look for a feature alone (the board may have moved by whole squares since).
        self._confirmed: set[int] = set()
        #: Binned previews rendered to place a window (see ``ServoConfig.preview_binning``).
        self.previews = 0
        #: Windows rendered, and windows that missed the target (a full frame followed).
        self.window_renders = 0
        self.window_misses = 0

    @property
    def step_range(self) -> tuple[int, int]:
        """Eye-motor range, whole encoder steps."""
        return self._step_range

    def observe(
        self, camera: int, detector: Detector, key: object = None, preview: bool = True
    ) -> Detection:
        """Render ``camera`` and detect the target in it (one render; more on a window miss).

        With windows on, and when this camera last saw the same target
        (``key``, default the detector) with the neck unchanged since and a
        gain known, only a window is rendered: around where the head expects
        the target from that detection and the eye steps moved since
        (u + gain * steps), of half-side 3 blob radii plus the margin and a
        quarter of the predicted motion (blob detectors only, see
        :data:`WINDOWED_DETECTORS`).  The detection there counts only if it
        is FOUND at least 3 blob radii + 2 px inside the window (so the blob
        and every piece the detector looks for beside it lie in the window)
        and, for a blob, with an area within ``AREA_CHANGE`` of the one seen;
        otherwise it is a miss (counted: the target moved, or something else is
        there), looked for again in a preview (:func:`look_again`), then in the
        same instant's full frame.  Never from the truth, nor from whether the
        scene changed: detections, gain, encoders.  A new target, or a
        pattern's feature after a move too long to find it alone, is first
        found in a binned preview; ``preview=False`` renders the full frame
        instead (a search's look).
        """
        key = detector if key is None else key
        sim, cfg = self.sim, self.config
        steps, neck = sim.eye_encoder_steps(), sim.neck_encoders()
        pattern = pattern_windowed(key)
        alone = alone_finder(key) if pattern else None
        if pattern:  # a pattern's features share their windows
            key = getattr(key, "window_key", key)
        window, spacing, whole = None, 0.0, False
        if pattern or windowed(key):
            window, spacing, whole = self._window(camera, key, steps, neck, alone)
        # A blob's window placed from the last sight of it: a guess the image confirms.
        guessed = self._seen[camera][4] if window is not None and not pattern else None
        looked = None
        if preview and alone is not None and not spacing and not whole:
            looked = self._pattern_preview(camera, key, detector, alone)
        if looked is not None:
            window, spacing = looked
        elif preview and window is None and not pattern and windowed(key):
            window = self._preview(camera, key, neck)
        detection = None
        found_alone: int | None = None  # the feature's index when found alone
        if window is not None:
            self.window_renders += 1
            look = partial(alone[1], spacing_px=spacing) if spacing and alone else detector
            detection = look_in_window(
                sim, camera, reporting(look, self.sink, camera, window), window, guessed
            )
            if detection is not None and spacing and alone:
                found_alone = alone[0]
            if detection is None:
                self.window_misses += 1
            if detection is None and guessed is not None and preview and cfg.preview_binning > 1:
                self.previews += 1
                report = partial(reporting, detector, self.sink, camera)
                detection, rendered = look_again(sim, camera, key, cfg, report)
                self.window_renders += rendered
                self.window_misses += rendered and detection is None
            if detection is None:
                # the same instant, whole
                detection = reporting(detector, self.sink, camera)(sim.retake(camera))
        if detection is None:
            detection = reporting(detector, self.sink, camera)(sim.render(camera))
        # Only blob detections (a centroid and an area) predict a window.
        if isinstance(detection, Detection) and detection.found and detection.uv is not None:
            if looked is not None or detection.pattern_uv is not None:
                self._confirmed.add(camera)  # the pattern seen whole (or its preview)
            self._seen[camera] = (key, steps, neck, detection.uv, detection.area_px)
            self._extent[camera] = detection.extent_px
            kept = remembered(self._pattern.get(camera), detection, found_alone)
            if kept is None:
                self._pattern.pop(camera, None)
            else:
                self._pattern[camera] = kept
                if found_alone is not None:  # the next whole-pattern window is its box
                    self._extent[camera] = kept.extent_from(detection.uv)
        else:
            self._seen.pop(camera, None)
            self._pattern.pop(camera, None)
            self._confirmed.discard(camera)
        return detection

    def _preview(self, camera: int, detector: object, neck: tuple[float, float]) -> Window | None:
        """A preview's window for ``detector``'s blob (see :func:`preview_window`) where no
        detection predicts where it is (a new target, or the neck moved since)."""
        seen = self._seen.get(camera)
        if not self.config.windows or self.config.preview_binning <= 1:
            return None
        if seen is not None and seen[0] == detector and seen[2] == neck:
            return None
        self.previews += 1
        return preview_window(self.sim, camera, detector, self.config)

    def _pattern_preview(
        self, camera: int, key: object, detector: Detector, alone: AloneFinder
    ) -> tuple[Window | None, float] | None:
        """After a move too long to find the feature ``alone`` looks for alone, where a
        binned preview puts it and the pattern's spacing there (:func:`pattern_preview`);
        None: no preview, or one that did not show the pattern (its window, as before)."""
        seen, kept = self._seen.get(camera), self._pattern.get(camera)
        if not self.config.windows or kept is None or seen is None or seen[0] != key:
            return None
        looked = pattern_preview(self.sim, camera, detector, kept, alone, self.config)
        if looked is not None:
            self.previews += 1
        if looked is None or looked[0] is None or looked[1] is None:
            return None
        self._pattern[camera] = looked[0]
        return looked[1], looked[0].spacing_px

    def _window(
        self,
        camera: int,
        key: object,
        steps: int,
        neck: tuple[float, float],
        alone: AloneFinder | None = None,
    ) -> tuple[Window | None, float, bool]:
        """Where to look for ``key``'s target in ``camera`` (None: the full frame), the
        pattern's spacing, px, when it is a feature looked for ``alone`` (else 0), and
        whether it is the whole pattern's window that tells the features apart first (in
        a new fixation): around where the last sight of the pattern puts it."""
        cfg, sim = self.config, self.sim
        seen, gain = self._seen.get(camera), self.gains.get(camera)
        if not cfg.windows or seen is None or gain is None:
            return None, 0.0, False
        seen_key, seen_steps, seen_neck, uv, area = seen
        if seen_key != key or seen_neck != neck:
            return None, 0.0, False
        motion = gain * (steps - seen_steps)
        kept, extent = self._pattern.get(camera), self._extent.get(camera)
        expected, margin, whole = (uv[0] + motion, uv[1]), cfg.window_margin_px, False
        if alone is not None and kept is not None and kept.expects_alone(alone[0], motion):
            if camera in self._confirmed:
                u, v = kept.features[alone[0]]
                spacing = kept.spacing_px
                window = pattern_window(
                    sim, camera, (u + motion, v), alone[2](spacing), motion, margin
                )
                return window, spacing if window is not None else 0.0, False
            whole = True  # a new fixation: the whole pattern first
        if extent is not None:  # a pattern: the whole of it
            window = pattern_window(sim, camera, expected, extent, motion, margin)
            return window, 0.0, whole and window is not None
        return expected_window(sim, camera, expected, area, motion, margin), 0.0, False

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
        length, at most ``max_retreats`` times.  Once converged, the sub-step
        fixation may be averaged over images around the crossing (see
        ``ServoConfig.average_fixation``).  Without ``first`` a new fixation begins: a
        pattern is seen whole again before its features are looked for alone.
        """
        if first is None:
            self._confirmed.clear()
        goal = self.sim.camera_settings(camera).image_centre[0] if goal_u is None else goal_u
        result = self._servo(camera, detector, goal, first)
        if result.converged:
            result = average_eye_crossing(self, camera, detector, goal, result)
        return result

    def _servo(
        self, camera: int, detector: Detector, goal: float, first: Detection | None
    ) -> ServoResult:
        """The servo proper: whole-step moves until u is within tolerance of ``goal``."""
        sim, cfg = self.sim, self.config
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
                        ServoOutcome.TARGET_LOST, target, None, goal, iteration, camera, gain,
                        lost=detection.status,
                    )  # fmt: skip
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
        path = tuple(self._path)
        return ServoResult(
            outcome, steps, uv, residual, gain, subpixel, self._renders, iterations, lost, path,
            self._retreats,
        )  # fmt: skip


__all__ = ["EyeServo"]
