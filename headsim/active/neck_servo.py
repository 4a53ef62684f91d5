"""Model 1's fixation servo: neck yaw, neck pitch and the eye motor together,
from images alone, with an image Jacobian measured by probing and updated by
Broyden's rule (kept for the next fixation).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from headsim.active.events import ServoKind, ServoStep
from headsim.active.eye_servo import pixel_period_steps
from headsim.active.look import Anew, Around, Hint, Looker, finds_blob
from headsim.active.servo_types import (
    Detector,
    NeckServoResult,
    ServoConfig,
    ServoOutcome,
)
from headsim.head.servo_head import ServoHead
from headsim.sim.events import EventSink
from headsim.vision.detection import Detection, DetectionStatus


class NeckServo:
    """Model 1's fixation: neck pitch puts P in the plane of the optical axes, neck
    yaw and the eye motor put it on both goal columns (Sec. II-B), from images only.

    Errors e = (u1 - u10, u2 - u20, (v1 + v2)/2 - v0) are driven to zero by
    whole-step moves of (yaw, pitch, eye) with a Jacobian measured by probing
    each joint once, then updated by Broyden's rule; it is kept for the next
    fixation (tracking).
    """

    JOINTS = ("neck_yaw", "neck_pitch", "eye")

    def __init__(
        self,
        sim: ServoHead,
        config: ServoConfig | None = None,
        sink: EventSink | None = None,
        motors: tuple[str, str, str] = JOINTS,
    ) -> None:
        #: The three motors it drives, in the order of ``steps``: Model 1's neck yaw,
        #: pitch and eye motor, or a one-step fixation's two eyes and the pitch.
        self.motors = motors
        self.sim = sim
        self.config = config or ServoConfig()
        #: Where detections and moves are reported (None: the simulator's sink).
        self.sink = sim.sink if sink is None else sink
        resolution = sim.settings.encoder_resolution_rad
        self._ranges = [
            (math.ceil(lo / resolution), math.floor(hi / resolution))
            for lo, hi in (sim.joint_range(j) for j in self.motors)
        ]
        self.jacobian: np.ndarray | None = None
        #: The last images' detections the windows are predicted from:
        #: (detector, steps, ((u, v), area) per camera).  Only what the head saw
        #: and moved: whether the scene changed since, its next images tell.
        self._seen: (
            tuple[object, tuple[int, ...], list[tuple[tuple[float, float], float]]] | None
        ) = None
        #: Where the servo looks (windows, previews; see :class:`~headsim.active.look.Looker`).
        self.looker = Looker(sim, self.config, self.sink)
        #: Where the target was lost in the current run: (camera, what the detector said).
        self._lost: tuple[int, DetectionStatus] | None = None
        self._key: object = None
        self._current: np.ndarray | None = None  # the Jacobian as the run stands
        self._goals = np.zeros(3)

    def _steps(self) -> np.ndarray:
        if self.motors != self.JOINTS:
            return np.array([self.sim.encoder_steps(m) for m in self.motors])
        resolution = self.sim.settings.encoder_resolution_rad
        yaw, pitch = (round(a / resolution) for a in self.sim.neck_encoders())
        return np.array([yaw, pitch, self.sim.eye_encoder_steps()])

    def _move(self, steps: np.ndarray) -> None:
        resolution = self.sim.settings.encoder_resolution_rad
        angles = {m: float(s) * resolution for m, s in zip(self.motors, steps, strict=True)}
        self.sim.command(**angles)
        self.sim.settle()

    def _looks(self, detector: Detector) -> list[Detection]:
        """Camera 1's detection, then camera 2's only if camera 1 saw the target
        (one render saved where the first image already says it is lost)."""
        seen = [self._look(1, detector)]
        if seen[0].found and seen[0].uv is not None:
            seen.append(self._look(2, detector))
        return seen

    def _error(self, detector: Detector, goals: np.ndarray) -> np.ndarray | None:
        seen = self._looks(detector)
        steps = tuple(int(s) for s in self._steps())
        if len(seen) == 2 and all(s.found and s.uv is not None for s in seen):
            self._seen = (self._key, steps, [(s.uv, s.area_px) for s in seen])  # type: ignore[misc]
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
        Jacobian put the target (same target, blob detector), else (a new target, or no
        Jacobian yet: its probes) in a preview's window, the full frame where that window
        misses (see :class:`~headsim.active.look.Looker`)."""
        return self.looker.look(camera, detector, self._hint(camera))

    def _hint(self, camera: int) -> Hint:
        """Where the last images and the Jacobian put the target in ``camera``, if they do;
        else a look anew."""
        seen, jac = self._seen, self._current
        if self.config.windows and seen is not None and jac is not None and seen[0] is self._key:
            move = self._steps() - np.array(seen[1])
            du1, du2, dv = jac @ move
            (u, v), area = seen[2][camera - 1]
            du = du1 if camera == 1 else du2
            return Around(self._key, (u + du, v + dv), area, max(abs(du), abs(dv)))
        return Anew(self._key)

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
        """Move to ``steps`` and look with both cameras (two renders; one where camera 1
        does not see it): both see it whole.

        Whole frames, no window or preview: a search's look is keyed to no earlier
        detection (as the runner's servo has always looked, its detector wrapped).
        """
        self._key = None
        self._move(np.asarray(steps))
        seen = self._looks(detector)
        return len(seen) == 2 and all(d.found and d.uv is not None for d in seen)

    def run(
        self,
        detector: Detector,
        goals: tuple[float, float, float] | None = None,
        key: object = None,
    ) -> NeckServoResult:
        """Fixate the target with neck and eyes; ``goals`` = (u10, u20, v0), default image centres.

        ``key``: what identifies the target for windows (default the detector).
        Once converged, the sub-step fixation is averaged over poses around it
        (see :meth:`_average_crossing`).
        """
        result = self._servo(detector, goals, key)
        if result.converged:
            result = self._average_crossing(detector, result)
        return result

    def _average_crossing(self, detector: Detector, result: NeckServoResult) -> NeckServoResult:
        """Average the sub-step fixation over eye steps whose images spread both cameras'
        columns evenly over one pixel around the goals (the eye servo's rule, see
        ``ServoConfig.average_fixation``; two renders a pose); back to ``result.steps``."""
        cfg, sim, jac = self.config, self.sim, result.jacobian
        if self.motors != self.JOINTS:  # one eye motor to spread the columns over: Model 1's
            return result
        if not cfg.average_fixation or jac is None or not finds_blob(self._key):
            return result
        gain = float(np.max(np.abs(jac[:2, 2])))  # px per eye step in the faster camera
        if gain == 0.0:
            return result
        start = sim.render_count
        whole = np.array(result.steps)
        final_error = np.array(result.error_px)  # image minus goals at `whole`
        eyes = pixel_period_steps(result.subpixel_steps[2], gain, cfg.max_fixation_samples)
        subs = []
        for eye in eyes:  # bounded: at most max_fixation_samples poses
            pose = np.array([whole[0], whole[1], eye])
            if not self._in_range(pose):
                continue
            error = final_error
            if eye != whole[2]:
                self._move(pose)
                seen = self._error(detector, self._goals)
                if seen is None:
                    break  # the averaging is bounded by what the images show
                error = seen
            subs.append(pose - np.linalg.solve(jac, error))
        self._move(whole)
        renders = result.renders + sim.render_count - start
        if len(subs) < 2:
            return replace(result, renders=renders)
        mean_yaw, mean_pitch, mean_eye = (float(x) for x in np.mean(subs, axis=0))
        return replace(
            result,
            subpixel_steps=(mean_yaw, mean_pitch, mean_eye),
            renders=renders,
            fixation_samples=len(subs),
        )

    def _servo(
        self, detector: Detector, goals: tuple[float, float, float] | None, key: object
    ) -> NeckServoResult:
        """The servo proper: whole-step moves until the errors are within tolerance."""
        cfg, sim = self.config, self.sim
        self._key = detector if key is None else key
        self._current = self.jacobian
        if goals is None:
            (u10, v10), (u20, v20) = (sim.camera_settings(c).image_centre for c in (1, 2))
            goals = (u10, u20, (v10 + v20) / 2)
        goal = np.asarray(goals, dtype=float)
        self._goals = goal
        start = sim.render_count
        self._lost = None
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
        yaw, pitch, eye = (int(s) for s in steps)
        whole = (yaw, pitch, eye)
        if error is None:
            err = (math.nan, math.nan, math.nan)
            sub = (float(yaw), float(pitch), float(eye))
        else:
            e1, e2, e3 = (float(e) for e in error)
            err = (e1, e2, e3)
            s1, s2, s3 = (
                float(s)
                for s in (steps - np.linalg.solve(jac, error) if jac is not None else steps)
            )
            sub = (s1, s2, s3)
        lost = self._lost if outcome is ServoOutcome.TARGET_LOST else None
        return NeckServoResult(
            outcome,
            whole,
            err,
            sub,
            jac,
            self.sim.render_count - start,
            iterations,
            None if lost is None else lost[0],
            None if lost is None else lost[1],
            self._retreats,
        )


__all__ = ["NeckServo"]
